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
