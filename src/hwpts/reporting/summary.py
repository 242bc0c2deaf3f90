"""``summary.json`` of ``hwpts reproduce`` (schema "hwpts.reproduce/1"; its keys are a contract other tools read)."""

from __future__ import annotations

import math

import numpy as np

from hwpts.experiments.paper import PAPER_REPORTED_FIT, fracture_comparison

SCHEMA = "hwpts.reproduce/1"
CONTRACT_METHODS = ("average", "zscore", "kmeans", "paper", "best")


def _number(x, digits=3):
    return None if x is None or (isinstance(x, float) and math.isnan(x)) else round(float(x), digits)


def run_info(seed: int, command: str | None = None) -> dict:
    """Who made a result and how: hwpts version, UTC date, command line and seed."""
    import datetime

    from hwpts import __version__

    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    return {"hwpts_version": __version__, "created_utc": now.isoformat().replace("+00:00", "Z"),
            "command": command, "seed": int(seed)}


def build_summary(result, total_time_s: float, run: dict | None = None) -> dict:
    """The summary as a JSON-ready dict; a diverged free run is ``null`` with ``"diverged": true``.

    ``run``: :func:`run_info` (version, date, command line, seed), stored under ``"run"``.
    """
    methods = {}
    for name, m in result.methods.items():
        cases = {}
        for case, fit in m.fit_percent.items():
            entry = {"fit_percent": _number(fit), "one_step_fit_percent": _number(m.one_step_fit_percent[case])}
            if math.isnan(fit):
                entry["diverged"] = True
            cases[case] = entry
        methods[name] = {
            "n_regions": int(m.model.n_regions_),
            "description": m.description,
            "hysteresis_compensated": m.compensated,
            "na": int(m.model.structure_.na),
            "nb": list(map(int, m.model.structure_.nb)),
            "fit_time_s": round(m.fit_time_s, 3),
            "stable_modes": [bool(ss.stable) for ss in m.model.state_space()],
            "cases": cases,
        }
    timings = {k: round(v, 3) for k, v in result.timings_s.items()}
    timings["total"] = round(total_time_s, 3)
    return {
        "schema": SCHEMA,
        "run": run if run is not None else run_info(result.config.seed),
        "seed": result.config.seed,
        "quick": result.config.quick,
        "sample_time_s": result.config.sample_time_s,
        "test_bed": {"sensor_noise_std_rpm": result.config.noise_std_rpm,
                     "logger_sample_time_s": result.config.logger_sample_time_s,
                     "identification_duration_s": result.config.identification_duration_s},
        "steady_state": {
            "points_per_sweep": result.sweeps.points_per_sweep,
            "max_hysteresis_gap_percent": round(float(np.max(result.sweeps.gap_percent)), 2),
            "calibration": result.calibration,
            "hysteresis_half_width_v": round(result.hysteresis_half_width_v, 4),
            "fracture_line": fracture_comparison(result.fracture),
        },
        "methods": methods,
        "best_selection": result.best_selection,
        "paper_reported_fit_percent": dict(PAPER_REPORTED_FIT),
        "timings_s": timings,
    }


def fit_table(summary: dict) -> str:
    """The fit table as fixed-width text (what ``hwpts reproduce`` prints)."""
    cases = ["case1", "case2", "case3", "case4"]
    lines = [f"{'method':22s} {'regions':>7s} " + " ".join(f"{c:>7s}" for c in cases), "-" * 62]
    for name, m in summary["methods"].items():
        cells = []
        for c in cases:
            fit = m["cases"][c]["fit_percent"]
            cells.append(f"{'diverged' if fit is None else f'{fit:.1f}':>7s}")
        lines.append(f"{name:22s} {m['n_regions']:>7d} " + " ".join(cells))
    paper = summary["paper_reported_fit_percent"]
    lines.append(f"{'paper (reported)':22s} {3:>7d} " + " ".join(f"{paper.get(c, '-'):>7}" for c in cases))
    lines.append("free-run fit % = 100 (1 - |y - yhat| / |y - mean(y)|)")
    return "\n".join(lines)
