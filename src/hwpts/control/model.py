"""The identified PWARX model bank as a controller designer sees it.

Built from a model file's document (schema ``hwpts.pwarx/1``: orders, signal names, per-region
``theta`` with the offset last, the partition as polyhedra {x : H_i x + g_i <= 0}, paper eq. 9),
never from the plant's equations. For region i the ARX model is (paper eqs. 5-7, 17)

    y(k) = sum_j a_ij y(k-j) + sum_j b_ij u1(k-nk1-j) + sum_j c_ij u2(k-nk2-j) + d_i

with u1 the (hysteresis-compensated) valve voltage [V] and u2 the measured pump speed [r/min].
The designer reads off each region its steady state (for feedforward), its static gains and the
step response of the valve channel (for PI tuning), and can run every region's one-step
predictor in parallel (for multiple-model control).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hwpts.errors import DataError

FLAT_GAIN_SHARE = 0.2
"""A region whose valve gain is below this share of the stiffest region's is 'flat' for feedforward."""

VALVE_WORDS = ("valve",)
PUMP_WORDS = ("pump",)
OTHER_OUTPUT_WORDS = ("motor_b", "pump", "pressure", "valve", "spool")  # an output that is not motor A's speed


SIGNAL_UNITS = ("V", "r/min", "r/min")
"""The units the controllers read the model's valve input, pump input and output in."""


def _check_units(inputs, output) -> None:
    """Refuse a model whose valve input, pump input or output is in another unit than the controllers
    command and measure (V, r/min, r/min) by its name's suffix (``pump_pressure_pa`` matched "pump"
    and was read as a speed in r/min). A unit given as free text (``identify --unit pump=rpm``) is
    not compared, as ``validate`` does not."""
    from hwpts.units import unit_from_name

    roles = ("valve input", "pump input", "output")
    for role, name, expected in zip(roles, [*inputs, output], SIGNAL_UNITS):
        unit = unit_from_name(name)
        if unit is not None and unit != expected:
            raise DataError(f"the model's {role} {name!r} is in {unit}; the controllers read the valve voltage in V, "
                            f"the pump speed and motor A's speed in r/min")


@dataclass(frozen=True)
class RegionDesign:
    """What a controller designer needs of one region's model (valve channel: u1 -> y)."""

    region: int
    kind: str
    valve_gain_rpm_per_v: float
    """Static gain dy/du1 [r/min per V] (nan when the region has no dynamics, e.g. 'zero')."""
    pump_gain: float
    """Static gain dy/du2 [r/min per r/min]."""
    time_constant_s: float
    """Time to 63 % of the valve step response, minus the dead time [s]."""
    dead_time_s: float
    """Time to 5 % of the valve step response [s]."""
    stable: bool


