"""``hwpts control run``: speed control of the test bed from an identified PWARX model bank."""

from __future__ import annotations

import argparse
import sys

from hwpts.commands._args import finite_float, non_negative_int

DEFAULT_CONTROLLERS = "pi,pi-no-inverse,scheduled,scheduled-no-inverse,mmac,mmac-no-inverse,mpc,mpc-no-inverse,reference"
SCENARIOS = ("setpoint-step", "pump-step", "load-step", "turbulence-a", "turbulence-b", "turbulence-c", "low-wind")


def _positive(text):
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def register(subparsers) -> None:
    p = subparsers.add_parser("control", help="closed-loop speed control from an identified model bank",
                              description="Design speed controllers from a PWARX model bank and run them closed loop "
                              "on the simulated test bed under wind and load disturbances.")
    sub = p.add_subparsers(dest="control_command", metavar="SUBCOMMAND", parser_class=type(p))
    sub.required = True
    r = sub.add_parser("run", help="one scenario, several controllers: summary.json, data, figures, report.html",
                       description="Run the controllers on one scenario. Writes DIR/summary.json (schema hwpts.control/1), "
                       "DIR/data/*.csv, DIR/figures/*.png and DIR/report.html. Without --model the model bank is "
                       "identified first as 'hwpts reproduce' does (method 'paper').")
    r.add_argument("--scenario", required=True, metavar="NAME", help=f"one of {', '.join(SCENARIOS)}")
    r.add_argument("--controllers", default=DEFAULT_CONTROLLERS, metavar="A,B,...",
                   help=f"comma-separated controller names (default: {DEFAULT_CONTROLLERS})")
    r.add_argument("--model", metavar="MODEL.json", help="PWARX model file with inputs (valve voltage, pump speed)")
    r.add_argument("--model-sample-time", type=_positive, default=0.05, metavar="S",
                   help="the model's sample period in seconds (default 0.05, that of 'hwpts reproduce')")
    r.add_argument("--hysteresis-width", type=finite_float, default=None, metavar="V",
                   help="half-width of the valve's play the model's valve input was compensated with [V] "
                   "(default: read off the sweeps when identifying, else 0.25)")
    r.add_argument("--setpoint", type=finite_float, default=1000.0, metavar="RPM", help="speed set-point (default 1000)")
    r.add_argument("--duration", type=_positive, default=None, metavar="S", help="shorter or longer record than the "
                   "scenario's own (turbulence: 600 s)")
    r.add_argument("--seed", type=non_negative_int, default=0, metavar="N", help="seed of wind and sensor noise (default 0)")
    r.add_argument("--out", required=True, metavar="DIR", help="output folder (an earlier run there is replaced)")
    r.set_defaults(handler=run_command)


def identify_model_bank(seed: int, quick: bool = False):
    """The model bank as 'hwpts reproduce' identifies it (method 'paper'): (model, play half-width)."""
    import warnings

    from hwpts.experiments import paper
    from hwpts.experiments.sweeps import estimate_hysteresis, find_fracture, record_sweeps
    from hwpts.identification import PWARX
    from hwpts.plant import PlantParameters, TestBed, identification_excitation

    config = paper.ReproduceConfig.quick_run(seed) if quick else paper.ReproduceConfig.full(seed)
    sweeps = record_sweeps(PlantParameters.paper(), progress=False)
    r_hat = estimate_hysteresis(sweeps)
    fracture = find_fracture(sweeps)
    bed = TestBed(sample_time=config.logger_sample_time_s, noise_std_rpm=config.noise_std_rpm)
    excitation = identification_excitation(config.identification_duration_s, config.logger_sample_time_s, seed=seed)
    raw, _ = bed.record(excitation, seed=seed)
    data = paper.compensate(paper.block_decimate(raw, config.decimation), r_hat)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = PWARX(paper.NA, paper.NB, paper.NK, segmentation="hyperplane",
                      hyperplanes=paper.paper_hyperplanes(fracture, paper.COMPENSATED_INPUT)).fit(data)
    return model, float(r_hat), config.sample_time_s


def run_command(args) -> int:
    import json
    import time

    from tqdm import tqdm

    from hwpts.control.controllers import parse_names
    from hwpts.control.model import ModelBank
    from hwpts.control.run import SCHEMA, check_setpoint, run_scenario
    from hwpts.errors import ParameterError
    from hwpts.io.atomic import write_bytes_atomic, write_text_atomic
    from hwpts.io.datasets import write_csv
    from hwpts.io.folders import check_replaceable, staged_folder
    from hwpts.io.models import load_model, model_to_dict, save_model
    from hwpts.reporting.control import loop_figure, metric_table, render_control_report

    if args.scenario not in SCENARIOS:
        raise ParameterError(f"--scenario: unknown scenario {args.scenario!r}; expected one of {', '.join(SCENARIOS)}")
    names = parse_names(args.controllers)
    if args.hysteresis_width is not None and not 0 <= args.hysteresis_width < 1.3:
        raise ParameterError(f"--hysteresis-width: expected a half-width in 0-1.3 V, got {args.hysteresis_width:g}")
    check_setpoint(None, args.setpoint)
    check_replaceable(args.out, SCHEMA)
    start = time.perf_counter()
    if args.model:
        model = load_model(args.model)
        doc = model_to_dict(model)
        half_width = 0.25 if args.hysteresis_width is None else args.hysteresis_width
        sample_time = args.model_sample_time
        source = f"file {args.model}"
    else:
        print("identifying the model bank as 'hwpts reproduce' does (method 'paper') ...", file=sys.stderr)
        model, r_hat, sample_time = identify_model_bank(args.seed)
        doc = model_to_dict(model)
        half_width = r_hat if args.hysteresis_width is None else args.hysteresis_width
        source = f"identified on the test bed (method 'paper', seed {args.seed})"
    bank = ModelBank(doc, sample_time)
    check_setpoint(bank, args.setpoint, doc["training"]["output_range"])
    with tqdm(total=1000, desc=f"control {args.scenario}", unit="‰", disable=not sys.stderr.isatty(), leave=False) as bar:
        def progress(fraction, name):
            bar.set_postfix_str(name)
            bar.n = int(1000 * fraction)
            bar.refresh()

        summary, runs, scenario = run_scenario(bank, half_width, args.scenario, names, args.seed, args.setpoint,
                                               args.duration, source, progress)
    with staged_folder(args.out, SCHEMA) as stage:
        for name, result in runs.items():
            write_csv(stage / "data" / f"{name}.csv", result.columns)
        cols = {n: r.columns for n, r in runs.items()}
        figures = {f"{args.scenario}.png": loop_figure(cols, f"{args.scenario}: {scenario.description}")}
        t_end = scenario.time[-1]
        if t_end > 60:
            figures[f"{args.scenario}_zoom.png"] = loop_figure(cols, f"{args.scenario}: 60 s zoom", (t_end / 2 - 30, t_end / 2 + 30))
        for name, data in figures.items():
            write_bytes_atomic(stage / "figures" / name, data)
        if not args.model:
            save_model(model, stage / "model.json")
        summary["timings_s"] = {"total": round(time.perf_counter() - start, 2)}
        write_text_atomic(stage / "report.html", render_control_report(summary, figures))
        write_text_atomic(stage / "summary.json", json.dumps(summary, indent=2) + "\n")
    print(metric_table(summary))
    print(f"best model-based controller: {summary['best']}; wrote {args.out}/: summary.json, report.html, "
          f"{len(figures)} figures, {len(runs)} data files in {summary['timings_s']['total']:.1f} s")
    return 0
