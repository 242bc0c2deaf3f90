"""``hwpts plant ...``: steady states, sweeps and simulations of the simulated test bed."""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from hwpts.commands._args import (file_with_suffix, finite_float, grid, non_negative_float, non_negative_int,
                                  shown_path)
from hwpts.errors import ParameterError, SimulationError

INPUT_COLUMNS = ("time_s", "valve_voltage_v", "pump_speed_rpm")
"""Columns of an --inputs CSV for ``hwpts plant simulate``."""


def register(subparsers) -> None:
    """Add ``hwpts plant`` and its sub-commands."""
    plant = subparsers.add_parser(
        "plant", help="the simulated HWPTS test bed", description="The simulated hydraulic wind power transfer system."
    )
    sub = plant.add_subparsers(dest="plant_command", metavar="COMMAND", parser_class=type(plant))
    sub.required = True

    p = sub.add_parser(
        "steady-state",
        help="one steady operating point, as JSON",
        description="Steady state at one valve command and pump speed. Prints one JSON object "
        "(speeds in r/min, pressures in Pa).",
    )
    p.add_argument("--valve-voltage", type=finite_float, required=True, metavar="V", help="valve coil command [V]")
    p.add_argument("--pump-speed", type=non_negative_float, required=True, metavar="RPM", help="pump speed [r/min]")
    p.add_argument(
        "--branch", choices=("none", "up", "down"), default="none",
        help="none: averaged valve, no hysteresis; up/down: reached by increasing/decreasing voltage",
    )
    p.set_defaults(handler=steady_state_command, prints_result="plant steady-state")

    p = sub.add_parser(
        "sweep",
        help="up and down steady-state sweeps to CSV",
        description="Up and down steady-state sweeps of the valve command at every pump speed of a grid, "
        "and their average. Columns: valve_voltage_v, pump_speed_rpm, direction (up|down|average), "
        "motor_a_speed_rpm.",
    )
    p.add_argument("--out", type=file_with_suffix(".csv", ".parquet", stdout=True), required=True, metavar="FILE.csv", help="output table: .csv, .parquet, or - for CSV on standard output")
    p.add_argument("--voltages", type=grid, default=(1.2, 3.8, 27), metavar="START:STOP:N",
                   help="valve command grid [V] (default 1.2:3.8:27)")
    p.add_argument("--pump-speeds", type=grid, default=(200.0, 1000.0, 81), metavar="START:STOP:N",
                   help="pump speed grid [r/min] (default 200:1000:81)")
    p.set_defaults(handler=sweep_command)

    p = sub.add_parser(
        "simulate",
        help="simulate the test bed on a validation case or an inputs CSV",
        description="Simulate the test bed (hysteresis, droop, sensor noise). Output columns: time_s, "
        "valve_voltage_v, pump_speed_rpm (measured), motor_a_speed_rpm (measured), then the states.",
    )
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--case", choices=("case1", "case2", "case3", "case4"), help="one of the paper's validation cases")
    source.add_argument("--inputs", metavar="FILE.csv",
                        help="CSV with columns time_s, valve_voltage_v [V], pump_speed_rpm [r/min, the command]")
    p.add_argument("--out", type=file_with_suffix(".csv", ".parquet", stdout=True), required=True, metavar="FILE.csv", help="output table: .csv, .parquet, or - for CSV on standard output")
    p.add_argument("--noise-std", type=_noise_std, default=None, metavar="RPM",
                   help="speed sensor noise standard deviation [r/min] (default: the test bed's 2.0)")
    p.add_argument("--seed", type=non_negative_int, default=0, metavar="N", help="noise seed (default 0)")
    p.set_defaults(handler=simulate_command)


def _noise_std(text):
    from hwpts.plant.testbed import MAX_NOISE_STD_RPM

    value = non_negative_float(text)
    if value > MAX_NOISE_STD_RPM:
        raise argparse.ArgumentTypeError(f"expected r/min from 0 to {MAX_NOISE_STD_RPM:g}, got {text!r}")
    return value