class ModelBank:
    """A PWARX model of (valve voltage, pump speed) -> motor A speed, from a model-file document.

    Parameters
    ----------
    document : dict
        The model file's JSON object (``hwpts.io.models.model_to_dict`` or the file read as JSON).
    sample_time : float
        The model's sample period [s] (model files do not record it; ``hwpts reproduce`` uses 50 ms).
    """

    def __init__(self, document: dict, sample_time: float = 0.05):
        if not (math.isfinite(sample_time) and sample_time > 0):
            raise DataError(f"model sample time must be > 0 s, got {sample_time!r}")
        st = document["structure"]
        if st.get("output_powers"):
            raise DataError(f"the model's regressor has the output power terms {st['output_powers']}: the "
                            f"controllers are designed from affine modes; identify without them "
                            f"(hwpts identify --output-powers none)")
        names = [str(n) for n in st["input_names"]]
        if len(names) != 2 or not any(w in names[0].lower() for w in VALVE_WORDS) \
                or not any(w in names[1].lower() for w in PUMP_WORDS):
            raise DataError(f"the model's inputs must be the valve voltage and the pump speed (in that order); "
                            f"the model has inputs {names}")
        self.input_names = tuple(names)
        self.output_name = str(st["output_name"])
        if any(w in self.output_name.lower() for w in OTHER_OUTPUT_WORDS):
            # a model of motor B's speed (or a pressure) designed controllers that steered motor A
            raise DataError(f"the model's output must be the main motor's (motor A's) speed, which the controllers "
                            f"hold; the model's output is {self.output_name!r}")
        _check_units(names, self.output_name)
        self.sample_time = float(sample_time)
        self.na = int(st["na"])
        nb, nk = st["nb"], st["nk"]
        self.nb = tuple(int(v) for v in (nb if isinstance(nb, list) else [nb, nb]))
        self.nk = tuple(int(v) for v in (nk if isinstance(nk, list) else [nk, nk]))
        self.constant = bool(st["constant"])
        self.theta = np.array([r["theta"] for r in document["regions"]], dtype=float)
        self.kinds = tuple(str(r.get("model", "affine")) for r in document["regions"])
        polys = document["partition"]["polyhedra"]
        nf = self.n_features
        self.H = [np.asarray(p["H"], dtype=float).reshape(-1, nf) for p in polys]
        self.g = [np.asarray(p["g"], dtype=float).reshape(-1) for p in polys]
        if self.theta.shape[1] != nf + 1:
            raise DataError(f"regions' theta have {self.theta.shape[1]} numbers, expected {nf + 1}")
        self.max_lag = max([self.na] + [k + b - 1 for b, k in zip(self.nb, self.nk) if b > 0] + [0])
        self.designs = [self._design(i) for i in range(self.n_regions)]
        counts = [int(r.get("n_train_samples", 0)) for r in document["regions"]]
        gains = [d.valve_gain_rpm_per_v for d in self.designs]
        usable = [i for i in range(self.n_regions) if math.isfinite(gains[i]) and self.designs[i].stable]
        if not usable:
            raise DataError("no region of the model has a finite, stable valve -> speed gain to design a controller from")
        main = max(usable, key=lambda i: (counts[i], abs(gains[i])))
        self.main_region = main
        """The region with the most training samples: its valve gain's sign is the plant's."""
        self.control_regions = tuple(i for i in usable if np.sign(gains[i]) == np.sign(gains[main]))
        stiff = max(abs(gains[i]) for i in self.control_regions)
        self.stiffest_region = max(self.control_regions, key=lambda i: abs(gains[i]))
        self.feedforward_regions = tuple(i for i in self.control_regions if abs(gains[i]) >= FLAT_GAIN_SHARE * stiff)
        """Regions whose steady state is well conditioned in the valve: a flat region (the pump-limited
        plateau, where the valve hardly moves the speed) would turn a small speed difference into volts."""
        """Regions a controller may design from: stable, and the valve acting with the main region's sign
        (a region whose fitted gain has the other sign, e.g. the closed valve hi >= 3.5 V where the motor
        only spins down, holds no usable operating point)."""

    # -- structure --------------------------------------------------------------------------
    @property
    def n_regions(self) -> int:
        """Number of modes of the bank."""
        return self.theta.shape[0]

    @property
    def n_features(self) -> int:
        """Length of the regressor ``na + nb_1 + nb_2``."""
        return self.na + sum(self.nb)

    def regressor(self, y_past, u1, u2) -> np.ndarray:
        """x(k) from histories, newest last: y_past ends at y(k-1), u1 and u2 end at u(k)."""
        x = np.empty(self.n_features)
        na = self.na
        for j in range(na):
            x[j] = y_past[-1 - j]
        pos = na
        for u, b, k in ((u1, self.nb[0], self.nk[0]), (u2, self.nb[1], self.nk[1])):
            for j in range(b):
                x[pos + j] = u[-1 - k - j]
            pos += b
        return x

    def steady_regressor(self, y: float, u1: float, u2: float) -> np.ndarray:
        """The regressor of a steady operating point: speed ``y`` [r/min], valve ``u1`` [V], pump ``u2`` [r/min] in every lag."""
        return np.concatenate([np.full(self.na, y), np.full(self.nb[0], u1), np.full(self.nb[1], u2)])

    def region(self, x) -> int:
        """Region of regressor x: the first polyhedron holding it, else the least violated (eq. 8)."""
        best, best_v = 0, math.inf
        for i, (h, g) in enumerate(zip(self.H, self.g)):
            if h.shape[0] == 0:
                return i
            v = float(np.max(h @ x + g))
            if v <= 0.0:
                return i
            if v < best_v:
                best, best_v = i, v
        return best

    def predict(self, x, region: int) -> float:
        """One-step prediction [r/min] of mode ``region`` from the regressor ``x`` (paper eq. 5)."""
        th = self.theta[region]
        return float(th[:-1] @ x + (th[-1] if self.constant else 0.0))

    # -- steady state ------------------------------------------------------------------------
    def _sums(self, i):
        th = self.theta[i]
        na, nb1 = self.na, self.nb[0]
        a = th[:na].sum()
        b = th[na:na + nb1].sum()
        c = th[na + nb1:na + nb1 + self.nb[1]].sum()
        d = th[-1] if self.constant else 0.0
        return a, b, c, d

    def steady_output(self, i: int, u1: float, u2: float) -> float:
        """Steady-state speed [r/min] of mode ``i`` at valve ``u1`` [V] and pump ``u2`` [r/min] (its DC gain and offset)."""
        a, b, c, d = self._sums(i)
        return (b * u1 + c * u2 + d) / (1.0 - a)

    def stiff_valve(self, y: float, u2: float) -> float:
        """The stiffest region's steady-state valve voltage for y at u2, whether or not it lies in that region."""
        a, b, c, d = self._sums(self.stiffest_region)
        return (y * (1.0 - a) - c * u2 - d) / b

    def steady_valve(self, y: float, u2: float, limits=(1.2, 3.8)):
        """(u1, region): the valve voltage holding output y at pump speed u2 in steady state.

        Each region's solution is checked against the partition; the consistent one wins (the one
        with the largest valve gain when several are). None when no region can hold y.
        """
        found = []
        for i in self.feedforward_regions:
            a, b, c, d = self._sums(i)
            if self.kinds[i] == "zero" or abs(b) < 1e-9:
                continue
            u1 = (y * (1.0 - a) - c * u2 - d) / b
            if not (limits[0] - 0.5 <= u1 <= limits[1] + 0.5):
                continue
            if self.region(self.steady_regressor(y, u1, u2)) == i:
                found.append((abs(self.designs[i].valve_gain_rpm_per_v), u1, i))
        if not found:
            return None, None
        found.sort(reverse=True)
        return found[0][1], found[0][2]

    # -- designs -------------------------------------------------------------------------------
    def step_response(self, i: int, n: int = 400) -> np.ndarray:
        """Unit step of u1 (region i held), the deviation of y from its start, n samples."""
        th = self.theta[i]
        na, nb1 = self.na, self.nb[0]
        a = th[:na]
        b = th[na:na + nb1]
        y = np.zeros(n + na)
        for k in range(n):
            acc = 0.0
            for j in range(na):
                acc += a[j] * y[na + k - 1 - j]
            for j in range(nb1):
                if k - self.nk[0] - j >= 0:
                    acc += b[j]
            y[na + k] = acc
        return y[na:]

    def _design(self, i: int) -> RegionDesign:
        a, b, c, _ = self._sums(i)
        kind = self.kinds[i]
        th = self.theta[i]
        roots = np.roots(np.r_[1.0, -th[:self.na]]) if self.na else np.zeros(0)
        stable = bool(np.all(np.abs(roots) < 1.0))
        if kind == "zero" or abs(1.0 - a) < 1e-9:
            return RegionDesign(i, kind, float("nan"), float("nan"), float("nan"), float("nan"), stable)
        kv = b / (1.0 - a)
        kp = c / (1.0 - a)
        tau, theta = float("nan"), float("nan")
        if stable and abs(kv) > 1e-9:
            s = self.step_response(i) / kv
            t = np.arange(1, s.size + 1) * self.sample_time
            i5 = int(np.argmax(s >= 0.05))
            i63 = int(np.argmax(s >= 0.632))
            theta = float(t[i5] - self.sample_time) if s[i5] >= 0.05 else 0.0
            tau = float(max(t[i63] - theta, self.sample_time)) if s[i63] >= 0.632 else float("nan")
        return RegionDesign(i, kind, float(kv), float(kp), tau, theta, stable)
