"""``mpc``: model predictive control on the PWA model bank, a QP on the predicted region sequence.

Every 10 ms sample the controller

1. builds the model-rate history ending now: sliding block means over the model's sample period of
   the measured speed, the compensated valve voltage and the measured pump speed (the way the
   identification data were averaged), so that a pump step is seen within one loop sample;
2. predicts the speed over ``horizon`` model samples with the pump speed held at its latest
   measurement (the mean of the last ``pump_window`` loop samples, 30 ms; not the block mean, which
   takes a model period to see a pump step whole), the
   valve following the previous plan, and reads the region of every predicted regressor off the
   model's partition (paper eq. 8-9): the predicted region sequence;
3. with that sequence fixed the prediction is affine in the future valve moves (``moves`` blocks of
   the horizon), and the QP::

       min  sum_i (y_i - r)^2 + lambda sum_j (u_j - u_{j-1})^2
       s.t. u_lo <= u_j <= u_hi,  |u_j - u_prev| <= rate (T_loop + j T)

   (the rate limit on each block's step, as a box around the present valve voltage: the first move
   is applied for one loop sample T_loop, the later ones a model sample T each) is solved as a
   bounded least-squares problem (:func:`scipy.optimize.lsq_linear`). Where the previous plan leads
   the prediction into a region no controller may design from (the closed valve, whose fitted gain
   has the other sign), the sequence is taken along the present valve voltage instead: planning
   through such a region feeds on itself (the plan runs to a limit, which keeps the prediction there,
   a 2-sample limit cycle);
4. applies the first move through the hysteresis inverse. An offset between the measured speed
   (the mean of the last :data:`OFFSET_WINDOW` loop samples) and the model's present output is added
   to every predicted step (a constant output disturbance: integral action without an integrator
   to wind up).
   The defaults (a horizon of 4 model samples, 0.2 s, one move per model sample) were chosen on the
   step scenarios: moves held over two model samples (horizon 6, moves 3) react a model period
   late: the pump-step peak was 4.3 % (3.6 % with one move per model sample, 2.8 % with the latest
   samples as well).
5. estimates the valve play's half-width online (:mod:`hwpts.control.controllers.play`: the model's
   free-run error regressed on the valve direction, at the model rate, through a dead zone) and lets the hysteresis
   inverse follow it, so that a valve whose play is not the identified one (wear, another unit)
   is still inverted (``adapt_width=False``: the identified width, fixed).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from scipy.optimize import lsq_linear

from hwpts.control.controllers.base import Controller, HysteresisInverse
from hwpts.control.controllers.play import AdaptiveInverse, PlayWidthEstimator
from hwpts.control.model import ModelBank

RATE_LIMIT_V_PER_S = 20.0
"""Largest rate of the (effective) valve voltage the MPC plans [V/s]."""

OFFSET_WINDOW = 2
"""Loop samples whose measured speed, averaged, the disturbance offset compares with the model's
present block output (None: the whole model-rate block, as the model was identified). The block mean
lags a fast disturbance by half a model period; the last two samples (20 ms) see a pump or load step
within one loop sample at half the sensor noise's variance. On the pump-step scenario the peak falls
from 3.56 % (block mean) to 2.76 %, on the load step from 1.79 % to 1.63 % (horizon 4, moves 4)."""


class MPCController(Controller):
    """QP-based MPC on the predicted region sequence (see the module doc)."""

    name = "mpc"
    has_modes = True

    def __init__(self, bank: ModelBank, half_width: float, inverse: bool = True, sample_time: float = 0.01,
                 horizon: int = 4, moves: int = 4, move_weight: float = 50.0,
                 rate_limit: float = RATE_LIMIT_V_PER_S, disturbance_filter: float = 0.6, adapt_width: bool = True,
                 offset_window: int | None = OFFSET_WINDOW, pump_latest: bool = True, pump_window: int = 3):
        super().__init__(sample_time)
        self.bank = bank
        self.inverse = HysteresisInverse(half_width, inverse)
        self.adaptive = AdaptiveInverse(self.inverse, PlayWidthEstimator(bank, half_width, sample_time)
                                        if adapt_width else None)
        self.ratio = max(1, int(round(bank.sample_time / sample_time)))
        self.horizon = int(horizon)
        self.moves = int(moves)
        self.move_weight = float(move_weight)
        self.rate = float(rate_limit) * bank.sample_time
        self.first_step = float(rate_limit) * sample_time
        """The present move is applied for one loop sample: the rate limit over that sample bounds it."""
        self.alpha = float(disturbance_filter)
        size = self.ratio * (bank.max_lag + 2)
        self._y = deque(maxlen=size)
        self._u1 = deque(maxlen=size)
        self._u2 = deque(maxlen=size)
        # which move block each horizon step uses
        edges = np.linspace(0, self.horizon, self.moves + 1).round().astype(int)
        self.block = np.zeros(self.horizon, dtype=int)
        for j in range(self.moves):
            self.block[edges[j]:edges[j + 1]] = j
        self.plan = None
        self.offset = 0.0
        self._cache = {}
        self._diff = np.eye(self.moves) - np.eye(self.moves, k=-1)
        self._control = np.asarray(bank.control_regions, dtype=int)
        self.solves = 0
        self.failed_solves = 0
        self.pump_latest = bool(pump_latest)
        self.offset_window = None if offset_window is None else max(1, min(int(offset_window), self.ratio))
        self.pump_future = None
        self.pump_window = max(1, min(int(pump_window), self.ratio))

    @property
    def effective(self) -> float:
        """The valve voltage [V] after the hysteresis inverse (what the model's valve input stands for)."""
        return self.inverse.effective

    def reset(self, setpoint, speed, pump, command):
        """Start in steady state: fill the model-rate history with the present speed, valve and pump."""
        self.adaptive.reset(command, speed, pump)
        for q, v in ((self._y, speed), (self._u1, command), (self._u2, pump)):
            q.clear()
            q.extend([v] * q.maxlen)
        self.plan = np.full(self.moves, float(command))
        self._ym = deque([float(speed)] * (self.ratio * (self.bank.max_lag + 2)), maxlen=self.ratio * (self.bank.max_lag + 2))
        self.offset = 0.0
        _, region = self.bank.steady_valve(setpoint, pump)
        self.region = self.bank.main_region if region is None else region

    def _history(self):
        """Model-rate block means ending now, oldest first (length max_lag + 2)."""
        m = self.ratio
        out = []
        for q in (self._y, self._u1, self._u2):
            a = np.fromiter(q, float, len(q))
            out.append(a.reshape(-1, m).mean(axis=1))
        return out

    def _predict(self, y_hist, u1_hist, u2_now, u_future, regions=None):
        """Free run over the horizon; returns (y, regions, regressors used)."""
        bank = self.bank
        ys = list(y_hist[:-1])  # past outputs up to y(k-1); y(k) itself is predicted
        u1s = list(u1_hist[:-1])
        u2s = list(u2_now)
        pump_future = u2s[-1] if self.pump_future is None else self.pump_future
        y = np.empty(self.horizon)
        regs = np.empty(self.horizon, dtype=int)
        for i in range(self.horizon):
            u1s.append(u_future[i])
            u2s.append(pump_future)
            x = bank.regressor(ys, u1s, u2s)
            r = bank.region(x) if regions is None else regions[i]
            y[i] = bank.predict(x, r)
            regs[i] = r
            ys.append(y[i])
        return y, regs

    def _model_history(self, newest_lag: int):
        """The parallel model's outputs at the model rate, oldest first, the newest ``newest_lag`` loop
        samples before the last one stored."""
        a = np.fromiter(self._ym, float, len(self._ym))
        return a[len(a) - 1 - newest_lag::-self.ratio][::-1]

    def step(self, setpoint, speed, pump):
        """One 10 ms sample: predict over the horizon on the region sequence, solve the QP, apply its first move [V]."""
        self.adaptive.observe(speed, pump, setpoint)
        self._y.append(speed)
        self._u1.append(self.inverse.effective)
        self._u2.append(pump)
        self.pump_future = (float(np.mean([self._u2[-1 - j] for j in range(self.pump_window)]))
                            if self.pump_latest else None)
        y_hist, u1_hist, u2_hist = self._history()
        bank = self.bank
        # the parallel model (a free run driven by the inputs only, one per phase of the model period)
        ym_hist = self._model_history(self.ratio - 1)  # ends with the block that ended m samples ago
        x_now = bank.regressor(ym_hist, u1_hist, u2_hist)
        r_now = bank.region(x_now)
        self.region = r_now
        ym_now = bank.predict(x_now, r_now)
        self._ym.append(ym_now)
        # the measured block mean minus the model's: a constant output disturbance over the horizon
        w = self.offset_window
        y_meas = y_hist[-1] if w is None else float(np.mean([self._y[-1 - j] for j in range(w)]))
        self.offset += self.alpha * ((y_meas - ym_now) - self.offset)
        # the horizon starts with the next model sample: past outputs and valve up to now (the
        # dummy last entries are dropped by _predict)
        y_model = np.append(self._model_history(0), 0.0)
        u1_hist = np.append(u1_hist, 0.0)
        return self.adaptive(float(self._optimize(setpoint, y_model, u1_hist, u2_hist)))

    def _optimize(self, setpoint, y_model, u1_hist, u2_hist) -> float:
        """The plan's first move (effective valve voltage) from the QP on the predicted region sequence."""
        lo, hi = self.inverse.effective_limits
        u_prev = self.inverse.effective
        # the region sequence along the previous plan, then an affine prediction in the moves
        base_u = self.plan[self.block]
        y0, regs = self._predict(y_model, u1_hist, u2_hist, base_u)
        if not np.isin(regs, self._control).all():
            # the previous plan leads into a region no controller may design from (e.g. the closed
            # valve, whose fitted gain has the other sign): planning through it feeds on itself (the
            # plan runs to a limit, which keeps the prediction there). Take the sequence along the
            # present valve voltage held instead.
            self.plan = np.full(self.moves, u_prev)
            base_u = self.plan[self.block]
            y0, regs = self._predict(y_model, u1_hist, u2_hist, base_u)
        y0 = y0 + self.offset
        # with the regions fixed the model is affine in the moves, and the sensitivity to them depends
        # on the region sequence only: computed once per sequence, with the unconstrained solution's
        # pseudo-inverse
        key = regs.tobytes()
        cached = self._cache.get(key)
        if cached is None:
            sens = np.empty((self.horizon, self.moves))
            for j in range(self.moves):
                du = base_u + (self.block == j)
                yj, _ = self._predict(y_model, u1_hist, u2_hist, du, regs)
                sens[:, j] = yj + self.offset - y0
            a = np.vstack([sens, math.sqrt(self.move_weight) * self._diff])
            cached = (sens, a, np.linalg.pinv(a))
            if len(self._cache) > 512:
                self._cache.clear()
            self._cache[key] = cached
        sens, a, a_pinv = cached
        target = setpoint - y0 + sens @ self.plan  # y = y0 + S (u - plan)
        # least squares: [S; sqrt(l) D] u ~ [target; sqrt(l) d0]
        d0 = np.zeros(self.moves)
        d0[0] = u_prev
        b = np.concatenate([target, math.sqrt(self.move_weight) * d0])
        steps = self.first_step + np.arange(self.moves) * self.rate
        lower = np.maximum(lo, u_prev - steps)
        upper = np.minimum(hi, u_prev + steps)
        free = a_pinv @ b
        if np.all(free >= lower) and np.all(free <= upper):
            self.solves += 1
            self.plan = free  # the bounds are inactive: the QP's solution is the unconstrained one
            return self.plan[0]
        self.solves += 1
        try:
            sol = lsq_linear(a, b, bounds=(lower, upper), method="bvls")
            ok = sol.status >= 0 and np.all(np.isfinite(sol.x))
        except (ValueError, np.linalg.LinAlgError):
            ok = False
        if ok:
            self.plan = sol.x
        else:
            self.failed_solves += 1
            self.plan = np.clip(self.plan, lower, upper)
        return self.plan[0]