def steady_state_command(args) -> int:
    """``hwpts plant steady-state``: print one steady operating point of the test bed as JSON."""
    from hwpts.plant import PlantParameters, steady_state
    from hwpts.plant.parameters import check_input_ranges

    check_input_ranges(args.valve_voltage, 0.0, where="--valve-voltage: ")  # the option named in the message
    check_input_ranges(0.0, args.pump_speed, where="--pump-speed: ")
    result = steady_state(PlantParameters.paper(), args.valve_voltage, args.pump_speed, branch=args.branch)
    print(json.dumps({
        "valve_voltage_v": args.valve_voltage,
        "pump_speed_rpm": args.pump_speed,
        "motor_a_speed_rpm": round(float(result.motor_a_speed_rpm), 4),
        "motor_b_speed_rpm": round(float(result.motor_b_speed_rpm), 4),
        "pump_pressure_pa": round(float(result.pump_pressure_pa), 2),
        "motor_a_pressure_pa": round(float(result.motor_a_pressure_pa), 2),
        "motor_b_pressure_pa": round(float(result.motor_b_pressure_pa), 2),
    }, indent=2))
    return 0


MAX_SWEEP_POINTS = 5_000_000  # operating points of one sweep (about 1.5 GiB of work arrays)


def sweep_command(args) -> int:
    """``hwpts plant sweep``: up and down steady-state sweeps of the valve command (paper Fig. 3) to a CSV file."""
    from hwpts.experiments.sweeps import sweep_columns
    from hwpts.io.datasets import is_stdout, write_table
    from hwpts.plant import PlantParameters, sweep

    points = int(args.voltages[2]) * int(args.pump_speeds[2])
    if points > MAX_SWEEP_POINTS:
        # about 40 float64 arrays per point (states, pressures, both sweeps, the CSV columns)
        raise ParameterError(
            f"--voltages x --pump-speeds: {points:,} operating points would need about "
            f"{points * 40 * 8 / 2**30:.0f} GiB; at most {MAX_SWEEP_POINTS:,} points are accepted"
        )
    voltages = np.linspace(*args.voltages)
    pumps = np.linspace(*args.pump_speeds)
    from hwpts.plant.parameters import check_input_ranges

    # the grid's ends, as typed (a grid point between them named a value the user never wrote)
    check_input_ranges(np.asarray(args.voltages[:2]), 0.0, where="--voltages: ")
    check_input_ranges(0.0, np.asarray(args.pump_speeds[:2]), where="--pump-speeds: ")
    result = sweep(PlantParameters.paper(), voltages, pumps)
    write_table(args.out, sweep_columns(result))
    gap_rpm = float(np.max(np.abs(result.up_rpm - result.down_rpm)))
    both = np.concatenate([result.up_rpm.ravel(), result.down_rpm.ravel()])
    if result.points_per_sweep < 2:
        gap = f"hysteresis gap {gap_rpm:.1f} r/min (one operating point: no full scale)"
    elif np.ptp(both) < 1.0:  # the pump at 0 r/min: 42.7 % of a full scale of a few thousandths
        gap = f"largest hysteresis gap {gap_rpm:.3g} r/min (the motor's speed spans {np.ptp(both):.3g} r/min: no full scale)"
    else:
        gap = f"largest hysteresis gap {np.max(np.abs(result.gap_percent)):.1f} % of full scale ({gap_rpm:.1f} r/min)"
    print(f"wrote {shown_path(args.out)}: {result.points_per_sweep} points per sweep (up, down, average); {gap}",
          file=sys.stderr if is_stdout(args.out) else sys.stdout)
    return 0


def simulate_command(args) -> int:
    """``hwpts plant simulate``: a transient of the test bed (a validation case or the user's inputs) to a CSV file."""
    from hwpts.errors import DataError
    from hwpts.io.datasets import is_stdout, read_table, write_table
    from hwpts.plant import TestBed, validation_case
    from hwpts.plant.testbed import DEFAULT_NOISE_STD_RPM

    bed = TestBed(noise_std_rpm=DEFAULT_NOISE_STD_RPM if args.noise_std is None else args.noise_std)
    if args.case:
        dataset, _ = bed.record(validation_case(args.case), seed=args.seed)
    else:
        try:
            columns = read_table(args.inputs)
        except DataError as error:
            raise DataError(f"--inputs: {error}") from None
        try:
            missing = [c for c in INPUT_COLUMNS if c not in columns]
            if missing:
                raise DataError(f"missing column(s) {missing}; available columns are {sorted(columns)}")
            dataset, _ = bed.run(columns["time_s"], columns["valve_voltage_v"], columns["pump_speed_rpm"],
                                 seed=args.seed, progress=True)
        except (DataError, SimulationError) as error:
            raise type(error)(f"--inputs {args.inputs!r}: {error}") from None
    write_table(args.out, dataset.columns())
    print(f"wrote {shown_path(args.out)}: {dataset.n_samples} samples, {dataset.time[-1] - dataset.time[0]:.2f} s",
          file=sys.stderr if is_stdout(args.out) else sys.stdout)
    return 0
