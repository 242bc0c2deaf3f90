"""The paper's pipeline as code (sections V.A-D), run on the simulated test bed.

1. Recording (V.A): up/down steady-state sweeps, their gap (Fig. 4) and average (Fig. 5); the valve's
   hysteresis width read off the sweeps; an identification run and the four validation cases on
   the test bed (hysteresis, droop, sensor noise).
2. Segmentation (V.B): the fracture of the averaged surface from the data, the space line through
   two operating points on it (eq. 15), its projection (eq. 16), and hi >= 3.5 V as a third
   cluster; also the paper's alternatives (average, z-score, k-means) and the library's learned
   partitions.
3. Regression (V.C): na = 5, nb = 4 (nk = 0, as eq. 18 uses hi(k)), least squares per region (eq. 17).
4. Validation (V.D): each model driven by the valve command and the *measured* pump speed of each
   case, free run with the switching rule, fit % against the measured motor A speed.

Hysteresis compensation. The paper averages the up and down surfaces so that its model stands for
the averaged valve. We go one step further and make that usable in free run: the model's valve
input is the command passed through a play operator of the half-width read off the sweeps (the
inverse of the averaging: it tells the model which branch the valve is on). ``paper_uncompensated``
keeps the raw command, as the paper's model does, to show what that costs.

The pipeline is a function of (config, seed): the same seed gives the same numbers.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from hwpts.dataset import IODataset
from hwpts.errors import HwptsError
from hwpts.experiments.sweeps import (
    PAPER_FRACTURE,
    Fracture,
    estimate_hysteresis,
    find_fracture,
    record_sweeps,
)
from hwpts.identification import PWARX, Hyperplane, fit_percent
from hwpts.identification.segmentation.hyperplane import fracture_hyperplane
from hwpts.plant import CASE_NAMES, PlantParameters, SweepResult, TestBed, identification_excitation, play_operator
from hwpts.plant import validation_case as _case_profile
from hwpts.units import units_from_names

PAPER_REPORTED_FIT = {"case2": 92, "case3": 93, "case4": 91}
"""Fit % the paper reports for its cases 2-4 (section V.D; no number is printed for case 1)."""

NA, NB, NK = 5, 4, 0
"""The paper's orders (section V.C): five poles and three zeros give na = 5, nb = 4; eq. 18 uses hi(k)."""

CLOSED_VOLTAGE = 3.5
"""The third cluster: valve voltages at or above 3.5 V close outlet A (section V.B, eq. 18)."""

COMPENSATED_INPUT = "valve_voltage_play_v"
"""Name of the hysteresis-compensated valve input (the command through the estimated play)."""


class StageError(HwptsError, RuntimeError):
    """A stage of the pipeline failed; the message names the stage."""


@dataclass(frozen=True)
class ReproduceConfig:
    """Sizes of a run. :meth:`quick_run` is a smaller run for tests: the same figures and files,
    but one learned segmentation (8 models, not 9) on a shorter record."""

    seed: int = 0
    quick: bool = False
    identification_duration_s: float = 1200.0
    logger_sample_time_s: float = 0.01
    noise_std_rpm: float = 2.0
    """Speed sensors' noise on the test bed [r/min]."""
    decimation: int = 5
    """Identification and validation use every 5th logger sample (block mean): 50 ms."""
    learned_methods: tuple[str, ...] = ("clustering", "alternating")
    polish_candidates: bool = True
    """Whether ``best`` also tries simulation-error polishing (slow to converge on short data)."""

    @classmethod
    def full(cls, seed: int = 0) -> ReproduceConfig:
        """The full run of ``hwpts reproduce`` with ``seed``."""
        return cls(seed=seed)

    @classmethod
    def quick_run(cls, seed: int = 0) -> ReproduceConfig:
        """A smaller run for tests: a 200 s identification record, ``alternating`` the one learned
        segmentation (8 models, not 9), no polished candidates; the same figures and files otherwise."""
        return cls(seed=seed, quick=True, identification_duration_s=200.0, learned_methods=("alternating",),
                   polish_candidates=False)

    @property
    def sample_time_s(self) -> float:
        """Sample period of the identification data [s]: the logger's period times the decimation."""
        return self.logger_sample_time_s * self.decimation


