"""Simulation-error polish of the local parameters (output-error refinement).

Least squares per region (eq. 17) minimises the one-step (equation) error. When a model is meant
for free-run simulation, the parameters can be refined to minimise the *simulation* error on the
training data, keeping the partition (eq. 9) fixed::

    min_theta  sum_k (y_k - yhat_k(theta))^2,   yhat from the switching-rule free run

solved by ``scipy.optimize.least_squares`` (trust region reflective) on the signals less their
means (:func:`polish_free_run`), starting from the least-squares parameters,
with the Jacobian from the sensitivity recursion of the free run (compiled, one pass: a
finite-difference Jacobian took one simulation per parameter, 1.2 s of Silverbox's 2.1 s of
polish). Where the start's Gauss-Newton matrix is well conditioned, the solver sees the residuals
and Jacobian compressed to one row more than there are parameters, with the same sum of squares,
gradient and Gauss-Newton matrix (:func:`compress`), so its trust-region steps are the same and
its SVD is of a 46 x 45 matrix rather than 20,000 x 45 (scipy's SVD of the full Jacobian was 19 ms
of a step's 22 ms on Silverbox). The compiled simulator makes one
evaluation cost microseconds per thousand samples. A
polished model is kept only if its training free-run error is lower and it does not diverge;
otherwise the least-squares parameters stay.
"""

from __future__ import annotations

import numpy as np

from hwpts.identification.simulation import free_run_sensitivity, simulate_pwarx
from hwpts.identification.threads import single_threaded


# The descent stops when a step lowers the simulation error by less than this fraction (scipy's
# ftol; its default 1e-8 ran Silverbox's polish for 28 evaluations where 15 reach the same model:
# the last steps moved the training error by less than 1e-5 of itself, a fit change of 1e-4 points)
FTOL = 1e-5

# The polish's compression (:func:`compress`) goes through the Gauss-Newton matrix J'J when its
# column-scaled eigenvalues span less than this (a scaled Jacobian's condition number below 1e5:
# forming J'J loses about eps * cond^2 of the smallest eigenvalue, here at most 2e-6 of it), through
# QR otherwise. Silverbox's polish Jacobians: 1.3e4; EMPS's: 4e12 and more (a column of zeros)
GRAM_RCOND = 1e-10


def _stretches(n: int, m: int, breaks) -> list[tuple[int, int]]:
    """``[start, stop)`` of the stretches between ``breaks`` long enough to simulate (more than
    ``m`` samples: the first ``m`` are the stretch's initial conditions)."""
    edges = [0] + sorted({int(b) for b in (breaks or ()) if 0 < int(b) < n}) + [n]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:]) if b - a > m]


def _gram_path(jac):
    """``(D, W, V)`` with ``D^-1 J'J D^-1 = V W V'`` (``D``: the column norms of ``J``) when the
    Gauss-Newton matrix keeps its digits (finite, no fewer rows than columns, eigenvalues spanning
    less than :data:`GRAM_RCOND`); ``None`` otherwise (the rule of :func:`compress`)."""
    if jac.shape[0] < jac.shape[1] or not np.all(np.isfinite(jac)):
        return None
    gram = jac.T @ jac
    scale = np.sqrt(np.diag(gram))
    scale[scale == 0] = 1.0
    w, vec = np.linalg.eigh(gram / np.outer(scale, scale))
    return (scale, w, vec) if w[0] > w[-1] * GRAM_RCOND else None


def gram_conditioned(jacobian) -> bool:
    """Whether :func:`compress` takes the Gauss-Newton matrix's path for this Jacobian (its
    column-scaled eigenvalues span less than :data:`GRAM_RCOND`, and it has no fewer rows than columns)."""
    return _gram_path(np.asarray(jacobian, dtype=float)) is not None


