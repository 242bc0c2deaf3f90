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

import os as _os


def _numba_cache_dir() -> None:
    """Give numba a cache folder where it would find none (it raises at the first compiled
    function then): a read-only install with no writable home. The package's own ``__pycache__``
    or the user's cache folder is used when either is writable; else a private temporary folder
    of this process (mode 0700: a shared, predictable one would let another user plant code)."""
    if _os.environ.get("NUMBA_CACHE_DIR") or _os.access(_os.path.dirname(__file__), _os.W_OK):
        return
    base = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache")
    while base and not _os.path.exists(base):  # numba makes the folder if its first existing parent is writable
        parent = _os.path.dirname(base)
        base = "" if parent == base else parent
    if base and _os.access(base, _os.W_OK):
        return
    import atexit
    import shutil
    import tempfile

    try:
        folder = tempfile.mkdtemp(prefix="hwpts-numba-")
    except OSError:  # no writable temporary folder either: numba will say so
        return
    _os.environ["NUMBA_CACHE_DIR"] = folder
    atexit.register(shutil.rmtree, folder, True)  # the process's own cache: gone with it


_numba_cache_dir()

from hwpts.errors import (  # noqa: E402 - after the cache folder, before numba is imported
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
