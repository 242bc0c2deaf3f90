"""Run the benchmarks: ``python -m benchmarks`` runs every ``bench_*.py``; names select some.

Each module exposes ``main(argv) -> int``, prints its own table with ratios against a baseline
measured in the same run.
"""

import importlib
import pkgutil
import sys
from pathlib import Path


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    names = sorted(
        m.name for m in pkgutil.iter_modules([str(Path(__file__).parent)]) if m.name.startswith("bench_")
    )
    if "-h" in argv or "--help" in argv:  # (it ran every benchmark)
        print(f"usage: python -m benchmarks [NAME ...] [--option=value ...]\n\n{__doc__.strip()}\n\n"
              f"benchmarks: {', '.join(n.removeprefix('bench_') for n in names)}; each module's docstring gives "
              f"its options (python -c 'import benchmarks.bench_zoo as b; print(b.__doc__)')")
        return 0
    wanted = [a for a in argv if not a.startswith("-")] or names
    unknown = [w for w in wanted if w not in names and f"bench_{w}" not in names]
    if unknown:
        print(f"benchmarks: unknown benchmark(s) {unknown}; available: {names}", file=sys.stderr)
        return 2
    status = 0
    for name in names:
        if name in wanted or name.removeprefix("bench_") in wanted:
            print(f"== {name} ==", flush=True)
            module = importlib.import_module(f"benchmarks.{name}")
            status |= int(module.main([a for a in argv if a.startswith("-")]) or 0)
    return status


if __name__ == "__main__":
    sys.exit(main())
