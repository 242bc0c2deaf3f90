"""``hwpts reproduce`` end to end, as a user runs it (a fresh process each, so imports and the
loading of compiled kernels count): the full run within 120 s, ``--quick`` within 20 s, and
``--quick`` as a user's very first run too (``first``: numba's cache in an empty folder, so every
kernel compiles, as after ``make install`` on a fresh machine).

Run: ``python -m benchmarks reproduce``. Prints each stage's time from summary.json.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _run(args, out, env=None):
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "hwpts", "reproduce", "--out", str(out), *args],
                          capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"hwpts reproduce {' '.join(args)} failed: {proc.stderr.strip()}")
    return wall, json.loads((out / "summary.json").read_text())


def main(argv=None) -> int:
    status = 0
    with tempfile.TemporaryDirectory() as tmp:
        rows = []
        cold = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba-cache")}
        for label, args, target, env in (("first", ["--quick"], 20.0, cold), ("--quick", ["--quick"], 20.0, None),
                                         ("full", [], 120.0, None)):
            wall, summary = _run(args, Path(tmp) / label.strip("-"), env)
            rows.append((label, wall, target, summary))
        print(f"{'run':8s} {'wall [s]':>9s} {'target':>8s}  stages [s]")
        for label, wall, target, summary in rows:
            ok = wall <= target
            status |= not ok
            stages = ", ".join(f"{k} {v:.1f}" for k, v in summary["timings_s"].items())
            print(f"{label:8s} {wall:9.1f} {'<= ' + format(target, 'g'):>8s}  {'ok' if ok else 'MISSED'}  {stages}")
        full = rows[2][3]
        print("\nfull run, free-run fit %:")
        for name in ("average", "paper", "paper_uncompensated", "best"):
            fits = full["methods"][name]["cases"]
            print(f"  {name:20s} " + "  ".join(f"{c} {fits[c]['fit_percent']}" for c in sorted(fits)))
    return status
