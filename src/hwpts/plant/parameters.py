"""Parameters of the HWPTS test bed (docs/plant.md section 5), in SI units.

Every field carries the symbol of docs/plant.md and its unit. ``PlantParameters.paper()`` gives the
defaults; ``averaged()`` the hysteresis-free valve the paper's PWA model stands for; ``test_bed()``
the rig as it records data (prime-mover droop on).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from hwpts.errors import ParameterError

# Physical ranges of the test bed's inputs, checked wherever the plant takes them: the valve
# amplifier's command range (the spool saturates outside 1.2-3.5 V, docs/plant.md section 4) and
# the prime mover's speed range (the paper operates at 200-1000 r/min).
VALVE_VOLTAGE_RANGE_V = (0.0, 10.0)
PUMP_SPEED_RANGE_RPM = (0.0, 3000.0)


def check_input_ranges(valve_voltage, pump_speed_rpm, error=ParameterError, where: str = "") -> None:
    """Refuse valve commands [V] or pump speeds [r/min] that are not finite or lie outside the
    test bed's physical ranges (:data:`VALVE_VOLTAGE_RANGE_V`, :data:`PUMP_SPEED_RANGE_RPM`)."""
    for label, unit, values, (lo, hi) in (("valve voltage", "V", valve_voltage, VALVE_VOLTAGE_RANGE_V),
                                          ("pump speed", "r/min", pump_speed_rpm, PUMP_SPEED_RANGE_RPM)):
        a = np.asarray(values, dtype=float)
        bad = ~np.isfinite(a) | (a < lo) | (a > hi)
        if np.any(bad):
            first = a[bad].ravel()[0]
            raise error(f"{where}{label} must be a finite number in {lo:g}-{hi:g} {unit} (the test bed's range), "
                        f"got {float(first):g}")


DROOP_TEST_BED = 3.37
"""Prime-mover droop K_droop of the lab rig [(rad/s)/(N m)] (docs/plant.md section 5, tuned on the triangle test)."""


