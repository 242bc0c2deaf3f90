"""``hwpts reproduce``: the paper end to end on the simulated test bed."""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from hwpts.commands._args import non_negative_int


def register(subparsers) -> None:
    """Add the ``reproduce`` sub-command to ``subparsers``."""
    p = subparsers.add_parser(
        "reproduce",
        help="the paper end to end on the simulated test bed",
        description="Record the test bed (sweeps, identification run, four validation cases), compensate the "
        "valve hysteresis, segment (fracture line, eqs. 15-16), identify PWARX models (na=5, nb=4, eq. 17) "
        "and validate them. Writes DIR/summary.json, DIR/figures/*.png, DIR/report.html, DIR/data/*.csv, "
        "DIR/models/*.json and prints the fit table.",
    )
    p.add_argument("--out", default="results", metavar="DIR", help="output folder (default: results); an earlier "
                   "run there is replaced as a whole; a folder holding files a run did not write (or without "
                   "its list of them) is refused")
    p.add_argument("--quick", action="store_true", help="a smaller run for tests: a 200 s identification record, one learned segmentation "
                        "(alternating, not clustering too: 8 models, not 9), no polished candidates; the same "
                        "figures and files otherwise")
    p.add_argument("--seed", type=non_negative_int, default=0, metavar="N", help="seed of every random choice (default 0)")
    p.set_defaults(handler=reproduce_command)


def reproduce_command(args) -> int:
    """``hwpts reproduce``: the paper end to end; writes the run folder atomically and prints the fit table."""
    from tqdm import tqdm

    from hwpts.experiments import paper
    from hwpts.experiments.sweeps import sweep_columns
    from hwpts.io.atomic import write_bytes_atomic, write_text_atomic
    from hwpts.io.datasets import write_csv
    from hwpts.io.folders import check_replaceable, staged_folder
    from hwpts.io.models import save_model
    from hwpts.reporting.figures import all_figures
    from hwpts.reporting.html import render_report
    from hwpts.reporting.summary import SCHEMA, build_summary, fit_table, run_info

    check_replaceable(args.out, SCHEMA)  # refuse before minutes of work
    config = paper.ReproduceConfig.quick_run(args.seed) if args.quick else paper.ReproduceConfig.full(args.seed)
    stages = ["steady-state sweeps", "segmentation (fracture line)", "test-bed recordings", "identification",
              "validation", "figures and report"]
    start = time.perf_counter()
    with tqdm(total=len(stages), desc="reproduce", unit="stage", disable=not sys.stderr.isatty(), leave=False) as bar:
        def progress(stage):
            bar.set_postfix_str(stage)
            if stage != stages[0]:
                bar.update(1)

        with staged_folder(args.out, SCHEMA) as stage:
            result = paper.run(config, progress)
            progress("figures and report")
            t0 = time.perf_counter()
            vv, ww = np.meshgrid(result.sweeps.voltages_v, result.sweeps.pump_speeds_rpm, indexing="ij")
            figures = all_figures(result, result.fracture.regions(vv, ww))
            for name, data in figures.items():
                write_bytes_atomic(stage / "figures" / name, data)
            write_csv(stage / "data" / "steady_state_sweeps.csv", sweep_columns(result.sweeps))
            write_csv(stage / "data" / "identification.csv", result.identification.columns())
            for case, data in result.cases.items():
                columns = data.columns()
                for name, method in result.methods.items():
                    columns[f"simulated_{name}_rpm"] = method.simulated[case]
                write_csv(stage / "data" / f"{case}.csv", columns)
            models = {name: m.model for name, m in result.methods.items()}
            for name, model in models.items():
                save_model(model, stage / "models" / f"{name}.json")
            result.timings_s["figures_and_report"] = time.perf_counter() - t0
            summary = build_summary(result, time.perf_counter() - start,
                                    run_info(args.seed, getattr(args, "command_line", None)))
            write_text_atomic(stage / "report.html", render_report(summary, figures, models))
            write_text_atomic(stage / "summary.json", json.dumps(summary, indent=2) + "\n")
        bar.update(1)
    print(fit_table(summary))
    print(f"wrote {args.out}/: summary.json, report.html, {len(figures)} figures, {len(models)} models, "
          f"{2 + len(result.cases)} data files in {summary['timings_s']['total']:.1f} s")
    return 0
