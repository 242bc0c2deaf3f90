"""Wind as a wind engineer specifies it, and the turbine that turns it into the pump speed command.

Turbulence: the longitudinal component of IEC 61400-1 (ed. 3, 2005) annex B, Kaimal spectrum,
normal turbulence model (NTM, section 6.3.1.3):

    sigma_1 = I_ref * (0.75 * V_hub + b),  b = 5.6 m/s,  I_ref = 0.16 (A), 0.14 (B), 0.12 (C)
    S_1(f) = 4 * sigma_1^2 * (L_1 / V_hub) / (1 + 6 * f * L_1 / V_hub)^(5/3)
    L_1 = 8.1 * Lambda_1,  Lambda_1 = 0.7 * z_hub (z_hub <= 60 m), 42 m above

A record is a stationary Gaussian process drawn in the frequency domain (independent complex
Gaussian Fourier coefficients with variance S_1(f_k) * df, inverse real FFT). The spectrum is
normalised over the record's frequency band (1/T ... 1/(2 dt)) so that its variance is sigma_1^2:
the standard deviation IEC 61400-1 specifies for a 10-minute record.

Turbine (a documented small-turbine emulator, our assumption): below rated wind the rotor runs at
its optimal tip-speed ratio, omega_r = lambda_opt * V / R, and its inertia filters the wind as a
first-order lag of time constant tau_r; a gearbox of ratio n_g drives the pump (the turbine
emulator's speed command). Below cut-in the rotor stops; above rated wind the pitch holds the
rated speed. With the defaults 1 m/s of wind is 93.6 r/min of pump speed; 9.5 m/s gives 889 r/min.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hwpts.errors import ParameterError

TURBULENCE_CLASSES = {"A": 0.16, "B": 0.14, "C": 0.12}
"""I_ref, the expected turbulence intensity at 15 m/s, per IEC 61400-1 ed. 3 turbulence category."""

NTM_B = 5.6
"""b of the normal turbulence model [m/s] (IEC 61400-1 ed. 3, eq. 11)."""


def turbulence_sigma(mean_speed: float, turbulence_class: str) -> float:
    """sigma_1 = I_ref (0.75 V_hub + 5.6) [m/s] (IEC 61400-1 ed. 3, eq. 11, NTM)."""
    return TURBULENCE_CLASSES[_check_class(turbulence_class)] * (0.75 * mean_speed + NTM_B)


def length_scale(hub_height: float) -> float:
    """L_1 = 8.1 Lambda_1 [m], Lambda_1 = 0.7 z (z <= 60 m) else 42 m (IEC 61400-1 ed. 3, eq. 5 and annex B)."""
    return 8.1 * (0.7 * hub_height if hub_height <= 60.0 else 42.0)


def kaimal_spectrum(frequency, mean_speed: float, sigma: float, hub_height: float = 30.0):
    """One-sided Kaimal spectrum S_1(f) [(m/s)^2/Hz] of the longitudinal component (IEC 61400-1 annex B)."""
    f = np.asarray(frequency, dtype=float)
    lv = length_scale(hub_height) / mean_speed
    return 4.0 * sigma**2 * lv / (1.0 + 6.0 * f * lv) ** (5.0 / 3.0)


def _check_class(turbulence_class: str) -> str:
    c = str(turbulence_class).upper()
    if c not in TURBULENCE_CLASSES:
        raise ParameterError(f"turbulence class must be one of A, B, C; got {turbulence_class!r}")
    return c


def kaimal_wind(duration: float, sample_time: float, mean_speed: float, turbulence_class: str = "A",
                seed: int = 0, hub_height: float = 30.0) -> np.ndarray:
    """A turbulent wind speed record [m/s] on the grid 0, dt, ..., duration (IEC 61400-1 NTM, Kaimal).

    The same seed gives the same record.
    """
    if not (math.isfinite(mean_speed) and mean_speed > 0):
        raise ParameterError(f"mean wind speed must be > 0 m/s, got {mean_speed!r}")
    if not (math.isfinite(duration) and duration > 0 and math.isfinite(sample_time) and sample_time > 0):
        raise ParameterError(f"duration and sample_time must be > 0 s, got {duration!r}, {sample_time!r}")
    if not (math.isfinite(hub_height) and hub_height > 0):
        raise ParameterError(f"hub height must be > 0 m, got {hub_height!r}")
    sigma = turbulence_sigma(mean_speed, turbulence_class)
    n = int(round(duration / sample_time)) + 1
    rng = np.random.default_rng(seed)
    freqs = np.fft.rfftfreq(n, sample_time)
    df = freqs[1] - freqs[0] if n > 2 else 1.0 / duration
    s = kaimal_spectrum(freqs[1:], mean_speed, sigma, hub_height)
    s *= sigma**2 / np.sum(s * df)  # the record's band carries sigma_1^2 (see module doc)
    # irfft: bin k (0 < k < n/2) contributes (2/n)|X_k| cos(2 pi f_k t + phase), of variance
    # 2 E|X_k|^2 / n^2; it must carry S(f_k) df, so each of Re, Im has the std n sqrt(S df) / 2
    coef = np.zeros(freqs.size, dtype=complex)
    coef[1:] = (0.5 * n) * np.sqrt(s * df) * (rng.standard_normal(s.size) + 1j * rng.standard_normal(s.size))
    if n % 2 == 0:  # the Nyquist bin is real and contributes X/n (-1)^m: its std is n sqrt(S df)
        coef[-1] = n * math.sqrt(s[-1] * df) * rng.standard_normal()
    u = np.fft.irfft(coef, n)
    return mean_speed + u


@dataclass(frozen=True)
class Turbine:
    """The wind turbine driving the pump (see the module doc for the model and its defaults)."""

    rotor_radius_m: float = 1.5
    """R: rotor radius [m]."""
    optimal_tip_speed_ratio: float = 7.0
    """lambda_opt: tip-speed ratio of the maximum power coefficient [-]."""
    gear_ratio: float = 2.1
    """n_g: pump speed / rotor speed [-]."""
    rotor_time_constant_s: float = 1.0
    """tau_r: the rotor's inertia as a first-order lag on the wind [s]."""
    cut_in_m_s: float = 3.0
    """Below this wind speed the rotor stands still [m/s]."""
    rated_pump_speed_rpm: float = 1000.0
    """Pump speed at rated wind; the pitch holds it above [r/min]."""

    def __post_init__(self):
        for name in ("rotor_radius_m", "optimal_tip_speed_ratio", "gear_ratio", "rated_pump_speed_rpm"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ParameterError(f"{name} must be > 0, got {value!r}")
        if not (math.isfinite(self.rotor_time_constant_s) and self.rotor_time_constant_s >= 0):
            raise ParameterError(f"rotor_time_constant_s must be >= 0, got {self.rotor_time_constant_s!r}")

    @property
    def rpm_per_m_s(self) -> float:
        """Pump speed per wind speed below rated [r/min per m/s]."""
        return self.gear_ratio * self.optimal_tip_speed_ratio / self.rotor_radius_m * 30.0 / math.pi

    def steady_pump_speed(self, wind_speed):
        """Pump speed command [r/min] in steady wind [m/s]."""
        v = np.asarray(wind_speed, dtype=float)
        w = np.where(v < self.cut_in_m_s, 0.0, self.rpm_per_m_s * v)
        return np.minimum(w, self.rated_pump_speed_rpm)

    def wind_for_pump_speed(self, pump_speed_rpm: float) -> float:
        """The steady wind speed [m/s] that gives this pump speed below rated."""
        return pump_speed_rpm / self.rpm_per_m_s

    def pump_speed_command(self, wind_speed, sample_time: float, initial=None) -> np.ndarray:
        """Pump speed command [r/min] for a wind record [m/s]: the rotor lag, then cut-in and rated limits."""
        v = np.asarray(wind_speed, dtype=float)
        target = self.steady_pump_speed(v)
        tau = self.rotor_time_constant_s
        if tau == 0:
            return target
        a = math.exp(-sample_time / tau)
        from scipy.signal import lfilter

        start = target[0] if initial is None else float(initial)
        out, _ = lfilter([1.0 - a], [1.0, -a], target, zi=[a * start])
        return out
