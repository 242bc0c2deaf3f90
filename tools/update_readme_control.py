"""Refresh the README's ``hwpts control`` section from a ``hwpts control run`` output folder.

``make readme-control`` runs ``hwpts control run --scenario turbulence-a --out results-control`` and
then this script, which copies the run's zoomed figure into docs/figures/ and rewrites the metric
table between the README's control markers. Nothing in that part is typed by hand.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

from hwpts.reporting.control import metric_table

START, END = "<!-- control-table:start -->", "<!-- control-table:end -->"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    results = Path(argv[0] if argv else "results-control")
    root = Path(__file__).resolve().parent.parent
    summary = json.loads((results / "summary.json").read_text())
    scenario = summary["scenario"]
    figures = sorted((results / "figures").glob(f"{scenario}*.png"))
    figure = next((f for f in figures if f.stem.endswith("_zoom")), figures[0])
    shutil.copyfile(figure, root / "docs" / "figures" / f"control_{scenario}.png")
    readme = root / "README.md"
    text = readme.read_text()
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    cmd = f"$ hwpts control run --scenario {scenario} --seed {summary['seed']} --out {results.name}"
    # the command's own last line, from the files the run wrote
    n_figures = len(list((results / "figures").glob("*.png")))
    n_data = len(list((results / "data").glob("*.csv")))
    last = (f"best model-based controller: {summary['best']}; wrote {results.name}/: summary.json, report.html, "
            f"{n_figures} figures, {n_data} data files in {summary['timings_s']['total']:.1f} s")
    block = f"{START}\n```\n{cmd}\n{metric_table(summary)}\n{last}\n```\n{END}"
    readme.write_text(head + block + tail)
    print(f"README.md: control metric table and figure from {results}/ ({scenario}, seed {summary['seed']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
