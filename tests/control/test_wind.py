"""The Kaimal turbulence generator against IEC 61400-1 ed. 3 (eq. 11 NTM, annex B Kaimal spectrum)."""

import numpy as np
import pytest
from scipy.signal import welch

from hwpts.control.wind import Turbine, kaimal_spectrum, kaimal_wind, length_scale, turbulence_sigma
from hwpts.errors import ParameterError


@pytest.mark.parametrize("cls, iref", [("A", 0.16), ("B", 0.14), ("C", 0.12)])
def test_turbulence_intensity_matches_the_ntm(cls, iref):
    v = 9.5
    sigma = iref * (0.75 * v + 5.6)  # IEC 61400-1 ed. 3, eq. 11
    assert turbulence_sigma(v, cls) == pytest.approx(sigma)
    records = [kaimal_wind(600.0, 0.05, v, cls, seed=s) for s in range(30)]
    variance = np.mean([r.var() for r in records])
    assert np.sqrt(variance) == pytest.approx(sigma, rel=0.06)
    assert np.mean([r.mean() for r in records]) == pytest.approx(v, abs=0.3)
    assert np.sqrt(variance) / v == pytest.approx(sigma / v, rel=0.06)  # turbulence intensity


def test_spectrum_matches_kaimal():
    v, z = 10.0, 30.0
    sigma = turbulence_sigma(v, "A")
    lv = 8.1 * 0.7 * z / v  # L_1 / V_hub, Lambda_1 = 0.7 z below 60 m
    assert length_scale(z) == pytest.approx(8.1 * 21.0)
    records = np.array([kaimal_wind(600.0, 0.05, v, "A", seed=s, hub_height=z) for s in range(40)])
    f, p = welch(records - v, fs=20.0, nperseg=2048, axis=-1)
    p = p.mean(axis=0)
    s_iec = 4 * sigma**2 * lv / (1 + 6 * f * lv) ** (5 / 3)
    assert np.allclose(kaimal_spectrum(f, v, sigma, z), s_iec)
    for lo, hi in [(0.02, 0.05), (0.05, 0.2), (0.2, 1.0), (1.0, 5.0)]:
        band = (f >= lo) & (f < hi)
        ratio = p[band].mean() / s_iec[band].mean()
        assert ratio == pytest.approx(1.0, abs=0.2), (lo, hi, ratio)


def test_same_seed_same_wind_and_bad_class():
    a = kaimal_wind(60, 0.01, 8.0, "B", seed=3)
    assert np.array_equal(a, kaimal_wind(60, 0.01, 8.0, "B", seed=3))
    assert not np.array_equal(a, kaimal_wind(60, 0.01, 8.0, "B", seed=4))
    with pytest.raises(ParameterError, match="turbulence class"):
        kaimal_wind(60, 0.01, 8.0, "D")


def test_turbine_maps_wind_to_pump_speed():
    t = Turbine()
    assert t.steady_pump_speed(2.0) == 0.0  # below cut-in
    assert t.steady_pump_speed(9.5) == pytest.approx(9.5 * t.rpm_per_m_s)
    assert t.steady_pump_speed(20.0) == t.rated_pump_speed_rpm
    step = t.pump_speed_command(np.r_[np.full(100, 8.0), np.full(1000, 9.0)], 0.01)
    k63 = np.argmax(step >= 8 * t.rpm_per_m_s + 0.632 * t.rpm_per_m_s) - 100
    assert k63 * 0.01 == pytest.approx(t.rotor_time_constant_s, abs=0.02)
