"""hwpts: piecewise affine (PWARX) identification and a hydraulic wind power transfer system simulator.

Layers:

- :mod:`hwpts.plant` - the physical simulator of the HWPTS test bed;
- :mod:`hwpts.identification` - a general PWARX library (never imports the plant);
- :mod:`hwpts.experiments` - the paper's recordings and pipeline;
- :mod:`hwpts.io` - datasets and model files (the only layer that touches files);
- :mod:`hwpts.reporting` - figures, tables and the HTML report (never fits or simulates);
- :mod:`hwpts.control` - speed controllers designed from an identified model, closed loop;
- :mod:`hwpts.commands` and :mod:`hwpts.cli` - the ``hwpts`` command line.
"""

from hwpts.errors import (
    DataError,
    HwptsError,
    IdentificationError,
    ParameterError,
    SimulationError,
)

__version__ = "0.1.0"

__all__ = [
    "DataError",
    "HwptsError",
    "IdentificationError",
    "ParameterError",
    "SimulationError",
    "__version__",
]
