"""Steady-state recordings and what the paper reads off them (section V.A-B).

- :func:`record_sweeps`: up and down sweeps on the 27 x 81 grid (2187 points each, Figs. 3-5);
- :func:`estimate_hysteresis`: the valve's play half-width from the horizontal shift between the
  up and down surfaces (both are the same surface of the effective command, shifted by +-r);
- :func:`find_fracture`: the fracture of the averaged surface, located per pump speed by a hinge
  fit, then the paper's construction: two operating points on it, the space line through them
  (eq. 15), its projection on the input plane (eq. 16).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hwpts.errors import IdentificationError
from hwpts.identification.segmentation.hyperplane import project_space_line, space_line
from hwpts.plant import PlantParameters, SweepResult, sweep

PAPER_FRACTURE = (-486.41, 1755.2)
"""Slope [r/min per V] and intercept [r/min] of the paper's eq. (16)."""

PAPER_POINT_PUMP_SPEEDS = (328.0, 904.0)
"""Pump speeds [r/min] of the paper's two operating points on the fracture (section V.B)."""

LOCAL_WINDOW_V = 0.5
"""Half-width [V] of the window of the second, local hinge fit around a sweep's kink."""

DEFAULT_VOLTAGES = np.linspace(1.2, 3.8, 27)
DEFAULT_PUMP_SPEEDS = np.linspace(200.0, 1000.0, 81)


def record_sweeps(parameters: PlantParameters | None = None, voltages=DEFAULT_VOLTAGES,
                  pump_speeds=DEFAULT_PUMP_SPEEDS, progress: bool | None = None) -> SweepResult:
    """Up and down steady-state sweeps of the test bed's valve (hysteresis on, as the rig)."""
    return sweep(parameters or PlantParameters.paper(), voltages, pump_speeds, progress=progress)


