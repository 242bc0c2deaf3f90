"""Refresh the README's generated parts from a ``hwpts reproduce`` output folder.

``make readme`` runs ``hwpts reproduce --out results`` and then this script, which copies three of
the figures into docs/figures/ and rewrites the fit table between the README's markers. Nothing in
those parts is typed by hand.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

from hwpts.reporting.summary import fit_table

FIGURES = ("fig10_case3.png", "fig07_fracture_line.png", "fig03_sweeps.png")
START, END = "<!-- fit-table:start -->", "<!-- fit-table:end -->"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    results = Path(argv[0] if argv else "results")
    root = Path(__file__).resolve().parent.parent
    summary = json.loads((results / "summary.json").read_text())
    if summary.get("quick"):
        print("update_readme: refusing a --quick run; run `make readme`", file=sys.stderr)
        return 2
    for name in FIGURES:
        shutil.copyfile(results / "figures" / name, root / "docs" / "figures" / name)
    readme = root / "README.md"
    text = readme.read_text()
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    # the command's last line, from the folder it wrote (as `hwpts reproduce` counts them)
    counts = {part: len(list((results / part).glob(pattern)))
              for part, pattern in (("figures", "*.png"), ("models", "*.json"), ("data", "*.csv"))}
    wrote = (f"wrote {results}/: summary.json, report.html, {counts['figures']} figures, {counts['models']} models, "
             f"{counts['data']} data files in {summary['timings_s']['total']:.1f} s")
    block = f"{START}\n```\n$ hwpts reproduce --seed {summary['seed']}\n{fit_table(summary)}\n{wrote}\n```\n{END}"
    readme.write_text(head + block + tail)
    print(f"README.md: fit table and {len(FIGURES)} figures from {results}/ (seed {summary['seed']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
