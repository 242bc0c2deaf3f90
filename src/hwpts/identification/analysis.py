"""Analysis and export of an identified model: each mode as a python-control state-space system.

Each mode of a PWARX model is the affine system of eq. 7 (:mod:`hwpts.identification.statespace`)::

    x_{k+1} = A x_k + B u_k + e
    y_k     = C x_k + D u_k + c

python-control has no affine systems, so :func:`to_control` returns the linear system with the
offset as one more input held at 1: ``B_aug = [B  e]``, ``D_aug = [D  c]``; its input names are the
model's inputs followed by ``"offset"``. Restricted to one mode (the switching ignored), the free
run of hwpts and the response of that system from the same initial state agree to rounding.

python-control is an optional dependency (``pip install hwpts[control]``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from hwpts.errors import DataError, ParameterError

__all__ = ["to_control", "mode_initial_state", "ResidualAnalysis", "residual_analysis", "correlation",
           "beyond_training_range"]


def beyond_training_range(model, inputs, output) -> dict:
    """``{signal name: {"share", "training_range"}}``: each signal's share of the samples (after the
    model's initial conditions) outside the range the fitted ``model`` was identified on, with that
    range. A PWA model extrapolates its outer pieces there, which a fit % alone does not say (a tank
    model identified below its overflow level, validated above it). Signals whose range the model
    does not hold (a model file without it, or ``PWARX.from_parts``'s +-1e300) are left out."""
    st = model.structure_
    m = st.max_lag
    u = np.asarray(inputs, dtype=float).reshape(len(output), -1)
    y = np.asarray(output, dtype=float)
    ranges = [(st.output_name, model.output_range_, y[m:]),
              *((name, r, u[m:, j]) for j, (name, r) in enumerate(zip(st.input_names, model.input_ranges_)))]
    out = {}
    for name, (lo, hi), values in ranges:
        if not (abs(lo) < 1e299 and abs(hi) < 1e299):
            continue
        out[name] = {"share": round(float(np.mean((values < lo) | (values > hi))), 6),
                     "training_range": [float(lo), float(hi)]}
    return out


def _control():
    try:
        import control
    except ImportError:  # pragma: no cover - depends on the environment
        raise ParameterError("exporting to python-control needs the optional dependency: "
                             "pip install 'hwpts[control]'") from None
    return control


def to_control(model, dt=None) -> list:
    """One python-control ``StateSpace`` per mode of a fitted ``PWARX`` (offset as the last input,
    named ``offset`` unless an input is: :func:`~hwpts.identification.statespace.offset_input_name`).

    ``dt``: the sample time in seconds; ``None`` gives a discrete-time system with an unspecified
    sample time (``dt=True`` in python-control).
    """
    _affine_only(model, "to_control")
    control = _control()
    if dt is not None and (isinstance(dt, (bool, np.bool_)) or not isinstance(dt, (int, float, np.integer, np.floating))
                           or not np.isfinite(dt) or dt <= 0):
        raise ParameterError(f"dt must be a positive number of seconds or None, got {dt!r}")
    from hwpts.identification.statespace import offset_input_name

    out = []
    names = [*model.structure_.input_names, offset_input_name(model.structure_.input_names)]
    for i, ss in enumerate(model.state_space()):
        B = np.column_stack([ss.B, ss.e]) if ss.A.size else np.zeros((0, len(names)))
        D = np.concatenate([ss.D.ravel(), [ss.c]]).reshape(1, -1)
        sys = control.ss(ss.A, B, ss.C, D, True if dt is None else float(dt),
                         inputs=names, outputs=[model.structure_.output_name], name=f"mode{i + 1}")
        out.append(sys)
    return out


def mode_initial_state(structure, inputs, output, k: int) -> np.ndarray:
    """The state ``x_k`` of eq. 7 from measured signals: ``[y(k-1..k-na), u_j(k-1..k-m_j)]``."""
    u = np.asarray(inputs, dtype=float).reshape(len(output), -1)
    y = np.asarray(output, dtype=float)
    x = [y[k - i] for i in range(1, structure.na + 1)]
    for j, (nb, nk) in enumerate(zip(structure.nb, structure.nk)):
        m = nk + nb - 1 if nb > 0 else 0
        x += [u[k - i, j] for i in range(1, m + 1)]
    return np.asarray(x, dtype=float)


def correlation(a: np.ndarray, b: np.ndarray, lags: int) -> np.ndarray:
    """Normalised cross-correlation ``r_ab(tau) = sum_t a(t) b(t-tau) / (N sd_a sd_b)``, tau = 0..lags.

    Both signals have their mean removed; ``correlation(e, e, L)[0] = 1``.
    """
    a = np.asarray(a, dtype=float) - np.mean(a)
    b = np.asarray(b, dtype=float) - np.mean(b)
    n = a.shape[0]
    denom = n * np.std(a) * np.std(b)
    if denom == 0:
        return np.full(lags + 1, np.nan)
    return np.array([a[tau:] @ b[:n - tau] for tau in range(lags + 1)]) / denom


EXACT_SHARE = 1e-9  # residual rms, as a share of the output's standard deviation, of an exact model


@dataclass(frozen=True)
class ResidualAnalysis:
    """Whiteness and independence tests of the one-step residuals (MATLAB's ``resid``).

    A correct model leaves residuals ``e(t) = y(t) - yhat(t|t-1)`` that are white (autocorrelation
    zero at every lag > 0) and uncorrelated with past inputs (cross-correlation zero at lags >= 0).
    Under that hypothesis each normalised correlation is about normal with standard deviation
    ``1/sqrt(N)``: the band ``+-z/sqrt(N)`` holds it with probability ``confidence`` (99 %:
    ``z = 2.576``), so about 1 % of the lags fall outside by chance.

    Attributes
    ----------
    residuals : ndarray
        One-step residuals after the initial conditions (length ``N``), in the output's unit.
    lags : int
    confidence : float
    band : float
        Half-width ``z/sqrt(N)`` of the confidence band.
    autocorrelation : ndarray, shape (lags + 1,)
        ``r_ee(tau)``, tau = 0..lags (``r_ee(0) = 1``; lag 0 is not tested).
    cross_correlation : dict of str -> ndarray, shape (lags + 1,)
        ``r_eu(tau)`` per input: residual at ``t`` against the input at ``t - tau``, tau = 0..lags.
    """

    residuals: np.ndarray
    lags: int
    confidence: float
    band: float
    autocorrelation: np.ndarray
    cross_correlation: dict
    output_spread: float = float("nan")

    @property
    def exact(self) -> bool:
        """Whether the residuals are rounding errors (rms under :data:`EXACT_SHARE` of the output's
        standard deviation ``output_spread``): the model reproduces the data, and the correlation
        tests, which assume a noise, say nothing (the rounding errors of an exact model are
        correlated with its regressors)."""
        rms = float(np.sqrt(np.mean(self.residuals ** 2)))
        return bool(rms <= EXACT_SHARE * self.output_spread)

    @property
    def n_samples(self) -> int:
        """Number of residuals ``N`` (samples after the initial conditions)."""
        return int(self.residuals.shape[0])

    def outside_share(self) -> dict:
        """Share of tested lags outside the band: autocorrelation (lags 1..L), each input (0..L), all.

        A correlation that is undefined (a constant input, such as a pump speed held through a valve
        test, or constant residuals: no spread to normalise by) is not tested: its share is None
        (it was counted as inside the band, every lag: "uncorrelated")."""
        def outside(values):
            values = np.asarray(values, dtype=float)
            return None if not np.all(np.isfinite(values)) else np.abs(values) > self.band

        auto = outside(self.autocorrelation[1:])
        cross = {k: outside(v) for k, v in self.cross_correlation.items()}
        tested = [v for v in (auto, *cross.values()) if v is not None]
        mean = lambda v: None if v is None else float(np.mean(v))  # noqa: E731
        return {"autocorrelation": mean(auto),
                "cross_correlation": {k: mean(v) for k, v in cross.items()},
                "all": float(np.mean(np.concatenate(tested))) if tested else None}

    def to_dict(self) -> dict:
        """JSON-ready: the correlations, the band and the shares of lags outside it."""
        share = self.outside_share()
        rms = float(np.sqrt(np.mean(self.residuals ** 2)))
        return {
            "n_residuals": self.n_samples, "residual_rms": rms, "lags": self.lags,
            "confidence": self.confidence, "band": self.band,
            "autocorrelation": [float(v) for v in self.autocorrelation],
            "cross_correlation": {k: [float(x) for x in v] for k, v in self.cross_correlation.items()},
            "outside_share": share,
            "white": None if share["autocorrelation"] is None else share["autocorrelation"] <= 0.05,
            # False where a tested input is correlated; None where the tested ones are not but some
            # input could not be tested (constant)
            "independent_of_inputs": False if any(v is not None and v > 0.05 for v in share["cross_correlation"].values())
            else None if None in share["cross_correlation"].values() else True,
            "untested_inputs": [k for k, v in share["cross_correlation"].items() if v is None],
            "exact": self.exact,
        }


MAX_CONFIDENCE = 0.999999999  # a band's level: beyond it the band's normal quantile is inf or nearly


def residual_analysis(model, inputs, output, lags: int = 25, confidence: float = 0.99) -> ResidualAnalysis:
    """Residual tests of a fitted ``PWARX`` on measured data (see :class:`ResidualAnalysis`).

    ``lags``: the largest lag tested (samples); ``confidence``: of the band (0.5 < c <= 0.999999999).
    """
    if isinstance(lags, bool) or not isinstance(lags, (int, np.integer)) or lags < 1:
        raise ParameterError(f"lags must be an int >= 1, got {lags!r}")
    if not 0.5 < float(confidence) <= MAX_CONFIDENCE:  # 1 - 1e-16: a band of +-inf, every residual white
        raise ParameterError(f"confidence must lie in (0.5, {MAX_CONFIDENCE}], got {confidence!r}")
    yhat = model.predict(inputs, output)
    m = model.structure_.max_lag
    y = np.asarray(output, dtype=float).ravel()
    e = y[m:] - yhat[m:]
    if e.shape[0] <= lags + 1:
        raise DataError(f"lags {lags}: expected at most {max(e.shape[0] - 2, 0)} for {e.shape[0]} residuals, "
                        f"got {lags}; use fewer lags or more data")
    u = np.asarray(inputs, dtype=float).reshape(y.shape[0], -1)[m:]
    band = float(norm.ppf(0.5 + float(confidence) / 2) / np.sqrt(e.shape[0]))
    cross = {name: correlation(e, u[:, j], lags) for j, name in enumerate(model.structure_.input_names)}
    return ResidualAnalysis(e, int(lags), float(confidence), band, correlation(e, e, lags), cross,
                            float(np.std(y[m:])))


def state_space_export(model) -> dict:
    """Every mode's affine state space (eq. 7) and the partition, as plain arrays for export.

    Returns a dict: ``sample_time_s`` (or None), ``inputs``, ``output``, ``units``,
    ``state_names``, ``regressor_names`` and per mode ``A``, ``B``, ``C``, ``D``, ``e`` (state
    offset), ``c`` (output offset), ``poles``; ``H``, ``g`` per region: the region is
    ``{x : H x + g <= 0}`` over the regressor vector named ``regressor_names`` (eq. 9).
    """
    _affine_only(model, "the state-space export")
    st = model.structure_
    modes = []
    for i, ss in enumerate(model.state_space()):
        modes.append({"region": i + 1, "model": model.region_models_[i], "A": np.atleast_2d(ss.A),
                      "B": np.asarray(ss.B).reshape(ss.A.shape[0], st.n_inputs),
                      "C": np.asarray(ss.C).reshape(1, ss.A.shape[0]), "D": np.asarray(ss.D).reshape(1, st.n_inputs),
                      "e": np.asarray(ss.e).reshape(ss.A.shape[0]), "c": float(ss.c),
                      "poles": np.asarray(ss.poles)})
    part = model.partition_
    return {
        "sample_time_s": getattr(model, "sample_time_", None),
        "inputs": list(st.input_names), "output": st.output_name,
        "units": dict(getattr(model, "units_", {}) or {}),
        "state_names": _state_names(st),
        "regressor_names": list(st.feature_names),
        "modes": modes,
        "H": [np.asarray(h) for h in part.H], "g": [np.asarray(g) for g in part.g],
    }


def _affine_only(model, what: str) -> None:
    """Refuse a model with power terms of the output: its modes are not affine state-space systems."""
    powers = model.structure_.output_powers
    if powers:
        raise ParameterError(f"{what} needs affine modes; this model's regressor has the output power terms "
                             f"{list(powers)} (output_powers), which no state-space system holds")


def _state_names(structure) -> list[str]:
    """Names of the state of eq. 7: past outputs, then each input's past samples."""
    names = [f"{structure.output_name}(k-{i})" for i in range(1, structure.na + 1)]
    for name, nb, nk in zip(structure.input_names, structure.nb, structure.nk):
        m = nk + nb - 1 if nb > 0 else 0
        names += [f"{name}(k-{i})" for i in range(1, m + 1)]
    return names
