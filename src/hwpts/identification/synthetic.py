"""The synthetic PWARX benchmark systems of the literature (Hybrid Identification Toolbox, PARC).

Each generator returns a :class:`SyntheticData` with inputs, output, the true mode of every
sample (``-1`` for the initial conditions) and the orders to identify it with. Randomness only
through ``rng`` (a numpy ``Generator``). Noise is equation error (paper eq. 13):
``y_k = phi_k' theta_sigma(k) + e_k``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hwpts.errors import ParameterError

__all__ = ["SyntheticData", "SYSTEMS", "make_system", "simulate_true_pwarx"]


@dataclass
class SyntheticData:
    inputs: np.ndarray
    output: np.ndarray
    modes: np.ndarray
    na: int
    nb: int | list
    nk: int | list
    n_modes: int
    theta: np.ndarray | None = None


def _static_1d(u, modes_fn, slopes, offsets, sigma, rng):
    # y(k) = slope * u(k-1) + offset: regressor x_k = u(k-1) (na=0, nb=1, nk=1)
    n = u.shape[0]
    y = np.zeros(n)
    modes = np.full(n, -1)
    x = u[:-1]
    m = modes_fn(x)
    y[1:] = slopes[m] * x + offsets[m] + sigma * rng.standard_normal(n - 1)
    modes[1:] = m
    theta = np.column_stack([slopes, offsets])
    return SyntheticData(u[:, None], y, modes, 0, 1, 1, len(slopes), theta)


def system1(n=70, sigma=0.1, rng=None):
    """HIT ex_pwarx_1d_3modes: u in [-4, 4]; y = u + 0.2 / -u + 2 / u + 0.2 (modes 1, 3 share theta)."""
    rng = np.random.default_rng(rng)
    u = rng.uniform(-4, 4, n + 1)
    return _static_1d(u, lambda x: np.digitize(x, [-1.0, 2.0]), np.array([1.0, -1.0, 1.0]),
                      np.array([0.2, 2.0, 0.2]), sigma, rng)


def system2(n=100, sigma=0.1, rng=None):
    """HIT ex_pwarx_1d_5modes: u in [-4, 8], five modes split at -1, 2, 4, 6."""
    rng = np.random.default_rng(rng)
    u = rng.uniform(-4, 8, n + 1)
    return _static_1d(u, lambda x: np.digitize(x, [-1.0, 2.0, 4.0, 6.0]),
                      np.array([1.0, -1.0, 1.0, 0.0, 2.0]), np.array([0.2, 2.0, -1.0, 2.0, -10.0]),
                      sigma, rng)


CAKE_THETA = np.array([[4.0, 2.0, 3.0], [-6.0, 6.0, -5.0], [4.0, -2.0, -2.0]])


def cake_modes(x1, x2):
    """True mode of the 'cake' (HIT ex_cake1): three sectors around the origin."""
    r3 = np.sqrt(3.0)
    m = np.full(x1.shape, 1)
    m[(x2 >= 0) & (x1 + x2 / r3 >= 0)] = 0
    m[(x1 - x2 / r3 >= 0) & (x2 < 0)] = 2
    return m


def system3(n=60, sigma=0.1, rng=None):
    """HIT ex_cake1: static 2-D, x in [-1, 1]^2, three sectors (regressor x_k = [x1(k), x2(k)])."""
    rng = np.random.default_rng(rng)
    x = rng.uniform(-1, 1, (n, 2))
    m = cake_modes(x[:, 0], x[:, 1])
    th = CAKE_THETA[m]
    y = th[:, 0] * x[:, 0] + th[:, 1] * x[:, 1] + th[:, 2] + sigma * rng.standard_normal(n)
    return SyntheticData(x, y, m, 0, [1, 1], [0, 0], 3, CAKE_THETA)


def system4(n=1000, sigma=0.0, rng=None):
    """PARC's static function y = sin(4 x1 - 5 (x2 - 0.5)^2) + 2 x2, x ~ U[0, 1]^2 (no true modes)."""
    rng = np.random.default_rng(rng)
    x = rng.uniform(0, 1, (n, 2))
    y = np.sin(4 * x[:, 0] - 5 * (x[:, 1] - 0.5) ** 2) + 2 * x[:, 1] + sigma * rng.standard_normal(n)
    return SyntheticData(x, y, np.zeros(n, dtype=int), 0, [1, 1], [0, 0], 10, None)


