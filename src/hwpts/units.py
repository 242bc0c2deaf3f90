"""Unit conversions. The CLI and datasets speak r/min, volts and seconds; the simulator works in SI."""

import math

RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)
"""Multiply an angular speed in rad/s by this to get r/min."""

RAD_S_PER_RPM = 2.0 * math.pi / 60.0
"""Multiply an angular speed in r/min by this to get rad/s."""


def rpm_to_rad_s(speed_rpm):
    """Angular speed from r/min to rad/s (works on scalars and arrays)."""
    return speed_rpm * RAD_S_PER_RPM


def rad_s_to_rpm(speed_rad_s):
    """Angular speed from rad/s to r/min (works on scalars and arrays)."""
    return speed_rad_s * RPM_PER_RAD_S


# a signal's unit by its name's suffix (case-insensitive), as the command line reads a data file
UNIT_SUFFIXES = {"_rpm": "r/min", "_v": "V", "_bar": "bar", "_s": "s", "_nm": "N m", "_mm": "mm",
                 "_m": "m", "_hz": "Hz", "_w": "W", "_kw": "kW", "_pct": "%", "_lpm": "L/min", "_deg": "deg",
                 "_rad": "rad", "_ms": "ms", "_pa": "Pa"}


def unit_from_name(name: str) -> str | None:
    """A signal's unit from its name's suffix: ``speed_rpm`` r/min; ``v_mm_s`` mm/s (a rate:
    another unit before ``_s``; it was labelled s); None without a known suffix."""
    low = str(name).lower()
    for suffix, unit in UNIT_SUFFIXES.items():
        if low.endswith(suffix):
            if suffix == "_s":
                before = low[:-2]
                inner = next((u for k, u in UNIT_SUFFIXES.items() if k != "_s" and before.endswith(k)), None)
                if inner is not None:
                    return f"{inner}/s"
            return unit
    return None


def units_from_names(names) -> dict[str, str]:
    """``{name: unit}`` for the names whose suffix gives a unit (:func:`unit_from_name`)."""
    return {str(n): u for n in names if (u := unit_from_name(n)) is not None}
