"""Right-hand side x' = F(x, h, w_p) of the HWPTS, its Jacobian, and the paper's f(x) + g(x) U form.

State x = [P_p, P_mA, P_mB, w_A, w_B] (Pa, Pa, Pa, rad/s, rad/s), inputs U = [h, w_p] (spool [m],
pump speed command [rad/s]); paper eqs. (1)-(2), docs/plant.md sections 2-3.

The kernels are compiled with numba and work on one operating point; their ``py_func`` is the same
code in plain Python (used as the straightforward baseline in the benchmarks).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from hwpts.plant.parameters import PARAMETER_INDEX as _I
from hwpts.plant.parameters import PlantParameters
from hwpts.plant.valve import (MAKEUP_ONSET_PA, makeup_shape, makeup_shape_derivative, orifice_shape,
                              orifice_shape_derivative, smooth_max0, smooth_max0_derivative)

N_STATES = 5
STATE_NAMES = ("pump_pressure_pa", "motor_a_pressure_pa", "motor_b_pressure_pa", "motor_a_speed", "motor_b_speed")

# parameter positions in PlantParameters.as_array() (compile-time constants for numba)
_RHO = _I["oil_density"]
_BETA = _I["bulk_modulus"]
_CD = _I["discharge_coefficient"]
_AMAX = _I["max_orifice_area"]
_HMAX = _I["spool_stroke"]
_ALEAK = _I["leak_area"]
_PCR = _I["orifice_transition_pressure"]
_EPS = _I["smoothing_pressure"]
_POB = _I["aux_opening_pressure"]
_VP = _I["pump_chamber_volume"]
_VA = _I["motor_a_chamber_volume"]
_VB = _I["motor_b_chamber_volume"]
_DP = _I["pump_displacement"]
_CSP = _I["pump_leakage"]
_DMA = _I["motor_a_displacement"]
_DMB = _I["motor_b_displacement"]
_CSA = _I["motor_a_leakage"]
_CSB = _I["motor_b_leakage"]
_JA = _I["motor_a_inertia"]
_JB = _I["motor_b_inertia"]
_BA = _I["motor_a_damping"]
_BB = _I["motor_b_damping"]
_TCA = _I["motor_a_load_torque"]
_TCB = _I["motor_b_load_torque"]
_WS = _I["coulomb_speed_width"]
_PRV = _I["relief_pressure"]
_KRV = _I["relief_gain"]
_KMU = _I["makeup_gain"]
_KDR = _I["droop_gain"]
_KG = _I["generator_slip_gain"]
_WSYNC = _I["generator_synchronous_speed"]


@numba.njit(cache=True)
def pump_speed_actual(pump_pressure, pump_speed_command, p):
    """Pump speed after prime-mover droop: w_p = max(w_p,cmd - K_droop * D_p * P_p, 0) [rad/s]
    (docs/plant.md 2.9): the turbine-driven pump slows under load but does not turn backwards (a
    command of 0 at 7 MPa gave -577 r/min, the pump motoring the line empty)."""
    return np.maximum(pump_speed_command - p[_KDR] * p[_DP] * pump_pressure, 0.0)


@numba.njit(cache=True)
def pump_speed_slope(pump_pressure, pump_speed_command, p):
    """d w_p / d P_p of :func:`pump_speed_actual` [(rad/s)/Pa]: the droop while the pump turns, 0 once stopped."""
    if pump_speed_command - p[_KDR] * p[_DP] * pump_pressure > 0.0:
        return -p[_KDR] * p[_DP]
    return 0.0


@numba.njit(cache=True)
def rhs_into(x, h, wp_cmd, p, dx):
    """Write F(x, h, w_p,cmd) into dx[0:5]: the full model (relief, make-up, droop), docs/plant.md section 2.

    With the generator option (K_g > 0, off by default) shaft A also carries the induction
    generator's slip torque K_g * (w_A - w_sync), linear in the slip as below the breakdown torque.
    """
    pp = x[0]
    pa = x[1]
    pb = x[2]
    wa = x[3]
    wb = x[4]
    eps = p[_EPS]
    c = p[_CD] * math.sqrt(2.0 / p[_RHO])
    frac = h / p[_HMAX]
    area_a = p[_AMAX] * (1.0 - frac) + p[_ALEAK]
    area_b = p[_AMAX] * frac + p[_ALEAK]
    qa = c * area_a * orifice_shape(pp - pa, p[_PCR], eps)
    qb = c * area_b * orifice_shape(pp - pb - p[_POB], p[_PCR], eps)
    qp = p[_DP] * pump_speed_actual(pp, wp_cmd, p) - p[_CSP] * pp
    qrv = p[_KRV] * smooth_max0(pp - p[_PRV], eps)
    kmu = p[_KMU]
    dx[0] = p[_BETA] / p[_VP] * (qp - qa - qb - qrv + kmu * makeup_shape(-pp, MAKEUP_ONSET_PA))
    dx[1] = p[_BETA] / p[_VA] * (qa - p[_DMA] * wa - p[_CSA] * pa + kmu * makeup_shape(-pa, MAKEUP_ONSET_PA))
    dx[2] = p[_BETA] / p[_VB] * (qb - p[_DMB] * wb - p[_CSB] * pb + kmu * makeup_shape(-pb, MAKEUP_ONSET_PA))
    dx[3] = (p[_DMA] * pa - p[_BA] * wa - p[_TCA] * math.tanh(wa / p[_WS]) - p[_KG] * (wa - p[_WSYNC])) / p[_JA]
    dx[4] = (p[_DMB] * pb - p[_BB] * wb - p[_TCB] * math.tanh(wb / p[_WS])) / p[_JB]


@numba.njit(cache=True)
def jacobian_into(x, h, wp_cmd, p, jac, dfdh):
    """Write dF/dx into jac[0:5, 0:5] and dF/dh into dfdh[0:5] (analytic)."""
    pp = x[0]
    pa = x[1]
    pb = x[2]
    wa = x[3]
    wb = x[4]
    eps = p[_EPS]
    pcr = p[_PCR]
    c = p[_CD] * math.sqrt(2.0 / p[_RHO])
    frac = h / p[_HMAX]
    area_a = p[_AMAX] * (1.0 - frac) + p[_ALEAK]
    area_b = p[_AMAX] * frac + p[_ALEAK]
    dpa = pp - pa
    dpb = pp - pb - p[_POB]
    ga = c * area_a * orifice_shape_derivative(dpa, pcr, eps)  # dQA/d(dpa)
    gb = c * area_b * orifice_shape_derivative(dpb, pcr, eps)  # dQB/d(dpb)
    dqa_dh = -c * p[_AMAX] / p[_HMAX] * orifice_shape(dpa, pcr, eps)
    dqb_dh = c * p[_AMAX] / p[_HMAX] * orifice_shape(dpb, pcr, eps)
    kmu = p[_KMU]
    dqp_dpp = p[_DP] * pump_speed_slope(pp, wp_cmd, p) - p[_CSP]
    dqrv_dpp = p[_KRV] * smooth_max0_derivative(pp - p[_PRV], eps)
    kp = p[_BETA] / p[_VP]
    ka = p[_BETA] / p[_VA]
    kb = p[_BETA] / p[_VB]
    for i in range(5):
        for j in range(5):
            jac[i, j] = 0.0
    jac[0, 0] = kp * (dqp_dpp - ga - gb - dqrv_dpp - kmu * makeup_shape_derivative(-pp, MAKEUP_ONSET_PA))
    jac[0, 1] = kp * ga
    jac[0, 2] = kp * gb
    jac[1, 0] = ka * ga
    jac[1, 1] = ka * (-ga - p[_CSA] - kmu * makeup_shape_derivative(-pa, MAKEUP_ONSET_PA))
    jac[1, 3] = -ka * p[_DMA]
    jac[2, 0] = kb * gb
    jac[2, 2] = kb * (-gb - p[_CSB] - kmu * makeup_shape_derivative(-pb, MAKEUP_ONSET_PA))
    jac[2, 4] = -kb * p[_DMB]
    ta = math.tanh(wa / p[_WS])
    tb = math.tanh(wb / p[_WS])
    jac[3, 1] = p[_DMA] / p[_JA]
    jac[3, 3] = (-p[_BA] - p[_TCA] / p[_WS] * (1.0 - ta * ta) - p[_KG]) / p[_JA]
    jac[4, 2] = p[_DMB] / p[_JB]
    jac[4, 4] = (-p[_BB] - p[_TCB] / p[_WS] * (1.0 - tb * tb)) / p[_JB]
    dfdh[0] = -kp * (dqa_dh + dqb_dh)
    dfdh[1] = ka * dqa_dh
    dfdh[2] = kb * dqb_dh
    dfdh[3] = 0.0
    dfdh[4] = 0.0


def _point(parameters: PlantParameters, state, spool, pump_speed_command):
    x = np.ascontiguousarray(state, dtype=np.float64).reshape(-1)
    if x.shape != (N_STATES,):
        raise ValueError(f"state must have {N_STATES} entries, got shape {np.shape(state)}")
    return x, float(spool), float(pump_speed_command), parameters.as_array()


def rhs(parameters: PlantParameters, state, spool, pump_speed_command) -> np.ndarray:
    """dx/dt [SI] at one point: state (5,), spool h [m], pump speed command [rad/s]."""
    x, h, w, p = _point(parameters, state, spool, pump_speed_command)
    dx = np.empty(N_STATES)
    rhs_into(x, h, w, p, dx)
    return dx


def jacobian(parameters: PlantParameters, state, spool, pump_speed_command):
    """(dF/dx (5, 5), dF/dh (5,)) at one point, analytic."""
    x, h, w, p = _point(parameters, state, spool, pump_speed_command)
    jac = np.empty((N_STATES, N_STATES))
    dfdh = np.empty(N_STATES)
    jacobian_into(x, h, w, p, jac, dfdh)
    return jac, dfdh


def paper_form(parameters: PlantParameters, state):
    """The paper's split x' = f(x) + g(x) U, U = [h, w_p] (eq. 2; docs/plant.md section 3).

    Exact (unregularised) square-root orifices, no droop, no make-up flows. Returns f (5,) and
    g (5, 2). Agrees with :func:`rhs` wherever the orifice pressure drops are well above p_cr and
    the leak areas are negligible.
    """
    pp, pa, pb, wa, wb = np.asarray(state, dtype=float)
    p = parameters
    k = p.discharge_coefficient * p.max_orifice_area * math.sqrt(2.0 / p.oil_density)
    phi_a = math.sqrt(max(pp - pa, 0.0))
    phi_b = math.sqrt(max(pp - pb - p.aux_opening_pressure, 0.0))
    qrv = p.relief_gain * max(pp - p.relief_pressure, 0.0)
    kp = p.bulk_modulus / p.pump_chamber_volume
    ka = p.bulk_modulus / p.motor_a_chamber_volume
    kb = p.bulk_modulus / p.motor_b_chamber_volume
    f = np.array(
        [
            kp * (-p.pump_leakage * pp - k * phi_a - qrv),
            ka * (k * phi_a - p.motor_a_displacement * wa - p.motor_a_leakage * pa),
            kb * (-p.motor_b_displacement * wb - p.motor_b_leakage * pb),
            (p.motor_a_displacement * pa - p.motor_a_damping * wa
             - p.motor_a_load_torque * math.tanh(wa / p.coulomb_speed_width)
             - p.generator_slip_gain * (wa - p.generator_synchronous_speed)) / p.motor_a_inertia,
            (p.motor_b_displacement * pb - p.motor_b_damping * wb
             - p.motor_b_load_torque * math.tanh(wb / p.coulomb_speed_width)) / p.motor_b_inertia,
        ]
    )
    g = np.zeros((N_STATES, 2))
    g[0, 0] = kp * k / p.spool_stroke * (phi_a - phi_b)
    g[0, 1] = kp * p.pump_displacement
    g[1, 0] = -ka * k / p.spool_stroke * phi_a
    g[2, 0] = kb * k / p.spool_stroke * phi_b
    return f, g


def linearize(parameters: PlantParameters, state, spool, pump_speed_command):
    """Linear model (A, B, C, D) of spool h -> motor A speed w_A about an operating point.

    A = dF/dx, B = dF/dh (5 x 1), C selects w_A, D = 0.
    """
    a, b = jacobian(parameters, state, spool, pump_speed_command)
    c = np.zeros((1, N_STATES))
    c[0, 3] = 1.0
    return a, b.reshape(-1, 1), c, np.zeros((1, 1))


def transfer_poles_zeros(parameters: PlantParameters, state, spool, pump_speed_command):
    """Poles and finite (invariant) zeros of the linearised h -> w_A transfer function.

    The zeros are the finite generalised eigenvalues of the Rosenbrock system pencil
    ([[A, B], [C, D]], [[I, 0], [0, 0]]): robust where a polynomial numerator is not.
    """
    from scipy.linalg import eigvals

    a, b, c, d = linearize(parameters, state, spool, pump_speed_command)
    n = a.shape[0]
    poles = np.linalg.eigvals(a)
    # balance the pencil: scale rows/columns so pressures and speeds have comparable magnitude
    scale = np.array([1e6, 1e6, 1e6, 1e2, 1e2])
    t = np.diag(scale)
    ti = np.diag(1.0 / scale)
    a_s = ti @ a @ t
    b_s = ti @ b / np.max(np.abs(ti @ b))
    c_s = c @ t / np.max(np.abs(c @ t))
    m = np.block([[a_s, b_s], [c_s, d]])
    nmat = np.zeros_like(m)
    nmat[:n, :n] = np.eye(n)
    z = eigvals(m, nmat)
    finite = z[np.isfinite(z) & (np.abs(z) < 1e12)]
    return poles, finite
