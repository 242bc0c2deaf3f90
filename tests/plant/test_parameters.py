import dataclasses

import numpy as np
import pytest

from hwpts.errors import ParameterError
from hwpts.plant.parameters import DROOP_TEST_BED, PARAMETER_NAMES, PlantParameters


def test_paper_defaults_match_plant_md_table():
    # PLANT.md section 5
    p = PlantParameters.paper()
    assert p.max_orifice_area == 9.003e-6
    assert p.aux_opening_pressure == 1.8848e6
    assert p.pump_displacement == 2.4857e-6
    assert p.hysteresis_half_width == 0.25
    assert p.droop_gain == 0.0
    assert (p.valve_voltage_open, p.valve_voltage_closed) == (1.2, 3.5)


def test_variants():
    assert PlantParameters.averaged().hysteresis_half_width == 0.0
    assert PlantParameters.test_bed().droop_gain == DROOP_TEST_BED


def test_frozen():
    p = PlantParameters.paper()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.bulk_modulus = 1.0


def test_every_field_is_documented_with_a_unit():
    source = open(PlantParameters.__module__.replace(".", "/").replace("hwpts", "src/hwpts", 1) + ".py").read()
    for name in PARAMETER_NAMES:
        block = source.split(f"    {name}: float")[1].split('"""')[1]
        assert "[" in block and "]" in block, f"{name} has no unit in its docstring"


@pytest.mark.parametrize(
    "changes, match",
    [
        ({"bulk_modulus": -1.0}, "bulk_modulus must be > 0"),
        ({"hysteresis_half_width": -0.1}, "hysteresis_half_width must be >= 0"),
        ({"oil_density": float("nan")}, "oil_density must be finite"),
        ({"valve_voltage_closed": 1.0}, "valve_voltage_closed must exceed"),
        ({"pump_displacement": "big"}, "pump_displacement must be a real number"),
        ({"no_such_field": 1.0}, "no_such_field"),
    ],
)
def test_validation(changes, match):
    with pytest.raises(ParameterError, match=match):
        PlantParameters.paper().replace(**changes)


def test_as_array_order():
    p = PlantParameters.paper()
    a = p.as_array()
    assert a.shape == (len(PARAMETER_NAMES),)
    assert np.all([a[i] == getattr(p, n) for i, n in enumerate(PARAMETER_NAMES)])
