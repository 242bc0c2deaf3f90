"""One error tree for the whole package.

Every class is also a built-in exception, so ``except ValueError`` keeps working
(as scikit-learn's ``NotFittedError(ValueError, AttributeError)``).
"""


class HwptsError(Exception):
    """Base class of every error hwpts raises on purpose."""


class ParameterError(HwptsError, ValueError):
    """A parameter or argument has a value outside what it accepts."""


class DataError(HwptsError, ValueError):
    """A dataset, file or signal is malformed (missing column, NaN, bad time axis...)."""


class SimulationError(HwptsError, RuntimeError):
    """A simulation or steady-state solve failed; the message carries the solver's diagnosis."""


class IdentificationError(HwptsError, RuntimeError):
    """An identification step could not produce a model (empty region, singular problem...)."""


class UsageError(HwptsError, ValueError):
    """A command-line argument is malformed (raised by the CLI's argument parser)."""
