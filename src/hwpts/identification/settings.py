"""Checks of the estimators' settings before any fit: a :class:`ParameterError` of one line naming
the setting (after ``owner``, e.g. ``"PWARXSearch: "``), what it takes and what it got. A ``bool``
is no number here, and NaN or inf no number at all."""

from __future__ import annotations

import numpy as np

from hwpts.errors import ParameterError

__all__ = ["is_count", "is_number", "check_count", "check_number", "check_bool", "check_random_state"]


def is_count(value, low: int) -> bool:
    """Whether ``value`` is an int (not a bool) ``>= low``."""
    return not isinstance(value, bool) and isinstance(value, (int, np.integer)) and value >= low


def is_number(value, low: float = 0.0, strict: bool = False, finite: bool = True) -> bool:
    """Whether ``value`` is a number (not a bool) ``>= low`` (``> low`` when ``strict``), finite
    unless ``finite`` is False (then +infinity counts: no regularisation, no margin)."""
    return (not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
            and not np.isnan(value) and (not finite or bool(np.isfinite(value)))
            and (value > low if strict else value >= low))


def check_count(value, name: str, low: int, owner: str = "", allow=()) -> None:
    """``value`` is an int ``>= low``, or one of the strings ``allow``."""
    if any(isinstance(value, str) and value == a for a in allow) or is_count(value, low):
        return
    extra = "".join(f" or {a!r}" for a in allow)
    raise ParameterError(f"{owner}{name} must be an int >= {low}{extra}, got {value!r}")


def check_number(value, name: str, low: float = 0.0, strict: bool = False, owner: str = "",
                 finite: bool = True) -> None:
    """``value`` is a number ``>= low`` (``> low`` when ``strict``), finite unless ``finite`` is False."""
    if not is_number(value, low, strict, finite):
        raise ParameterError(f"{owner}{name} must be a number {'>' if strict else '>='} {low:g}, got {value!r}")


def check_bool(value, name: str, owner: str = "") -> None:
    """``value`` is ``True`` or ``False`` (a numpy bool too), not a string or a number read as one."""
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{owner}{name} must be True or False, got {value!r}")


def check_random_state(seed, owner: str = "") -> None:
    """``seed`` is what numpy's ``default_rng`` takes: None, an int >= 0, a SeedSequence, a
    Generator (a bool, a float or a text is refused although numpy would read some of them)."""
    try:
        if isinstance(seed, (bool, np.bool_, str, bytes, float)):
            raise TypeError
        np.random.default_rng(seed)
    except (TypeError, ValueError):
        shown = seed if isinstance(seed, (bool, str, bytes, float, int)) else type(seed).__name__
        raise ParameterError(f"{owner}random_state must be None, an int >= 0 or a numpy Generator or SeedSequence, "
                             f"got {shown!r}") from None