def compress(residuals, jacobian) -> tuple[np.ndarray, np.ndarray]:
    """Residuals ``r`` (n) and Jacobian ``J`` (n x q, n >= q) compressed to ``q + 1`` rows with the
    same sum of squares, gradient ``J'r`` and Gauss-Newton matrix ``J'J``.

    A trust-region (or Levenberg-Marquardt) step depends on nothing else, so the solver takes the
    same steps, while its SVD is of a (q + 1) x q matrix instead of the n x q Jacobian (Silverbox:
    19 ms a step for 20,000 x 45, most of the polish). The compressed Jacobian is ``[C; 0]`` with
    ``C'C = J'J``, the residuals ``[c; sqrt(r'r - c'c)]`` with ``C'c = J'r``:

    - from the column-scaled ``J'J = D V W V' D`` (1.4 ms): ``C = W^1/2 V' D``,
      ``c = W^-1/2 V' D^-1 J'r``, when its eigenvalues span less than :data:`GRAM_RCOND` (forming
      ``J'J`` squares the condition number: past that its small eigenvalues lose their digits);
    - otherwise from Householder QR, ``J = QR`` (13 ms, as accurate as the SVD): ``C = R``,
      ``c = Q'r``.
    """
    r = np.asarray(residuals, dtype=float)
    jac = np.asarray(jacobian, dtype=float)
    q = jac.shape[1]
    gram = _gram_path(jac)
    if gram is not None:
        scale, w, vec = gram
        root = np.sqrt(w)
        top = (vec.T @ ((jac.T @ r) / scale)) / root
        factor = (root[:, None] * vec.T) * scale
    else:
        from scipy.linalg import qr_multiply

        if jac.shape[0] < q:  # fewer rows than parameters: pad (rows of zeros change nothing)
            jac = np.vstack([jac, np.zeros((q - jac.shape[0], q))])
            r = np.append(r, np.zeros(q - r.size))
        top, factor = qr_multiply(jac, r, mode="right")
    rest = max(float(r @ r) - float(top @ top), 0.0)
    return np.append(top, np.sqrt(rest)), np.vstack([factor, np.zeros((1, q))])


def polish_free_run(structure, partition, theta, kinds, inputs, output, center, bound,
                    max_nfev: int | None = None, breaks=None) -> tuple[np.ndarray, dict]:
    """Return (theta, info) after simulation-error minimisation over the affine modes' parameters.

    ``breaks``: sample positions where the record restarts (two stretches joined, as in a
    cross-validation fold); each stretch is simulated from its own first measured outputs, since a
    free run carried across a junction would chase the jump in the measurements.

    With a constant term the descent runs on the signals less their means (the same model: each
    mode's offset, the partition and the power terms' center shifted to match, and shifted back
    after). The solver's first trust region is sized from the start's parameters, offsets
    included, so on the raw signals the zero of the output's unit (absolute or gauge pressure)
    moved where the polish landed: the hydraulic actuator with its output 1000 higher chose an
    unpolished model scoring 49.14 % on its test part instead of the polished 58.68 %. The
    simulation error of a short record has several minima near the least-squares start, and one
    descent lands in one of them by the path it takes; on the raw signals a second descent
    (Levenberg-Marquardt, the lower cost kept) had taken the actuator from 49.14 to 58.68 %. On
    the centred signals the trust region alone reaches 62.76 % there, and the second descent's
    lower costs were minima that do not generalise: on pick_and_place (400 Hz, 5,000 training
    samples) it made a 150-sample mode unstable (pole 1.22; test fit 76.8 % against 87.1 % for the
    trust region alone) or, all modes stable, scored -6.7 % against 86.1 %. So one descent.
    """
    y = np.asarray(output, dtype=float)
    u = np.asarray(inputs, dtype=float)
    theta = np.asarray(theta, dtype=float)
    if not structure.constant or y.size == 0:
        return _polish(structure, partition, theta, kinds, u, y, center, bound, max_nfev, breaks)
    from dataclasses import replace

    ym = float(np.mean(y))
    um = np.mean(u, axis=0) if u.shape[0] else np.zeros(u.shape[1])
    sig, _ = structure.lags
    m = np.where(sig < 0, ym, um[np.maximum(sig, 0)])  # each regressor column's shift
    m[structure.n_linear:] = 0.0  # power terms: their center moves instead
    nf = structure.n_features
    shifted = theta.copy()
    shifted[:, nf] += theta[:, :nf] @ m - ym  # y - ym = theta' (x - m) + (c + theta' m - ym)
    local = replace(structure, power_center=structure.power_center - ym) if structure.output_powers else structure
    out, info = _polish(local, partition.shifted(m), shifted, kinds, u - um, y - ym, center - ym, bound,
                        max_nfev, breaks)
    if out is shifted:  # not accepted: the parameters as given, to the last digit
        return theta, info
    out = out.copy()
    out[:, nf] -= out[:, :nf] @ m - ym
    fixed = [i for i, k in enumerate(kinds) if k != "affine"]
    out[fixed] = theta[fixed]  # constant and zero modes are not polished: theirs to the last digit
    return out, info