@dataclass(frozen=True)
class PlantParameters:
    """Physical parameters of the hydraulic wind power transfer system (SI units).

    Tags follow docs/plant.md: paper, recon(struction), tuned, assumed, numerical.
    """

    oil_density: float = 870.0
    """rho: oil density [kg/m^3] (assumed)."""
    bulk_modulus: float = 1.0e9
    """beta: effective bulk modulus of oil and hoses [Pa] (assumed)."""
    discharge_coefficient: float = 0.65
    """C_D: orifice discharge coefficient [-] (recon)."""
    max_orifice_area: float = 9.003e-6
    """A_max: largest outlet area of the proportional valve [m^2] (tuned: the 5 gal/min valve)."""
    spool_stroke: float = 1.0e-3
    """h_max: spool travel [m] (assumed)."""
    leak_area: float = 1.0e-8
    """A_leak: area of a closed valve port [m^2] (numerical)."""
    orifice_transition_pressure: float = 2.0e4
    """p_cr: below this pressure drop the orifice law turns laminar, keeping the Jacobian finite [Pa] (numerical)."""
    smoothing_pressure: float = 1.0e3
    """Width of the smooth max(dP, 0) of the check valves, relief and make-up valves [Pa] (numerical)."""
    valve_voltage_open: float = 1.2
    """V_0: command at which outlet A is fully open, spool h = 0 [V] (paper)."""
    valve_voltage_closed: float = 3.5
    """V_1: command at which outlet A is closed, spool h = h_max [V] (paper: wA = 0 for hi >= 3.5 V)."""
    hysteresis_half_width: float = 0.25
    """r: half-width of the play operator of the valve coil [V]; 0 = the averaged valve (tuned)."""
    spool_time_constant: float = 0.0
    """tau_v: first-order spool lag [s]; 0 = no lag, the 5-state paper form (assumed, optional)."""
    aux_opening_pressure: float = 1.8848e6
    """P_oB: opening pressure of the auxiliary branch B (check valve spring / breakaway load) [Pa] (tuned, eq. 16)."""
    pump_chamber_volume: float = 2.5e-4
    """V_p: oil volume between pump and valve [m^3] (assumed)."""
    motor_a_chamber_volume: float = 1.0e-4
    """V_A: oil volume between valve and motor A [m^3] (assumed)."""
    motor_b_chamber_volume: float = 1.0e-4
    """V_B: oil volume between valve and motor B [m^3] (assumed)."""
    pump_displacement: float = 2.4857e-6
    """D_p: pump displacement [m^3/rad] (15.6 cm^3/rev, tuned)."""
    pump_leakage: float = 1.0e-12
    """C_sp: pump leakage coefficient [m^3/(s Pa)] (tuned)."""
    motor_a_displacement: float = 1.305e-6
    """D_mA: main motor displacement [m^3/rad] (8.2 cm^3/rev, assumed)."""
    motor_b_displacement: float = 1.305e-6
    """D_mB: auxiliary motor displacement [m^3/rad] (assumed)."""
    motor_a_leakage: float = 1.688e-11
    """C_sA: main motor leakage [m^3/(s Pa)] (tuned)."""
    motor_b_leakage: float = 6.0e-12
    """C_sB: auxiliary motor leakage [m^3/(s Pa)] (assumed)."""
    motor_a_inertia: float = 6.0e-3
    """J_A: inertia of motor A and its generator [kg m^2] (assumed)."""
    motor_b_inertia: float = 3.0e-3
    """J_B: inertia of motor B and its generator [kg m^2] (assumed)."""
    motor_a_damping: float = 2.0e-3
    """B_A: viscous damping of shaft A [N m s/rad] (assumed)."""
    motor_b_damping: float = 1.5e-3
    """B_B: viscous damping of shaft B [N m s/rad] (assumed)."""
    motor_a_load_torque: float = 1.0
    """T_cA: constant load torque on shaft A (generator + electric load) [N m] (assumed)."""
    motor_b_load_torque: float = 0.5
    """T_cB: constant load torque on shaft B [N m] (assumed)."""
    coulomb_speed_width: float = 0.5
    """w_s: width of the tanh standing in for sgn(w) in the load torque [rad/s] (numerical)."""
    relief_pressure: float = 6.9e6
    """P_rv: relief valve setting on the pump line [Pa] (assumed)."""
    relief_gain: float = 1.0e-9
    """K_rv: relief valve flow gain [m^3/(s Pa)] (assumed: full pump flow at 3000 r/min passes 0.8 MPa above the
    setting, 11 %; 1e-10 needed 7.8 MPa, and a valve step peaked at 11.2 MPa)."""
    makeup_gain: float = 1.0e-6
    """K_mu: make-up check valve gain keeping pressures >= 0 [m^3/(s Pa)] (numerical: 1e-9 let motor A's
    inlet fall to -135 kPa in validation case 2, below vacuum; at 1e-6 the pressures stay above -1.1 kPa,
    the opening over :data:`~hwpts.plant.valve.MAKEUP_ONSET_PA` included, at full flow)."""
    droop_gain: float = 0.0
    """K_droop: prime-mover droop, w_p = max(w_p,cmd - K_droop * D_p * P_p, 0) [(rad/s)/(N m)]; test bed 3.37 (tuned)."""
    generator_slip_gain: float = 0.0
    """K_g: slope of the induction generator's slip torque on shaft A, T_g = K_g * (w_A - w_sync)
    [N m s/rad] (an option of ours, not in the paper; 0 = off, the paper's 5-state plant)."""
    generator_synchronous_speed: float = 1000.0 * math.pi / 30.0
    """w_sync: synchronous speed of the induction generator on shaft A [rad/s] (1000 r/min; used when K_g > 0)."""

    def __post_init__(self):
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(f"{f.name} must be a real number, got {value!r}")
            if not math.isfinite(value):
                raise ParameterError(f"{f.name} must be finite, got {value!r}")
            object.__setattr__(self, f.name, float(value))
        non_negative = {
            "leak_area", "hysteresis_half_width", "spool_time_constant", "aux_opening_pressure",
            "pump_leakage", "motor_a_leakage", "motor_b_leakage", "motor_a_damping",
            "motor_b_damping", "motor_a_load_torque", "motor_b_load_torque", "relief_gain",
            "makeup_gain", "droop_gain", "generator_slip_gain",
        }
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name in non_negative:
                if value < 0:
                    raise ParameterError(f"{f.name} must be >= 0, got {value!r}")
            elif f.name not in ("valve_voltage_open", "valve_voltage_closed") and value <= 0:
                raise ParameterError(f"{f.name} must be > 0, got {value!r}")
        if self.valve_voltage_closed <= self.valve_voltage_open:
            raise ParameterError(
                "valve_voltage_closed must exceed valve_voltage_open; got "
                f"{self.valve_voltage_closed} <= {self.valve_voltage_open}"
            )

    # -- constructors -------------------------------------------------------------------------
    @classmethod
    def paper(cls) -> PlantParameters:
        """The defaults of docs/plant.md section 5: hysteretic valve (r = 0.25 V), no droop."""
        return cls()

    @classmethod
    def averaged(cls) -> PlantParameters:
        """The averaged valve (r = 0) the paper's PWA model stands for (docs/plant.md section 4)."""
        return cls(hysteresis_half_width=0.0)

    @classmethod
    def test_bed(cls) -> PlantParameters:
        """The lab rig as it records data: hysteresis on and prime-mover droop on (K_droop = 3.37)."""
        return cls(droop_gain=DROOP_TEST_BED)

    def replace(self, **changes) -> PlantParameters:
        """A copy with some fields changed (validated again)."""
        try:
            return dataclasses.replace(self, **changes)
        except TypeError as error:
            raise ParameterError(str(error)) from None

    # -- packing for the compiled kernels -----------------------------------------------------
    def as_array(self) -> np.ndarray:
        """The parameters as a float64 vector in the order of :data:`PARAMETER_INDEX`."""
        return np.array([getattr(self, name) for name in PARAMETER_NAMES], dtype=np.float64)


PARAMETER_NAMES: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(PlantParameters))
PARAMETER_INDEX: dict[str, int] = {name: i for i, name in enumerate(PARAMETER_NAMES)}
