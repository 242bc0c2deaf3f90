"""``hwpts identify | validate | predict``: PWARX models from data files (DESIGN.md section 3)."""

from __future__ import annotations

import time
import warnings

import numpy as np

from hwpts.commands._args import json_text
from hwpts.errors import DataError, ParameterError, SimulationError


def _int_list(text: str, name: str):
    """``"4"`` -> 4, ``"4,2"`` -> [4, 2] (one per input)."""
    try:
        values = [int(v) for v in str(text).split(",")]
    except ValueError:
        raise ParameterError(f"--{name} expects an int or comma-separated ints (one per input), got {text!r}") from None
    return values[0] if len(values) == 1 else values


def _rows(text: str | None):
    if text is None:
        return slice(None)
    parts = str(text).split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        start = int(parts[0]) if parts[0].strip() else None
        stop = int(parts[1]) if parts[1].strip() else None
    except ValueError:
        raise ParameterError(f"--rows expects START:STOP (Python slice, e.g. 0:5000 or -1001:), got {text!r}") from None
    return slice(start, stop)


def _load_dataset(path, input_names, output_name, time_name=None, rows=None):
    from hwpts.dataset import IODataset
    from hwpts.io.datasets import read_table

    columns = read_table(path, [*input_names, output_name, *([time_name] if time_name else ["time_s"])])
    if time_name is not None and time_name not in columns:
        raise DataError(f"{str(path)!r}: no time column {time_name!r}; available columns are {sorted(columns)}")
    missing = [c for c in [*input_names, output_name] if c not in columns]
    if missing:
        raise DataError(f"{str(path)!r}: no column(s) {missing}; available columns are {sorted(columns)}")
    sl = _rows(rows)
    cols = {k: np.asarray(v)[sl] for k, v in columns.items()}
    n = len(cols[output_name])
    if n == 0:
        raise DataError(f"{str(path)!r}: no rows selected (--rows {rows})")
    tname = time_name if time_name is not None else ("time_s" if "time_s" in cols else None)
    if tname is None:
        # time = sample index of the file (keeps the original numbering under --rows)
        cols["__index__"] = np.arange(len(columns[output_name]), dtype=float)[sl]
        tname = "__index__"
    return IODataset.from_columns(cols, list(input_names), output_name, time_name=tname)


def _fit_summary(model, data, path, out, elapsed, search=None):
    from hwpts.identification.metrics import fit_percent, rmse

    m = model.structure_.max_lag
    sim = model.simulate(data.inputs, data.output)
    one = model.predict(data.inputs, data.output)
    y = data.output[m:]
    summary = {"model": str(out), "data": str(path), "n_samples": data.n_samples}
    summary.update(model.summary())
    summary["train_fit_percent"] = None if sim.diverged else round(fit_percent(y, sim.output[m:]), 3)
    summary["train_one_step_fit_percent"] = round(fit_percent(y, one[m:]), 3)
    summary["train_rmse"] = None if sim.diverged else rmse(y, sim.output[m:])
    if sim.diverged:
        summary["diverged"] = True
        summary["reason"] = sim.reason
    if search is not None:
        table = search.candidate_table()
        summary["choice"] = {
            "na": model.structure_.na, "nb": list(model.structure_.nb), "nk": list(model.structure_.nk),
            "segmentation": summary["segmentation"], "n_regions": int(model.n_regions_),
            "polished": summary["polished"], "heldout_fit_percent": round(search.best_score_, 3),
            "n_candidates": len(table), "n_blocks": search.n_splits_,
            "why": (f"best mean free-run fit over {search.n_splits_} held-out blocks of the training data "
                    f"({len(table)} candidates; within {search.tolerance} points the fewest regions, then the "
                    f"fewest parameters, win)"),
        }
        summary["candidates"] = table
    summary["fit_time_s"] = round(elapsed, 3)
    return summary


