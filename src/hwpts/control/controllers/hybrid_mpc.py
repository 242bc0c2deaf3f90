"""``hybrid-mpc``: exact hybrid MPC of the PWA model bank, the regions as binary variables.

The prediction over the horizon is the PWARX model itself in mixed logical dynamical form
(Bemporad & Morari, Automatica 35(3), 1999): per predicted step i and region r a binary delta_ri
(one region per step), the region's polyhedron H_r phi_i + g_r <= M (1 - delta_ri) (paper eq. 9),
and z_ri = delta_ri * theta_r' [phi_i; 1] by big-M inequalities, y_i = sum_r z_ri. phi_i holds
the predicted outputs, the planned valve voltages and the held pump speed, all decision variables
or constants, so the region sequence is chosen by the optimiser rather than predicted beforehand.
The cost is the L1 norm of the speed error (plus the output disturbance of the parallel model, as
in ``mpc``) and of the valve moves; limits 1.2-3.8 V (effective: +-r inside) and the rate limit
are constraints. Solved by HiGHS through :func:`scipy.optimize.milp` every 10 ms sample.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp

from hwpts.control.controllers.mpc import MPCController

SPEED_SPAN_RPM = 200.0
"""A predicted speed stays within this distance of the present model output over the horizon [r/min]
(0.2 s: the valve's full stroke moves the speed by less); the big-M constants come from it."""


class HybridMPCController(MPCController):
    """MILP hybrid MPC (see the module doc); history, parallel model and disturbance as ``mpc``."""

    name = "hybrid-mpc"

    def __init__(self, bank, half_width, inverse=True, sample_time=0.01, horizon: int = 4, moves: int = 2,
                 move_weight: float = 20.0, time_limit_s: float = 0.5, **kwargs):
        super().__init__(bank, half_width, inverse, sample_time, horizon=horizon, moves=moves, **kwargs)
        self.move_weight_l1 = float(move_weight)
        self.time_limit = float(time_limit_s)
        self.options = {"time_limit": self.time_limit, "presolve": True}

        self._layout()

    def _layout(self):
        """Variable indices: u (moves), y (horizon), delta, z (horizon x regions), e (horizon), du (moves)."""
        n, m, s = self.horizon, self.moves, self.bank.n_regions
        self.iu = np.arange(m)
        self.iy = m + np.arange(n)
        self.idelta = m + n + np.arange(n * s).reshape(n, s)
        self.iz = m + n + n * s + np.arange(n * s).reshape(n, s)
        self.ie = m + n + 2 * n * s + np.arange(n)
        self.idu = m + 2 * n + 2 * n * s + np.arange(m)
        self.nvar = m + 2 * n + 2 * n * s + m
        self._var_lo = np.zeros(self.nvar)
        bank = self.bank
        present = np.zeros(bank.n_features, dtype=bool)
        present[bank.na] = bank.nk[0] == 0 and bank.nb[0] > 0  # u1(k)
        present[bank.na + bank.nb[0]] = bank.nk[1] == 0 and bank.nb[1] > 0  # u2(k)
        self._tied = all(np.all(h[:, ~present] == 0.0) for h in bank.H)
        self._var_hi = np.zeros(self.nvar)

    def _phi(self, i, y_model, u1_hist, u2_hist):
        """phi_i as (constant part c, coefficient matrix over the variables A): phi = c + A x."""
        bank = self.bank
        nf = bank.n_features
        c = np.zeros(nf)
        a = np.zeros((nf, self.nvar))
        na, (nb1, nb2), (nk1, nk2) = bank.na, bank.nb, bank.nk
        past_y = y_model[:-1]  # known outputs up to now
        past_u1 = u1_hist[:-1]
        for j in range(na):
            step = i - 1 - j  # predicted step index (negative: known)
            if step >= 0:
                a[j, self.iy[step]] = 1.0
            else:
                c[j] = past_y[len(past_y) + step]
        pos = na
        for j in range(nb1):
            step = i - nk1 - j
            if step >= 0:
                a[pos + j, self.iu[self.block[step]]] = 1.0
            else:
                c[pos + j] = past_u1[len(past_u1) + step]
        pos += nb1
        for j in range(nb2):
            c[pos + j] = u2_hist[-1] if i - nk2 - j >= 0 else u2_hist[len(u2_hist) + (i - nk2 - j)]
        return c, a

    def _optimize(self, setpoint, y_model, u1_hist, u2_hist):
        bank = self.bank
        n, m, s = self.horizon, self.moves, bank.n_regions
        lo, hi = self.inverse.effective_limits
        u_prev = self.inverse.effective
        ylo, yhi = y_model[-2] - SPEED_SPAN_RPM, y_model[-2] + SPEED_SPAN_RPM
        reach = (np.arange(m) + 1) * self.rate  # the rate limit bounds each block's move from now
        u_lo = np.maximum(lo, u_prev - reach)
        u_hi = np.minimum(hi, u_prev + reach)
        rows, lbs, ubs = [], [], []

        def add(row, lb, ub):
            rows.append(row)
            lbs.append(lb)
            ubs.append(ub)

        theta = bank.theta
        if self._tied:
            # the partition reads only the present valve voltage and pump speed, both constant over a
            # move block: every step of a block lies in the same region
            for i in range(1, n):
                if self.block[i] == self.block[i - 1]:
                    for r in range(s):
                        row = np.zeros(self.nvar)
                        row[self.idelta[i, r]] = 1.0
                        row[self.idelta[i - 1, r]] = -1.0
                        add(row, 0.0, 0.0)
        impossible = np.zeros((n, s), dtype=bool)
        for i in range(n):
            c, a = self._phi(i, y_model, u1_hist, u2_hist)
            # interval bounds of phi for the big-M constants
            var_lo, var_hi = self._var_lo, self._var_hi
            var_lo[self.iu], var_hi[self.iu] = u_lo, u_hi
            var_lo[self.iy], var_hi[self.iy] = ylo, yhi
            pos_a, neg_a = np.maximum(a, 0), np.minimum(a, 0)
            phi_lo = c + pos_a @ var_lo + neg_a @ var_hi
            phi_hi = c + pos_a @ var_hi + neg_a @ var_lo
            one = np.zeros(self.nvar)
            one[self.idelta[i]] = 1.0
            add(one, 1.0, 1.0)  # one region per step
            ysum = np.zeros(self.nvar)
            ysum[self.iy[i]] = 1.0
            ysum[self.iz[i]] = -1.0
            add(ysum, 0.0, 0.0)  # y_i = sum_r z_ri
            for r in range(s):
                th, d = theta[r, :-1], (theta[r, -1] if bank.constant else 0.0)
                f_lo = d + np.sum(np.minimum(th * phi_lo, th * phi_hi))
                f_hi = d + np.sum(np.maximum(th * phi_lo, th * phi_hi))
                frow = th @ a  # f = d + th.c + frow.x
                fc = d + th @ c
                dz, zz = self.idelta[i, r], self.iz[i, r]
                row = np.zeros(self.nvar); row[zz] = 1.0; row[dz] = -f_hi
                add(row, -np.inf, 0.0)  # z <= f_hi delta
                row = np.zeros(self.nvar); row[zz] = 1.0; row[dz] = -f_lo
                add(row, 0.0, np.inf)  # z >= f_lo delta
                row = -frow.copy(); row[zz] += 1.0; row[dz] -= f_lo
                add(row, -np.inf, fc - f_lo)  # z <= f - f_lo (1 - delta)
                row = -frow.copy(); row[zz] += 1.0; row[dz] -= f_hi
                add(row, fc - f_hi, np.inf)  # z >= f - f_hi (1 - delta)
                h, g = bank.H[r], bank.g[r]
                if h.shape[0] and np.any(g + np.sum(np.minimum(h * phi_lo, h * phi_hi), axis=1) > 0.0):
                    impossible[i, r] = True  # no point of the box lies in the region: delta fixed at 0
                for q in range(h.shape[0]):
                    hrow = h[q] @ a
                    hc = h[q] @ c + g[q]
                    big = hc + np.sum(np.maximum(h[q] * phi_lo, h[q] * phi_hi)) - h[q] @ c
                    big = max(big, 0.0) + 1.0
                    row = hrow.copy(); row[dz] += big
                    add(row, -np.inf, big - hc)  # H phi + g <= big (1 - delta)
            # |y_i + offset - setpoint| <= e_i
            row = np.zeros(self.nvar); row[self.iy[i]] = 1.0; row[self.ie[i]] = -1.0
            add(row, -np.inf, setpoint - self.offset)
            row = np.zeros(self.nvar); row[self.iy[i]] = 1.0; row[self.ie[i]] = 1.0
            add(row, setpoint - self.offset, np.inf)
        for j in range(m):
            prev = u_prev if j == 0 else None
            row = np.zeros(self.nvar); row[self.iu[j]] = 1.0; row[self.idu[j]] = -1.0
            if j > 0:
                row[self.iu[j - 1]] = -1.0
            add(row, -np.inf, prev if prev is not None else 0.0)  # u_j - u_{j-1} <= du_j
            row = np.zeros(self.nvar); row[self.iu[j]] = 1.0; row[self.idu[j]] = 1.0
            if j > 0:
                row[self.iu[j - 1]] = -1.0
            add(row, prev if prev is not None else 0.0, np.inf)  # u_j - u_{j-1} >= -du_j
            row = np.zeros(self.nvar); row[self.iu[j]] = 1.0
            if j > 0:
                row[self.iu[j - 1]] = -1.0
            add(row, (u_prev if j == 0 else 0.0) - self.rate, (u_prev if j == 0 else 0.0) + self.rate)  # rate
        cost = np.zeros(self.nvar)
        cost[self.ie] = 1.0
        cost[self.idu] = self.move_weight_l1
        lb = np.full(self.nvar, -np.inf)
        ub = np.full(self.nvar, np.inf)
        lb[self.iu], ub[self.iu] = u_lo, u_hi
        lb[self.iy], ub[self.iy] = ylo, yhi
        lb[self.idelta.ravel()], ub[self.idelta.ravel()] = 0.0, 1.0
        # regions no controller designs from (the closed valve, where the fitted gain has the wrong
        # sign) are kept out of the plan: their binaries are fixed at 0
        for r in range(s):
            if r not in bank.control_regions:
                ub[self.idelta[:, r]] = 0.0
        ub[self.idelta[impossible]] = 0.0
        lb[self.ie], lb[self.idu] = 0.0, 0.0
        integrality = np.zeros(self.nvar)
        integrality[self.idelta.ravel()] = 1
        self.solves += 1
        constraints = LinearConstraint(np.array(rows), np.array(lbs), np.array(ubs))
        bounds = Bounds(lb, ub)
        res = milp(cost, constraints=constraints, integrality=integrality, bounds=bounds, options=self.options)
        if res.x is None or res.status not in (0, 1):
            self.failed_solves += 1
            return float(np.clip(self.plan[0], lo, hi))
        self.plan = np.asarray(res.x[self.iu], dtype=float)
        regions = np.argmax(res.x[self.idelta].reshape(n, s), axis=1)
        self.planned_regions = regions
        return float(self.plan[0])
