"""Closed-loop speed control of the HWPTS from an identified PWARX model bank.

wind (IEC 61400-1 Kaimal turbulence, the turbine), scenarios (set-point, pump and load steps,
turbulence, low wind) on the test bed with the induction generator option, controllers designed
from a PWARX model file, the sample-by-sample closed loop, and its metrics.
"""