def _polish(structure, partition, theta, kinds, u, y, center, bound, max_nfev, breaks) -> tuple[np.ndarray, dict]:
    """:func:`polish_free_run` on the signals as given."""
    from scipy.optimize import least_squares

    free_rows = [i for i, k in enumerate(kinds) if k == "affine"]
    cols = list(range(structure.n_features)) + ([structure.n_features] if structure.constant else [])
    mask = np.zeros(theta.shape, dtype=bool)
    for i in free_rows:
        mask[i, cols] = True
    m = structure.max_lag
    parts = _stretches(y.shape[0], m, breaks)
    if not parts:  # no stretch longer than its initial conditions: nothing to simulate
        return theta, {"initial_sse": 0.0, "accepted": False}
    target = np.concatenate([y[a + m:b] for a, b in parts])
    penalty = abs(center) + bound

    last: dict = {}  # the runs of the last parameters: the Jacobian is asked where the residuals were

    def runs(th):
        """The free run of every stretch (a :class:`SimulationResult` each)."""
        key = th.tobytes()
        if last.get("key") != key:
            last["key"] = key
            last["sims"] = [simulate_pwarx(structure, partition, th, u[a:b], y[a:b], center, bound) for a, b in parts]
        return last["sims"]

    def simulate(th):
        """The free run of every stretch (outputs after its initial conditions), and whether any diverged."""
        sims = runs(th)
        return np.concatenate([sim.output[m:] for sim in sims]), any(sim.diverged for sim in sims)

    def residuals(p):
        th = theta.copy()
        th[mask] = p
        out, diverged = simulate(th)
        if diverged:
            out = np.where(np.isfinite(out), out, penalty)
        return out - target

    columns = np.flatnonzero(mask.ravel())  # theta[mask] is theta's masked entries row by row
    every = columns.size == mask.size  # every parameter free: the sensitivities need no selection

    def jacobian(p):
        """The sensitivity recursion (:func:`free_run_sensitivity`) of every stretch, stacked (the
        last one kept: the start's is asked for by the path test and again by the solver)."""
        key = p.tobytes()
        if last.get("jac_key") != key:
            th = theta.copy()
            th[mask] = p
            blocks = [free_run_sensitivity(structure, th, u[a:b], sim)[m:] for (a, b), sim in zip(parts, runs(th))]
            if not every:
                blocks = [block[:, columns] for block in blocks]
            last["jac_key"] = key
            last["jac"] = blocks[0] if len(blocks) == 1 else np.concatenate(blocks)
        return last["jac"]

    compact: dict = {}

    def compressed(p):
        """:func:`compress` of the residuals and Jacobian at ``p`` (both asked for at each point)."""
        key = p.tobytes()
        if compact.get("key") != key:
            compact["r"], compact["J"] = compress(residuals(p), jacobian(p))
            compact["key"] = key
        return compact

    p0 = theta[mask]
    r0 = residuals(p0)
    cost0 = float(np.sum(r0**2))
    info = {"initial_sse": cost0}
    if p0.size == 0:
        return theta, info
    nfev = max_nfev or 30 * (p0.size + 1)
    # the compressed problem (:func:`compress`) when the start's Gauss-Newton matrix keeps its digits
    # (Silverbox); otherwise the full one, whose steps scipy takes from the Jacobian's SVD (EMPS,
    # condition numbers of 1e12 and more: the compression would need a QR at every evaluation,
    # rejected steps included, where scipy takes one SVD per accepted step)
    # one BLAS thread, entered once for the path test and the descents: the Gauss-Newton matrix of
    # the (n x p) Jacobian (p tens) is fastest single-threaded, and threaded BLAS beside another job
    # spin-waits (measured 1.2 s -> 0.02 s per SVD of 30,000 x 45 on a busy 2-core machine)
    with single_threaded("blas"):
        small = gram_conditioned(jacobian(p0))
        info["compressed"] = small
        try:
            if small:
                res = least_squares(lambda p: compressed(p)["r"], p0, jac=lambda p: compressed(p)["J"],
                                    method="trf", x_scale="jac", max_nfev=nfev, ftol=FTOL)
            else:
                res = least_squares(residuals, p0, jac=jacobian, method="trf", x_scale="jac",
                                    max_nfev=nfev, ftol=FTOL)
        except (ValueError, np.linalg.LinAlgError) as error:  # pragma: no cover - defensive
            info["failed"] = str(error)
            return theta, info
    th = theta.copy()
    th[mask] = res.x
    out, diverged = simulate(th)
    cost1 = float(np.sum((out - target) ** 2)) if not diverged else float("inf")
    info.update({"final_sse": cost1, "nfev": int(res.nfev)})
    if cost1 < cost0:
        info["accepted"] = True
        return th, info
    info["accepted"] = False
    return theta, info
