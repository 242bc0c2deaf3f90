"""``hwpts residuals | export``: residual tests of a model on data, and its state space exported."""

from __future__ import annotations

from hwpts.commands._args import json_text
from hwpts.errors import DataError, ParameterError


def cmd_residuals(args) -> int:
    """``hwpts residuals``: residual tests of MODEL on DATA; prints a verdict per test (or JSON), optionally a figure."""
    from hwpts.commands.model import _beyond_line, _beyond_training, _model_and_data
    from hwpts.identification.analysis import residual_analysis

    model, data, _ = _model_and_data(args)
    model.structure_.check_length(data.n_samples, what="DATA")
    try:
        analysis = residual_analysis(model, data.inputs, data.output, lags=args.lags, confidence=args.confidence)
    except DataError as error:
        if str(error).startswith("lags "):  # said as the option
            raise DataError(f"--{error}") from None
        raise
    result = analysis.to_dict()
    # residuals where the model extrapolates say as little about the model as a fit % does there
    result["beyond_training_range"] = _beyond_training(model, data)
    if args.plot is not None:
        from hwpts.io.atomic import write_bytes_atomic
        from hwpts.reporting.analysis import residual_figure

        units = getattr(model, "units_", {}) or {}
        name = model.structure_.output_name
        write_bytes_atomic(args.plot, residual_figure(analysis, output_name=name, unit=units.get(name),
                                                      title=f"{args.model} on {args.data}"), argument="--plot")
        result["plot"] = str(args.plot)
    if args.json:
        print(json_text(result))
        return 0
    share = result["outside_share"]
    conf = f"{100 * result['confidence']:.12g} %"  # 99.9999999, not 100
    print(f"residuals: {result['n_residuals']} one-step residuals of {model.structure_.output_name!r}, "
          f"rms {result['residual_rms']:.6g}")
    if result["exact"]:
        print("the residuals are rounding errors (rms under 1e-9 of the output's standard deviation): the model "
              "reproduces the data exactly, and the whiteness and input-correlation tests, which assume a "
              "noise, do not apply")
    else:
        if share["autocorrelation"] is None:
            print("whiteness: the residuals are constant on these data: not tested (no spread to correlate)")
        else:
            print(f"whiteness: {100 * share['autocorrelation']:.1f} % of lags 1..{args.lags} outside the {conf} band "
                  f"(+-{result['band']:.4g}) -> {'white' if result['white'] else 'NOT white'}")
        for name, value in share["cross_correlation"].items():
            if value is None:
                print(f"input {name}: constant on these data: not tested (its correlation with the residuals is "
                      f"undefined)")
                continue
            print(f"input {name}: {100 * value:.1f} % of lags 0..{args.lags} outside the band -> "
                  f"{'uncorrelated' if value <= 0.05 else 'CORRELATED'}")
    beyond = _beyond_line(result["beyond_training_range"])
    if beyond:
        print(beyond)
    if args.plot is not None:
        print(f"wrote {args.plot}")
    return 0


def cmd_export(args) -> int:
    """``hwpts export``: write MODEL's per-mode state space as a python-control module, a .mat file or JSON."""
    from hwpts import __version__
    from hwpts.identification.analysis import state_space_export
    from hwpts.io.export import EXPORT_FORMATS, write_export
    from hwpts.io.models import load_model

    suffix = EXPORT_FORMATS[args.format]
    if not str(args.out).lower().endswith(suffix):
        raise ParameterError(f"--out {str(args.out)!r}: --format {args.format} writes a {suffix} file; "
                             f"expected a file name ending in {suffix}")
    model = load_model(args.model)
    try:
        doc = state_space_export(model)
    except ParameterError as error:  # a model that has no state-space form: say which file
        raise ParameterError(f"{str(args.model)!r}: {error}") from None
    write_export(args.out, args.format, doc, f"hwpts {__version__}", str(args.model))
    n = doc["modes"][0]["A"].shape[0]
    dt = doc["sample_time_s"]
    print(f"wrote {args.out} ({args.format}: {len(doc['modes'])} modes of {n} states, "
          f"{len(doc['inputs'])} inputs + offset, sample time {'unknown' if dt is None else f'{dt:g} s'})")
    return 0


def register(subparsers):
    """Add the ``residuals`` and ``export`` sub-commands to ``subparsers``."""
    import argparse

    from hwpts.commands._args import finite_float, positive_int
    from hwpts.commands.model import _common_data_args, _mapping_args, _png_path

    def confidence(text):
        value = finite_float(text)
        from hwpts.identification.analysis import MAX_CONFIDENCE

        if not 0.5 < value <= MAX_CONFIDENCE:  # 1 - 1e-16: a band of +-inf called every residual white
            raise argparse.ArgumentTypeError(f"expected a probability in (0.5, {MAX_CONFIDENCE}], got {text!r}")
        return value

    r = subparsers.add_parser(
        "residuals", help="whiteness and input-correlation tests of a model's one-step residuals",
        description="Autocorrelation of the one-step residuals of MODEL on DATA and their cross-correlation "
                    "with each input, with a confidence band (MATLAB's resid). A correct model leaves white "
                    "residuals, uncorrelated with past inputs: about 1 % of lags outside the 99 % band.")
    r.add_argument("model", metavar="MODEL.json")
    r.add_argument("data", metavar="DATA")
    r.add_argument("--lags", type=positive_int, default=25, metavar="L", help="largest lag tested [samples] (default 25)")
    r.add_argument("--confidence", type=confidence, default=0.99, metavar="P",
                   help="probability of the confidence band (default 0.99)")
    r.add_argument("--plot", metavar="FILE.png", type=_png_path, default=None,
                   help="write the correlations and the band as a figure")
    r.add_argument("--json", action="store_true", help="print one JSON object")
    _mapping_args(r)
    _common_data_args(r)
    r.set_defaults(handler=cmd_residuals, prints_result="residuals")

    e = subparsers.add_parser(
        "export", help="export a model's per-mode state space (python-control, MATLAB, JSON)",
        description="Each mode as the affine state space of the paper's eq. 7 with its region (eq. 9): "
                    "--format control writes a Python module building python-control systems (MODES), "
                    "matlab a .mat file (A, B, C, D, e, c, H, g, Ts), json a JSON document.")
    e.add_argument("model", metavar="MODEL.json")
    e.add_argument("--format", choices=["control", "matlab", "json"], required=True)
    e.add_argument("--out", required=True, metavar="FILE", help="file to write: .py, .mat or .json by format")
    e.set_defaults(handler=cmd_export)
