"""Reading a CSV of a million rows: pyarrow's reader (``hwpts.io.datasets.read_csv``) against the
line-by-line Python reader hwpts used before (kept as the diagnostic path), in the same run.

``python -m benchmarks io``
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROWS = 1_000_000


def main(argv=None) -> int:
    from hwpts.io.datasets import _read_csv_python, read_csv, write_csv

    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "big.csv"
        write_csv(path, {"time_s": np.arange(ROWS) * 1e-3, "u": rng.standard_normal(ROWS), "y": rng.standard_normal(ROWS)})
        t0 = time.perf_counter()
        fast = read_csv(path)
        t_fast = time.perf_counter() - t0
        t0 = time.perf_counter()
        slow = _read_csv_python(path)
        t_slow = time.perf_counter() - t0
        assert all(np.array_equal(fast[k], slow[k]) for k in slow)
    print(f"CSV, {ROWS:,} rows x 3 columns: pyarrow {t_fast:.2f} s, line-by-line reader {t_slow:.2f} s: "
          f"{t_slow / t_fast:.1f}x faster (target >= 3x); same values")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