@dataclass
class MethodResult:
    """One identification method: its model, how it sees the data, and its fit per case."""

    name: str
    description: str
    model: PWARX
    compensated: bool
    fit_percent: dict = field(default_factory=dict)
    one_step_fit_percent: dict = field(default_factory=dict)
    simulated: dict = field(default_factory=dict)
    fit_time_s: float = 0.0


@dataclass
class ReproduceResult:
    """Everything a run produced (figures and files are written from it by the CLI and reporting)."""

    config: ReproduceConfig
    sweeps: SweepResult
    hysteresis_half_width_v: float
    fracture: Fracture
    identification: IODataset
    cases: dict
    methods: dict
    best_selection: list
    calibration: list
    timings_s: dict


CALIBRATION_POINTS = ((1.8, 904.0, 1566.0), (2.95, 328.0, 489.5), (1.5, 600.0, 1000.0), (2.375, 600.0, 997.5))
"""(valve [V], pump [r/min], motor A [r/min]) the paper prints (section V.B points, Fig. 10 start, eq. 15 at t = 0.5)."""


def calibrate(parameters: PlantParameters) -> list[dict]:
    """The simulator's steady states at the operating points the paper prints (docs/plant.md section 6)."""
    from hwpts.plant import steady_state

    v, w, paper = (np.array(c) for c in zip(*CALIBRATION_POINTS))
    model = steady_state(parameters, v, w).motor_a_speed_rpm
    return [{"valve_voltage_v": float(a), "pump_speed_rpm": float(b), "paper_rpm": float(c), "model_rpm": round(float(d), 1)}
            for a, b, c, d in zip(v, w, paper, model)]