SYSTEM5_THETA = np.array([
    [0.5, -0.1, 1.0, 0.3, -0.4, 0.2, 0.2],
    [-0.3, 0.2, 0.9, -0.2, 0.6, 0.1, -0.1],
    [0.4, 0.2, -0.6, 0.4, 0.8, -0.3, 0.4],
])


def system5_mode(y1, u2_1):
    """Mode of system 5 from y(k-1) - u2(k-1): < -0.4, [-0.4, 0.6), >= 0.6."""
    return np.digitize(y1 - u2_1, [-0.4, 0.6])


def system5_partition(n_features: int = 6) -> "RegionPartition":
    """The true partition of system 5 over x = [y1, y2, u1_1, u1_2, u2_1, u2_2, ...] (eq. 9)."""
    from hwpts.identification.partition import RegionPartition

    a = np.zeros(n_features)
    a[0], a[4] = 1.0, -1.0  # d = y(k-1) - u2(k-1)
    return RegionPartition(
        [np.array([a]), np.array([-a, a]), np.array([-a])],
        [np.array([0.4]), np.array([-0.4, -0.6]), np.array([0.6])],
    )


def system5(n=2000, sigma=0.05, rng=None):
    """2 inputs, 3 modes, na = nb = 2, nk = 1 (synthetic system 5); u ~ U[-1, 1]^2.

    The equation error enters the recursion; it is simulated as a third input e(k) with
    coefficient 1 through the compiled switching-rule loop, so 10^6 samples take milliseconds.
    """
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.simulation import simulate_pwarx

    rng = np.random.default_rng(rng)
    u = rng.uniform(-1, 1, (n, 2))
    e = sigma * rng.standard_normal(n)
    st = RegressorStructure.create(2, [2, 2, 1], [1, 1, 0], 3)
    theta = np.column_stack([SYSTEM5_THETA[:, :6], np.ones(3), SYSTEM5_THETA[:, 6]])
    sim = simulate_pwarx(st, system5_partition(7), theta, np.column_stack([u, e]), np.zeros(2))
    return SyntheticData(u, sim.output, sim.regions, 2, 2, 1, 3, SYSTEM5_THETA)


def simulate_true_pwarx(structure, partition, theta, inputs, noise, initial_output):
    """Equation-error PWARX data ``y_k = phi_k' theta_sigma(k) + e_k``: (output, modes).

    A plain Python loop, independent of the compiled simulator, so tests can compare the two.
    """
    u = np.asarray(inputs, dtype=float)
    if u.ndim == 1:
        u = u[:, None]
    n = u.shape[0]
    m = structure.max_lag
    y = np.zeros(n)
    y[:m] = np.asarray(initial_output, dtype=float)[:m]
    modes = np.full(n, -1)
    sig, lag = structure.lags
    for k in range(m, n):
        x = np.array([y[k - lg] if s < 0 else u[k - lg, s] for s, lg in zip(sig, lag)])
        x = structure.with_powers(x[None])[0]
        r = int(partition.predict(x[None])[0])
        y[k] = theta[r, :-1] @ x + theta[r, -1] + noise[k]
        modes[k] = r
    return y, modes


SYSTEMS = {1: system1, 2: system2, 3: system3, 4: system4, 5: system5}


def make_system(number: int, rng=None, **kwargs) -> SyntheticData:
    """Data of synthetic system ``number`` (1-5) of this module; ``n`` (samples, at least 10) and
    ``sigma`` (noise standard deviation, >= 0) override the system's own."""
    from hwpts.identification.settings import check_count, check_number

    if isinstance(number, bool) or number not in SYSTEMS:
        raise ParameterError(f"make_system: number must be one of {sorted(SYSTEMS)}, got {number!r}")
    unknown = set(kwargs) - {"n", "sigma"}
    if unknown:
        raise ParameterError(f"make_system: unknown setting(s) {sorted(unknown)}; valid are n and sigma")
    if "n" in kwargs:
        check_count(kwargs["n"], "n", 10, owner="make_system: ")
    if "sigma" in kwargs:
        check_number(kwargs["sigma"], "sigma", 0.0, owner="make_system: ")
    return SYSTEMS[number](rng=rng, **kwargs)
