"""``hwpts --help`` in a fresh process, against the import path it had before (the parser built
after importing the identification library), measured in the same run.

``python -m benchmarks cli``
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time

RUNS = 7
HELP = "from hwpts.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
BASELINE = "import hwpts.identification.segmentation\n" + HELP


def _time(code: str) -> float:
    times = []
    for _ in range(RUNS):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv=None) -> int:
    ours, before = _time(HELP), _time(BASELINE)
    print(f"hwpts --help, fresh process, median of {RUNS}: {ours:.3f} s; with the library imported first "
          f"(as before): {before:.3f} s; {before / ours:.1f}x faster (target >= 5x)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