def block_decimate(dataset: IODataset, factor: int) -> IODataset:
    """Every ``factor`` samples averaged into one (an anti-alias block mean), time of the first."""
    if factor == 1:
        return dataset
    n = (dataset.n_samples // factor) * factor

    def mean(a):
        return a[:n].reshape(n // factor, factor, *a.shape[1:]).mean(axis=1)

    return IODataset(dataset.time[:n:factor], mean(dataset.inputs), mean(dataset.output), dataset.input_names,
                     dataset.output_name, {k: mean(v) for k, v in dataset.extra.items()})


def compensate(dataset: IODataset, half_width: float) -> IODataset:
    """Add the hysteresis-compensated valve input: the command through a play of ``half_width``.

    The play starts centred on the first command (the test bed's convention, and the natural guess
    when the valve's history is unknown).
    """
    v = dataset.input("valve_voltage_v")
    comp = play_operator(v, half_width)
    inputs = np.column_stack([comp, dataset.input("pump_speed_rpm")])
    return IODataset(dataset.time, inputs, dataset.output, (COMPENSATED_INPUT, "pump_speed_rpm"),
                     dataset.output_name, dict(dataset.extra, valve_voltage_v=v))


def paper_hyperplanes(fracture: Fracture, valve_input: str) -> list[Hyperplane]:
    """The paper's partition as a decision list: hi >= 3.5 V, then the plateau side of eq. 16."""
    columns = [valve_input, "pump_speed_rpm"]
    return [Hyperplane([1.0], -CLOSED_VOLTAGE, columns[:1]),
            fracture_hyperplane(fracture.slope, fracture.intercept, columns)]


def _method_specs(config: ReproduceConfig, fracture: Fracture, seed: int):
    """(name, description, compensated, estimator factory) for every method of the run."""
    raw = "valve_voltage_v"
    specs = [
        ("average", "one ARX model over all data (the paper's 'average' segmentation)", True,
         lambda: PWARX(NA, NB, NK, segmentation="average")),
        ("zscore", "two regions by the z-score of the observations (paper V.B)", True,
         lambda: PWARX(NA, NB, NK, segmentation="zscore", random_state=seed)),
        ("kmeans", "three k-means clusters of the regressors (paper V.B)", True,
         lambda: PWARX(NA, NB, NK, n_regions=3, segmentation="kmeans", random_state=seed)),
        ("paper", "fracture line found in the data (eqs. 15-16) and hi >= 3.5 V, least squares per region "
                  "(eq. 17), hysteresis-compensated valve input", True,
         lambda: PWARX(NA, NB, NK, segmentation="hyperplane",
                       hyperplanes=paper_hyperplanes(fracture, COMPENSATED_INPUT))),
        ("paper_zero_mode", "as 'paper' with the third region fixed to wA = 0, literally eq. 18", True,
         lambda: PWARX(NA, NB, NK, segmentation="hyperplane", region_models=["zero", "affine", "affine"],
                       hyperplanes=paper_hyperplanes(fracture, COMPENSATED_INPUT))),
        ("paper_uncompensated", "as 'paper' on the raw valve command (the averaged-valve model alone)", False,
         lambda: PWARX(NA, NB, NK, segmentation="hyperplane", hyperplanes=paper_hyperplanes(fracture, raw))),
    ]
    for name in config.learned_methods:
        specs.append((name, f"learned partition '{name}' of the identification library, 3 regions", True,
                      (lambda n=name: PWARX(NA, NB, NK, n_regions=3, segmentation=n, random_state=seed))))
    return specs


def _best_search(fracture: Fracture, polish: bool):
    """The model search behind ``best``: (labels, PWARXSearch) over the fracture partition with two
    orders (and the simulation-error polish), scored on the last 20 % of the identification run."""
    from hwpts.identification import HoldoutSplit, PWARXSearch

    hps = paper_hyperplanes(fracture, COMPENSATED_INPUT)
    grid = [{"output_order": NA, "input_order": NB}, {"output_order": 3, "input_order": 3}]
    labels = ["fracture partition, na=5 nb=4", "fracture partition, na=3 nb=3"]
    if polish:
        grid += [{**g, "polish": True} for g in grid]
        labels += [f"{label}, simulation-error polish" for label in labels]
    base = PWARX(NA, NB, NK, segmentation="hyperplane", hyperplanes=hps)
    # tolerance 0 on one held-out block: the best held-out fit wins outright (the candidates share
    # one partition)
    return labels, PWARXSearch(base, grid, cv=HoldoutSplit(0.2), tolerance=0.0, n_standard_errors=0.0,
                               try_polish=False)


def _score(model: PWARX, data: IODataset) -> tuple[float, float, np.ndarray]:
    """(free-run fit %, one-step fit %, simulated output) - nan fit when the free run diverges."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = model.simulate(data)
        one = model.predict(data)
    m = model.structure_.max_lag
    y = data.output
    free = float("nan") if sim.diverged else fit_percent(y[m:], sim.output[m:])
    return free, fit_percent(y[m:], one[m:]), sim.output


def run(config: ReproduceConfig, progress: Callable[[str], None] | None = None) -> ReproduceResult:
    """Run the whole pipeline. ``progress(stage_name)`` is called as each stage starts."""
    timings = {}
    say = progress or (lambda _stage: None)
    seed = config.seed

    def stage(name):
        say(name)
        return time.perf_counter()

    try:
        t0 = stage("steady-state sweeps")
        sweeps = record_sweeps(PlantParameters.paper(), progress=False)
        r_hat = estimate_hysteresis(sweeps)
        calibration = calibrate(PlantParameters.averaged())
        timings["sweeps"] = time.perf_counter() - t0
    except HwptsError as error:
        raise StageError(f"stage 'sweeps' failed: {error}") from None

    try:
        t0 = stage("segmentation (fracture line)")
        fracture = find_fracture(sweeps)
        timings["segmentation"] = time.perf_counter() - t0
    except HwptsError as error:
        raise StageError(f"stage 'segmentation' failed: {error}") from None

    try:
        t0 = stage("test-bed recordings")
        bed = TestBed(sample_time=config.logger_sample_time_s, noise_std_rpm=config.noise_std_rpm)
        excitation = identification_excitation(config.identification_duration_s, config.logger_sample_time_s, seed=seed)
        ident_raw, _ = bed.record(excitation, seed=seed)
        identification = block_decimate(ident_raw, config.decimation)
        cases = {}
        for i, name in enumerate(CASE_NAMES):
            raw, _ = bed.record(_case_profile(name, config.logger_sample_time_s), seed=seed + 1 + i)
            cases[name] = block_decimate(raw, config.decimation)
        timings["recording"] = time.perf_counter() - t0
    except HwptsError as error:
        raise StageError(f"stage 'recording' failed: {error}") from None

    train = {True: compensate(identification, r_hat), False: identification}
    valid = {name: {True: compensate(ds, r_hat), False: ds} for name, ds in cases.items()}

    # the signals' units from their names (motor_a_speed_rpm: r/min), kept in every model as
    # `hwpts identify` keeps them, so that data whose columns say other units are refused
    units = {comp: units_from_names([*ds.input_names, ds.output_name]) for comp, ds in train.items()}
    try:
        t0 = stage("identification")
        methods = {}
        for name, description, comp, factory in _method_specs(config, fracture, seed):
            t1 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                model = factory().fit(train[comp], units=units[comp])
            methods[name] = MethodResult(name, description, model, comp, fit_time_s=time.perf_counter() - t1)
        # best: choose on a held-out tail of the identification data only, then refit on all of it
        t1 = time.perf_counter()
        labels, search = _best_search(fracture, config.polish_candidates)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            search.fit(train[True], units=units[True])
        best = search.best_estimator_
        selection = []
        for label, row in zip(labels, search.cv_results_):
            score = row["mean_fit_percent"]
            selection.append({"candidate": label, "held_out_fit_percent": None if score is None else round(score, 3),
                              **({"chosen": True} if row.get("chosen") else {})})
        label = next(s["candidate"] for s in selection if s.get("chosen"))
        methods["best"] = MethodResult("best", f"the package's recommendation: hysteresis-compensated input, {label} "
                                               "(chosen by held-out fit on the identification data)",
                                       best, True, fit_time_s=time.perf_counter() - t1)
        timings["identification"] = time.perf_counter() - t0
    except HwptsError as error:
        raise StageError(f"stage 'identification' failed: {error}") from None

    try:
        t0 = stage("validation")
        for result in methods.values():
            for name in CASE_NAMES:
                free, one, sim = _score(result.model, valid[name][result.compensated])
                result.fit_percent[name] = free
                result.one_step_fit_percent[name] = one
                result.simulated[name] = sim
        timings["validation"] = time.perf_counter() - t0
    except HwptsError as error:
        raise StageError(f"stage 'validation' failed: {error}") from None

    return ReproduceResult(config, sweeps, r_hat, fracture, train[True],
                           {name: valid[name][True] for name in CASE_NAMES}, methods, selection, calibration, timings)


def fracture_comparison(fracture: Fracture) -> dict:
    """The fracture line found beside the paper's eq. (16)."""
    pumps = np.array([200.0, 1000.0])
    ours = fracture.voltage_at(pumps)
    paper = (pumps - PAPER_FRACTURE[1]) / PAPER_FRACTURE[0]
    return {
        "slope_rpm_per_v": round(fracture.slope, 3),
        "intercept_rpm": round(fracture.intercept, 2),
        "paper_slope_rpm_per_v": PAPER_FRACTURE[0],
        "paper_intercept_rpm": PAPER_FRACTURE[1],
        "least_squares_slope_rpm_per_v": round(fracture.fit_slope, 3),
        "least_squares_intercept_rpm": round(fracture.fit_intercept, 2),
        "operating_points": [[round(float(x), 4) for x in p] for p in fracture.operating_points],
        "max_voltage_difference_v": round(float(np.max(np.abs(ours - paper))), 4),
    }
