"""Online estimate of the valve's play half-width from the model bank and the measurements.

The hysteresis inverse needs the play's half-width r. The identified value holds for the valve it
was identified on; a valve whose play differs (wear, another unit: the study's plants) defeats the
inverse on every reversal: with the true play wider by dr the spool stays put for 2 dr more of
command, narrower and it jumps by 2 dr too far, either way an error of about the valve gain times dr that
changes sign with the valve's direction (about 45 r/min, 4.5 % of the set-point, for dr = 0.05 V).

With the inverse's estimate u of the play output, the true output is u - s dr, where s is +1 while
the play was last pushed up and -1 while last pushed down. The error of the model's free run (the
parallel model, at the model rate, on the block means the model was identified with, paper eq. 5)
is then, to first order,

    e(k) = alpha v(k) - kappa dr z(k) + gamma p(k) + c + noise

where v, z and p are the active region's valve channel driven by u, by s and its pump channel
driven by the pump speed (the region's own a, b, c coefficients as a filter), kappa = 1 + alpha the
plant's valve gain over the model's and gamma a pump-gain mismatch (a plant that is not the one
identified: without these two terms the play would absorb them), and c a slow disturbance. v and z
are driven by the values at the start of each model sample, set by commands computed before any of
that sample's measurements (so that the controller's answer to this sample's sensor noise does not
leak into them). The estimator solves for alpha, kappa dr and gamma by exponentially weighted least
squares on high-passed signals and moves the width by the estimated dr at a slow rate, through a
dead zone: the classic robust modification of an adaptive law against unmodelled dynamics
(Peterson & Narendra, IEEE TAC 27(6), 1982; Ioannou & Sun, Robust Adaptive Control, 1996, sec. 8.5),
here the model's error at the loop's fast valve reversals, which would otherwise let the width
drift on the very valve it was identified on. Only the model file and the measurements are used.
"""

from __future__ import annotations

import math

import numpy as np

from hwpts.control.model import ModelBank

WIDTH_SPAN = 0.5
"""The estimate stays within the identified width x (1 - span ... 1 + span)."""
BIAS_TIME_S = 0.5
"""Time constant of the high-pass (a slow disturbance, the model's offset) [s]."""
WINDOW_S = 60.0
"""Time constant of the least-squares window [s]."""
ADAPT_TIME_S = 8.0
"""The width moves by the estimated difference (beyond the dead zone) with this time constant [s]."""
DEAD_ZONE = 0.03
"""Estimated differences smaller than this share of the identified width leave the width as it is."""
WARMUP_S = 10.0
"""The estimate stays at the identified width for this long after a reset [s]."""
TRANSIENT_BAND = 0.008
"""Where the speed error's mean over the last ``TRANSIENT_TIME_S`` exceeds this share of the set-point,
the loop is in a transient (a load or pump step, the set-point out of reach; a worn valve's limit
cycle averages out): those samples are left out of the estimate."""
TRANSIENT_TIME_S = 0.5
"""Time constant of that mean [s]."""
TRANSIENT_HOLD_S = 2.0
"""... and so are the samples for this long after one [s]."""


