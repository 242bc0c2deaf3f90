import numpy as np
import pytest

from hwpts.experiments.paper import paper_hyperplanes
from hwpts.experiments.sweeps import estimate_hysteresis, find_fracture, record_sweeps
from hwpts.plant import PlantParameters


@pytest.mark.parametrize("r", [0.1, 0.25, 0.4])
def test_hysteresis_width_is_read_off_the_sweeps(r):
    sweeps = record_sweeps(PlantParameters.paper().replace(hysteresis_half_width=r), progress=False)
    assert estimate_hysteresis(sweeps) == pytest.approx(r, abs=0.01)


def test_no_hysteresis_reads_zero():
    sweeps = record_sweeps(PlantParameters.averaged(), progress=False)
    assert estimate_hysteresis(sweeps) == pytest.approx(0.0, abs=0.01)


def test_fracture_regions_and_the_paper_partition():
    f = find_fracture(record_sweeps(progress=False))
    v = np.array([3.6, 1.5, 3.0])
    w = np.array([500.0, 300.0, 900.0])
    assert f.regions(v, w).tolist() == [0, 2, 1]
    closed, plateau = paper_hyperplanes(f, "hi")
    a, c = np.array(plateau.coefficients, dtype=float), float(plateau.offset)
    assert a @ [3.0, 900] + c >= 0 and a @ [1.5, 300] + c < 0  # the plateau side holds
    assert list(closed.coefficients) == [1.0] and closed.offset == -3.5