def _orders_to_search(args):
    """The estimator's orders and the order grid of the search: the orders not given are searched
    (``--nk`` defaults to 1 when ``--na`` and ``--nb`` are both given, as before)."""
    from hwpts.identification.selection import ORDER_GRID

    given = {"output_order": args.na,
             "input_order": None if args.nb is None else _int_list(args.nb, "nb"),
             "input_delay": None if args.nk is None else _int_list(args.nk, "nk")}
    if given["output_order"] is not None and given["input_order"] is not None and given["input_delay"] is None:
        given["input_delay"] = 1
    for key, flag in (("output_order", "--na"), ("input_order", "--nb"), ("input_delay", "--nk")):
        values = given[key] if isinstance(given[key], list) else [given[key]]
        if given[key] is not None and any(v < 0 for v in values):
            raise ParameterError(f"{flag} expects ints >= 0, got {given[key]!r}")
    searched = {k: list(ORDER_GRID[k]) for k, v in given.items() if v is None}
    fixed = {k: v for k, v in given.items() if v is not None}
    return fixed, searched


def cmd_identify(args) -> int:
    from hwpts.identification import PWARX, PWARXSearch
    from hwpts.identification.partition import Hyperplane
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.selection import DEFAULT_METHODS
    from hwpts.io.models import save_model

    data = _load_dataset(args.data, args.input, args.output, args.time, args.rows)
    fixed, searched = _orders_to_search(args)
    if not searched:
        structure = RegressorStructure.create(fixed["output_order"], fixed["input_order"], fixed["input_delay"],
                                              len(args.input), True, args.input, args.output)
        structure.check_length(data.n_samples, what=f"{args.data!s}")
    hyperplanes = [Hyperplane.parse(h) for h in args.hyperplane]
    segmentation = args.segmentation
    if hyperplanes and segmentation is None:
        segmentation = "hyperplane"
    segmentation = segmentation or "auto"
    if segmentation == "hyperplane" and not hyperplanes:
        raise ParameterError("--segmentation hyperplane needs at least one --hyperplane \"a,b,c\"")
    if hyperplanes and segmentation != "hyperplane":
        raise ParameterError(f"--hyperplane needs --segmentation hyperplane, not {segmentation!r}")
    regions = args.regions
    if regions == "auto":
        n_regions = "auto"
    else:
        try:
            n_regions = int(regions)
        except ValueError:
            raise ParameterError(f"--regions expects an int >= 1 or 'auto', got {regions!r}") from None
        if n_regions < 1:
            raise ParameterError(f"--regions expects an int >= 1, got {n_regions}")
    region_models = None
    if args.zero_region:
        n_hyper = len(hyperplanes) + 1 if segmentation == "hyperplane" else n_regions
        if not isinstance(n_hyper, int):
            raise ParameterError("--zero-region needs a fixed number of regions (--regions S or hyperplanes)")
        region_models = ["affine"] * n_hyper
        for r in args.zero_region:
            if not 1 <= r <= n_hyper:
                raise ParameterError(f"--zero-region {r}: regions are numbered 1..{n_hyper}")
            region_models[r - 1] = "zero"
    fixed_partition = segmentation in ("hyperplane", "average", "zscore")
    model = PWARX(
        **{"output_order": 1, "input_order": 1, "input_delay": 1, **fixed},
        n_regions=n_regions if isinstance(n_regions, int) else 2,
        segmentation=segmentation if segmentation != "auto" else "clustering",
        hyperplanes=hyperplanes or None, region_models=region_models,
        ridge=args.ridge, polish=args.polish, random_state=args.seed,
        partition_columns=args.partition_column or None, sparse_partition=not args.all_partition_columns,
    )
    search = None
    if searched or (n_regions == "auto" and not fixed_partition):
        if segmentation == "auto" or n_regions == "auto" and not fixed_partition:
            methods = DEFAULT_METHODS if segmentation == "auto" else (segmentation,)
            search = PWARXSearch(model, methods=methods, orders=searched or None, progress=True,
                                 try_polish="auto" if not args.polish else False,
                                 max_regions=n_regions if isinstance(n_regions, int) else "auto")
            if isinstance(n_regions, int):  # a fixed method and count, the orders searched
                search.set_params(param_grid={**searched, "segmentation": [segmentation], "n_regions": [n_regions]})
        else:
            search = PWARXSearch(model, param_grid=dict(searched), progress=True, try_polish=False)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if search is not None:
            search.fit(data.inputs, data.output, input_names=args.input, output_name=args.output)
            model = search.best_estimator_
        else:
            model.fit(data.inputs, data.output, input_names=args.input, output_name=args.output)
    elapsed = time.perf_counter() - t0
    summary = _fit_summary(model, data, args.data, args.out, elapsed, search)
    notes = sorted({str(w.message) for w in caught if issubclass(w.category, UserWarning)})
    if notes:
        summary["warnings"] = notes
    save_model(model, args.out)
    print(json_text(summary))
    return 0