class PlayWidthEstimator:
    """Least-squares estimate of the play's half-width from the model's free-run error (see the module
    doc). Call :meth:`observe` every loop sample with the measured speed and pump speed and the
    inverse's present output estimate and direction, *before* the new command is computed. ``width``
    is the estimate [V], ``difference`` the last estimated dr [V], ``gain_ratio`` the last kappa."""

    def __init__(self, bank: ModelBank, half_width: float, sample_time: float = 0.01, span: float = WIDTH_SPAN,
                 bias_time_s: float = BIAS_TIME_S, window_s: float = WINDOW_S, adapt_time_s: float = ADAPT_TIME_S,
                 dead_zone: float = DEAD_ZONE, warmup_s: float = WARMUP_S, transient_band: float = TRANSIENT_BAND,
                 transient_hold_s: float = TRANSIENT_HOLD_S):
        self.bank = bank
        self.nominal = float(half_width)
        self.bounds = (self.nominal * (1.0 - span), self.nominal * (1.0 + span))
        self.dead_zone = float(dead_zone) * self.nominal
        self.ratio = max(1, int(round(bank.sample_time / sample_time)))
        period = bank.sample_time
        self.a_bias = 1.0 - math.exp(-period / bias_time_s)
        self.a_win = 1.0 - math.exp(-period / window_s)
        self.a_adapt = 1.0 - math.exp(-period / adapt_time_s)
        self.warmup = int(math.ceil(warmup_s / period))
        self.transient_band = float(transient_band)
        self.a_transient = 1.0 - math.exp(-period / TRANSIENT_TIME_S)
        self.hold = int(math.ceil(transient_hold_s / period))
        self.length = bank.max_lag + 2
        self.reset(1.2, 0.0, 0.0)

    def reset(self, command: float, speed: float, pump: float) -> None:
        """Steady state at ``command`` [V], ``speed`` and ``pump`` [r/min]; the width back to the identified one."""
        n = self.length
        self.y = [float(speed)] * n
        self.ym = [float(speed)] * n
        self.u1 = [float(command)] * n
        self.u2 = [float(pump)] * n
        self.u_first = [float(command)] * n
        self.s_first = [0.0] * n
        self.vf = [0.0] * n
        self.zf = [0.0] * n
        self.pf = [0.0] * n
        self._acc = np.zeros(4)
        self._first = (float(command), 0.0)
        self._since_transient = self.hold
        self.error_mean = 0.0
        self._count = 0
        self.mean = None
        self.R = np.zeros((4, 4))
        self.updates = 0
        self.width = self.nominal
        self.gain_ratio = 1.0
        self.difference = 0.0

    def observe(self, speed: float, pump: float, effective: float, direction: float,
                setpoint: float = math.nan) -> bool:
        """One loop sample: measured ``speed`` and ``pump`` [r/min], the inverse's play output estimate
        ``effective`` [V] and ``direction`` (+1 last pushed up, -1 down) over the last interval, and the
        ``setpoint`` [r/min] (nan: no transient detection). True when a model-rate sample completed."""
        if self._count == 0:
            self._first = (float(effective), float(direction))
        self._acc += (speed, effective, pump, setpoint)
        self._count += 1
        if self._count < self.ratio:
            return False
        m = self._acc / self._count
        for seq, v in ((self.y, m[0]), (self.u1, m[1]), (self.u2, m[2]), (self.u_first, self._first[0]),
                       (self.s_first, self._first[1])):
            seq.append(float(v))
            del seq[0]
        self._acc[:] = 0.0
        self._count = 0
        if math.isfinite(m[3]) and m[3] != 0.0:
            self.error_mean += self.a_transient * ((m[0] - m[3]) / m[3] - self.error_mean)
        if abs(self.error_mean) > self.transient_band:
            self._since_transient = 0
        else:
            self._since_transient += 1
        self._update()
        return True

    def _update(self) -> None:
        bank = self.bank
        # the parallel model (free run on the inputs): its error holds the sensor noise of this sample
        # only, not of the past outputs as a one-step predictor's error does
        x = bank.regressor(self.ym, self.u1, self.u2)
        r = bank.region(x)
        ym = bank.predict(x, r)
        na, (nb1, nb2), (nk1, nk2) = bank.na, bank.nb, bank.nk
        th = bank.theta[r]
        a, b, c = th[:na], th[na:na + nb1], th[na + nb1:na + nb1 + nb2]

        def channel(past, inputs, coef, lag):
            return (sum(a[j] * past[-1 - j] for j in range(na))
                    + sum(coef[j] * inputs[-1 - lag - j] for j in range(coef.size)))

        vf = channel(self.vf, self.u_first, b, nk1)
        zf = channel(self.zf, self.s_first, b, nk1)
        pf = channel(self.pf, self.u2, c, nk2)
        for seq, v in ((self.ym, ym), (self.vf, vf), (self.zf, zf), (self.pf, pf)):
            seq.append(float(v))
            del seq[0]
        sig = np.array([vf, zf, pf, self.y[-1] - ym])
        if self.mean is None:
            self.mean = sig.copy()
        self.mean += self.a_bias * (sig - self.mean)
        hp = sig - self.mean
        if self._since_transient < self.hold:
            # a large transient: the first-order error model does not hold there; the model runs on
            return
        self.R += self.a_win * (np.outer(hp, hp) - self.R)
        self.updates += 1
        if self.updates < self.warmup:
            return
        ff, fe = self.R[:3, :3], self.R[:3, 3]
        scale = 1e-6 * (np.trace(ff) + 1e-12)
        try:
            alpha, beta, _ = np.linalg.solve(ff + scale * np.eye(3), fe)
        except np.linalg.LinAlgError:  # pragma: no cover - regularised
            return
        if not (math.isfinite(alpha) and math.isfinite(beta)):
            return
        kappa = min(max(1.0 + alpha, 0.3), 3.0)
        self.gain_ratio = kappa
        self.difference = -beta / kappa
        step = math.copysign(max(abs(self.difference) - self.dead_zone, 0.0), self.difference)
        w = self.width + self.a_adapt * step
        self.width = float(min(max(w, self.bounds[0]), self.bounds[1]))


WIDTH_UPDATE_V = 0.002
"""The inverse takes a new width estimate when it moved by more than this [V]."""


class AdaptiveInverse:
    """A :class:`~hwpts.control.controllers.base.HysteresisInverse` whose half-width follows a
    :class:`PlayWidthEstimator` (``estimator=None``, or the inverse off: the fixed inverse)."""

    def __init__(self, inverse, estimator: PlayWidthEstimator | None):
        self.inverse = inverse
        self.estimator = estimator if inverse.enabled else None
        self.direction = 0.0

    def reset(self, command: float, speed: float, pump: float) -> None:
        """Steady start at ``command`` [V] with the identified width."""
        self.inverse.reset(command)
        self.direction = 0.0
        if self.estimator is not None:
            self.estimator.reset(command, speed, pump)
            self.inverse.r = self.estimator.nominal

    def observe(self, speed: float, pump: float, setpoint: float = math.nan) -> None:
        """This sample's measured speed and pump speed [r/min] and the set-point, before the command is computed."""
        if self.estimator is not None:
            self.estimator.observe(speed, pump, self.inverse.effective, self.direction, setpoint)

    def __call__(self, desired: float) -> float:
        """The coil command [V] for the ``desired`` play output [V]; the width follows the estimate."""
        inv = self.inverse
        cmd = inv(desired)
        est = self.estimator
        if est is not None:
            if inv.effective <= cmd - inv.r + 1e-12:
                self.direction = 1.0
            elif inv.effective >= cmd + inv.r - 1e-12:
                self.direction = -1.0
            if abs(est.width - inv.r) > WIDTH_UPDATE_V:
                # the play's output stays on its contact edge, which the new width moves
                eff = cmd - self.direction * est.width if self.direction else inv.effective
                inv.set_width(est.width, eff)
        return cmd
