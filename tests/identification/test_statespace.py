"""State-space form of each mode (paper eq. 7) reproduces the ARX recursion; poles flag instability."""

import numpy as np

from hwpts.identification.regressors import RegressorStructure
from hwpts.identification.statespace import mode_state_space


def test_state_space_matches_recursion():
    rng = np.random.default_rng(0)
    st = RegressorStructure.create(2, [2, 1], [1, 0], 2)
    theta = np.array([0.5, -0.2, 1.0, 0.3, 0.7, 0.1])
    ss = mode_state_space(st, theta)
    u = rng.standard_normal((30, 2))
    y = np.zeros(30)
    for k in range(2, 30):
        y[k] = 0.5 * y[k - 1] - 0.2 * y[k - 2] + 1.0 * u[k - 1, 0] + 0.3 * u[k - 2, 0] + 0.7 * u[k, 1] + 0.1
    # state at k = 2: [y1, y0, u1_0(1), u1_0(0)]
    x = np.array([y[1], y[0], u[1, 0], u[0, 0]])
    for k in range(2, 30):
        yk = (ss.C @ x + ss.D @ u[k] + ss.c).item()
        assert np.isclose(yk, y[k])
        x = ss.A @ x + ss.B @ u[k] + ss.e
    assert ss.stable


def test_unstable_mode_is_seen():
    st = RegressorStructure.create(1, 1, 1, 1)
    ss = mode_state_space(st, np.array([1.2, 1.0, 0.0]))
    assert not ss.stable and np.isclose(ss.max_pole_modulus, 1.2)