def _validate_numbers(model, data):
    from hwpts.identification.metrics import fit_percent, rmse

    model.structure_.check_length(data.n_samples)
    m = model.structure_.max_lag
    y = data.output[m:]
    sim = model.simulate(data.inputs, data.output)
    one = model.predict(data.inputs, data.output)
    regions = sim.regions[m:]
    share = np.bincount(regions[regions >= 0], minlength=model.n_regions_) / max(1, np.sum(regions >= 0))
    result = {
        "fit_percent": None if sim.diverged else fit_percent(y, sim.output[m:]),
        "one_step_fit_percent": fit_percent(y, one[m:]),
        "rmse": None if sim.diverged else rmse(y, sim.output[m:]),
        "one_step_rmse": rmse(y, one[m:]),
        "n_samples": int(data.n_samples),
        "n_initial_conditions": int(m),
        "n_regions": int(model.n_regions_),
        "region_share": [round(float(v), 6) for v in share],
        "diverged": bool(sim.diverged),
    }
    if sim.diverged:
        result["diverged_at"] = sim.diverged_at
        result["reason"] = sim.reason
    return result


def _model_and_data(args):
    from hwpts.io.models import load_model

    model = load_model(args.model)
    data = _load_dataset(args.data, list(model.structure_.input_names), model.structure_.output_name,
                         args.time, args.rows)
    return model, data


def cmd_validate(args) -> int:
    model, data = _model_and_data(args)
    result = _validate_numbers(model, data)
    if args.json:
        print(json_text(result))
        return 0
    st = model.structure_
    print(f"model: {args.model} ({model.n_regions_} regions, {st.describe_orders()}, "
          f"inputs {list(st.input_names)}, output {st.output_name!r})")
    print(f"data: {args.data} ({result['n_samples']} samples, first {result['n_initial_conditions']} "
          f"are initial conditions)")
    if result["diverged"]:
        print(f"free-run fit: none - {result['reason']}")
    else:
        print(f"free-run fit: {result['fit_percent']:.2f} %  (rmse {result['rmse']:.6g})")
    print(f"one-step fit: {result['one_step_fit_percent']:.2f} %  (rmse {result['one_step_rmse']:.6g})")
    return 0


def cmd_predict(args) -> int:
    from hwpts.io.datasets import write_csv

    model, data = _model_and_data(args)
    model.structure_.check_length(data.n_samples)
    name = data.output_name
    if args.mode == "simulate":
        sim = model.simulate(data.inputs, data.output)
        if sim.diverged:
            raise SimulationError(f"{sim.reason}; no file written (try --mode one-step)")
        yhat, regions = sim.output, sim.regions
    else:
        yhat = model.predict(data.inputs, data.output)
        regions = model.predict_regions(data.inputs, data.output)
    columns = {"time_s": data.time}
    for j, nm in enumerate(data.input_names):
        columns[nm] = data.inputs[:, j]
    columns[name] = data.output
    columns[f"{name}_predicted"] = yhat
    columns["region"] = regions + 1  # 1-based; 0 marks the initial conditions
    write_csv(args.out, columns)
    print(f"wrote {args.out} ({data.n_samples} rows, mode {args.mode}; region 0 = initial conditions)")
    return 0


def _common_data_args(parser):
    parser.add_argument("--time", metavar="COL", default=None,
                        help="time column [s] (default: time_s if present, else the sample index)")
    parser.add_argument("--rows", metavar="START:STOP", default=None,
                        help="use only these rows (Python slice: 0:5000; write --rows=-1001: for a negative start)")