def estimate_hysteresis(result: SweepResult, resolution: float = 1e-3) -> float:
    """Half-width r [V] of the valve's play from the two sweeps.

    The up sweep sees v_eff = v - r and the down sweep v_eff = v + r, so where the surface slopes
    down(v) = up(v + 2r). The shift 2r minimises the mean squared difference over the sloped parts
    of all pump-speed columns (linear interpolation of the up sweep), coarse then fine.
    """
    v = result.voltages_v
    if v.size < 3:
        raise IdentificationError("estimating the hysteresis needs sweeps of at least 3 voltages")
    up, down = result.up_rpm, result.down_rpm
    plateau = np.median(up[: max(2, v.size // 4)], axis=0)
    sloped = (down > 0.05 * plateau) & (down < 0.95 * plateau)  # (n_v, n_pump)
    step = np.diff(v).mean()

    def cost(d):
        x = v + d
        inside = sloped & (x <= v[-1])[:, None]
        if inside.sum() < 0.25 * sloped.sum() or not np.any(inside):
            return np.inf
        i = np.clip(np.searchsorted(v, x, side="right") - 1, 0, v.size - 2)
        w = (x - v[i]) / (v[i + 1] - v[i])
        up_shifted = up[i] * (1 - w)[:, None] + up[i + 1] * w[:, None]
        diff = np.where(inside, down - up_shifted, 0.0)
        return float(np.sum(diff * diff) / inside.sum())

    coarse = np.arange(0.0, min(1.0, np.ptp(v) / 2), step / 10)
    best = coarse[int(np.argmin([cost(d) for d in coarse]))]
    fine = np.arange(max(0.0, best - step / 10), best + step / 10, resolution)
    costs = [cost(d) for d in fine]
    if not np.isfinite(np.min(costs)):
        raise IdentificationError("the sweeps have no sloped part to compare: no hysteresis estimate")
    return float(fine[int(np.argmin(costs))] / 2.0)


@dataclass(frozen=True)
class Fracture:
    """The fracture line of the averaged surface (section V.B).

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        (valve voltage [V], pump speed [r/min], motor A speed [r/min]) of the fracture per pump speed.
    operating_points : ndarray, shape (2, 3)
        The two points the space line is drawn through (nearest the paper's pump speeds).
    line_origin, line_direction : ndarray, shape (3,)
        The space line (eq. 15): point(t) = origin + t * direction.
    slope, intercept : float
        Its projection on the input plane (eq. 16): pump speed = slope * voltage + intercept.
    fit_slope, fit_intercept : float
        A least-squares line through all fracture points, for comparison.
    """

    points: np.ndarray
    operating_points: np.ndarray
    line_origin: np.ndarray
    line_direction: np.ndarray
    slope: float
    intercept: float
    fit_slope: float
    fit_intercept: float

    def voltage_at(self, pump_speed_rpm):
        """Valve voltage [V] of the projected fracture line at a pump speed."""
        return (np.asarray(pump_speed_rpm, dtype=float) - self.intercept) / self.slope

    def regions(self, voltage, pump_speed_rpm, closed_voltage: float = 3.5) -> np.ndarray:
        """The paper's three clusters: 0 where hi >= 3.5 V, 1 above the line (plateau), 2 below."""
        v = np.asarray(voltage, dtype=float)
        w = np.asarray(pump_speed_rpm, dtype=float)
        return np.where(v >= closed_voltage, 0, np.where(w >= self.slope * v + self.intercept, 1, 2))


def _hinge(v, y, resolution):
    """Kink voltage and plateau of y(v) ~ min(plateau, plateau - s (v - k)), least squares over k."""
    kinks = np.arange(v[0], v[-1], resolution)
    x = -np.maximum(v[None, :] - kinks[:, None], 0.0)  # (n_k, n_v)
    n = v.size
    sx, sxx = x.sum(axis=1), (x * x).sum(axis=1)
    sy, sxy = y.sum(), x @ y
    det = n * sxx - sx * sx
    ok = det > 1e-12
    plateau = np.where(ok, (sxx * sy - sx * sxy) / np.where(ok, det, 1.0), np.mean(y))
    slope = np.where(ok, (n * sxy - sx * sy) / np.where(ok, det, 1.0), 0.0)
    resid = y[None, :] - plateau[:, None] - slope[:, None] * x
    sse = np.where(ok & (slope > 0), (resid * resid).sum(axis=1), np.inf)
    best = int(np.argmin(sse))
    return float(kinks[best]), float(plateau[best])


def find_fracture(result: SweepResult, resolution: float = 0.005) -> Fracture:
    """Locate the fracture of the averaged surface and build eqs. (15)-(16) from it.

    Averaging the sweeps leaves two kinks, at k0 - r (down sweep) and k0 + r (up sweep), joined by
    a half slope; the averaged valve's fracture k0 lies midway. Each sweep has one sharp kink where
    its flow-limited plateau meets its valve-limited slope, found per pump speed by a hinge fit
    over the part of the column that is not yet closed, then refitted within +-0.5 V of the first
    estimate (further down, the orifice's square root curves the slope and biases a global fit); their midpoint is the fracture, at the
    averaged surface's plateau speed.
    """
    v = result.voltages_v
    points = []
    for j, wp in enumerate(result.pump_speeds_rpm):
        kinks = []
        for surface in (result.up_rpm[:, j], result.down_rpm[:, j]):
            open_ = surface > 0.02 * surface.max()
            if open_.sum() < 4:
                break
            last = int(np.nonzero(open_)[0][-1]) + 1
            k, _ = _hinge(v[:last], surface[:last], resolution)
            near = np.abs(v[:last] - k) <= LOCAL_WINDOW_V  # refit locally: the slope curves further on
            if near.sum() >= 4:
                k, _ = _hinge(v[:last][near], surface[:last][near], resolution)
            if not (v[0] < k < v[last - 1]):
                break
            kinks.append(k)
        if len(kinks) == 2:
            k0 = 0.5 * (kinks[0] + kinks[1])
            points.append((k0, wp, float(np.interp(k0, v, result.average_rpm[:, j]))))
    if len(points) < 2:
        raise IdentificationError("no fracture found on the sweeps (no plateau meets a slope)")
    points = np.array(points)
    picks = [int(np.argmin(np.abs(points[:, 1] - w))) for w in PAPER_POINT_PUMP_SPEEDS]
    if picks[0] == picks[1]:
        picks = [0, len(points) - 1]
    chosen = points[picks]
    origin, direction = space_line(chosen[0], chosen[1])
    slope, intercept = project_space_line(origin, direction)
    fit_slope, fit_intercept = np.polyfit(points[:, 0], points[:, 1], 1)
    return Fracture(points, chosen, origin, direction, slope, intercept, float(fit_slope), float(fit_intercept))


def sweep_columns(result: SweepResult) -> dict:
    """The sweeps as table columns: valve_voltage_v, pump_speed_rpm, direction (up|down|average),
    motor_a_speed_rpm (the format of ``hwpts plant sweep``)."""
    vv, ww = np.meshgrid(result.voltages_v, result.pump_speeds_rpm, indexing="ij")
    surfaces = (("up", result.up_rpm), ("down", result.down_rpm), ("average", result.average_rpm))
    return {
        "valve_voltage_v": np.tile(vv.ravel(), 3),
        "pump_speed_rpm": np.tile(ww.ravel(), 3),
        "direction": np.repeat([name for name, _ in surfaces], vv.size),
        "motor_a_speed_rpm": np.concatenate([z.ravel() for _, z in surfaces]),
    }