# the registry's names, written out so that `hwpts --help` does not import the library (a test
# checks that they match hwpts.identification.segmentation.SEGMENTATION_METHODS)
SEGMENTATION_NAMES = ("alternating", "average", "clustering", "hyperplane", "kmeans", "threshold", "zscore")


def register(subparsers):
    from hwpts.commands._args import non_negative_float, non_negative_int

    p = subparsers.add_parser(
        "identify", help="fit a PWARX model to a data file",
        description="Fit a PWARX model (paper section IV) and write it as JSON (schema hwpts.pwarx/1). "
                    "Prints a JSON summary.",
    )
    p.add_argument("data", metavar="DATA", help="data file: .csv, .parquet or .mat")
    p.add_argument("--input", metavar="COL", action="append", required=True, help="input column (repeat for several)")
    p.add_argument("--output", metavar="COL", required=True, help="output column")
    p.add_argument("--na", type=int, default=None, metavar="N",
                   help="output order (default: chosen on the data, 0-4)")
    p.add_argument("--nb", default=None, metavar="N",
                   help="input order, an int or one per input: 4,4 (default: chosen on the data, 1-4)")
    p.add_argument("--nk", default=None, metavar="N",
                   help="input delay, 0 uses u(k) (default: chosen on the data, 0-1; 1 when --na and --nb are given)")
    p.add_argument("--segmentation", choices=["auto", *SEGMENTATION_NAMES], default=None,
                   help="segmentation method (default auto: chosen on the data among threshold, clustering and "
                        "alternating; hyperplane when --hyperplane is given)")
    p.add_argument("--regions", default="auto", metavar="S",
                   help="number of regions (default auto: grown while the held-out fit improves)")
    p.add_argument("--hyperplane", action="append", default=[], metavar='"a,b,c"',
                   help="a*x1 + b*x2 + c >= 0 on the first two inputs, or 'a,b,c@col1,col2' on named "
                        "regressor columns; repeat for a decision list (m hyperplanes, m+1 regions); write "
                        "--hyperplane=-1,0,2.8 when the first coefficient is negative")
    p.add_argument("--zero-region", type=int, action="append", default=[], metavar="I",
                   help="region I (1-based) is the zero mode y = 0 (paper eq. 18)")
    p.add_argument("--partition-column", action="append", default=[], metavar="COL",
                   help="regressor column the region classifier may use, e.g. 'y(k-1)' (repeat; default all)")
    p.add_argument("--all-partition-columns", action="store_true",
                   help="keep every allowed column in a learned partition (default: drop the columns its "
                        "boundaries hardly use)")
    p.add_argument("--ridge", type=non_negative_float, default=0.0,
                   help="ridge penalty of the local least squares (relative to the regressors' scale; default 0)")
    p.add_argument("--polish", action="store_true", help="refine parameters on the free-run simulation error")
    p.add_argument("--seed", type=non_negative_int, default=0, metavar="N", help="random seed (default 0)")
    p.add_argument("--out", required=True, metavar="MODEL.json", help="model file to write")
    _common_data_args(p)
    p.set_defaults(handler=cmd_identify)

    v = subparsers.add_parser("validate", help="free-run and one-step fit of a model on data",
                              description="Free-run simulation and one-step prediction of MODEL on DATA.")
    v.add_argument("model", metavar="MODEL.json")
    v.add_argument("data", metavar="DATA")
    v.add_argument("--json", action="store_true", help="print one JSON object")
    _common_data_args(v)
    v.set_defaults(handler=cmd_validate)

    r = subparsers.add_parser("predict", help="write a model's predictions for DATA to CSV",
                              description="Free-run (simulate) or one-step predictions of MODEL on DATA.")
    r.add_argument("model", metavar="MODEL.json")
    r.add_argument("data", metavar="DATA")
    r.add_argument("--out", required=True, metavar="FILE.csv")
    r.add_argument("--mode", choices=["simulate", "one-step"], default="simulate")
    _common_data_args(r)
    r.set_defaults(handler=cmd_predict)
