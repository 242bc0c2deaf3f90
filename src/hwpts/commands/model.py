"""``hwpts identify | validate | predict``: PWARX models from data files (the command-line contract)."""

from __future__ import annotations

import math
import re
import sys
import time
import warnings

import numpy as np

from hwpts.commands._args import json_text, shown_path
from hwpts.errors import DataError, ParameterError, SimulationError
from hwpts.text import plain_int
from hwpts.units import UNIT_SUFFIXES, unit_from_name


def _int_list(text: str, name: str):
    """``"4"`` -> 4, ``"4,2"`` -> [4, 2] (one per input)."""
    try:
        values = [plain_int(v) for v in str(text).split(",")]
    except ValueError:
        raise ParameterError(f"--{name} expects an int or comma-separated ints (one per input), got {text!r}") from None
    return values[0] if len(values) == 1 else values


def _ridge(text: str) -> float:
    import argparse

    from hwpts.commands._args import non_negative_float
    from hwpts.identification.pwarx import MAX_RIDGE

    value = non_negative_float(text)
    if value > MAX_RIDGE:
        raise argparse.ArgumentTypeError(f"expected a number from 0 to {MAX_RIDGE:g}, got {text!r}")
    return value


def _output_powers(text: str):
    """``--output-powers``: ``"auto"`` (the search tries them), ``()`` for ``none``, or the powers given."""
    from hwpts.identification.regressors import MAX_POWER, check_output_powers

    text = str(text).strip()
    if text in ("auto", "none"):
        return "auto" if text == "auto" else ()
    try:
        return check_output_powers([plain_int(v) for v in text.split(",")])
    except (ValueError, ParameterError):
        raise ParameterError(f"--output-powers: expected 'auto', 'none' or distinct powers 2-{MAX_POWER} such as "
                             f"2,3; got {text!r}") from None


def _rows(text: str | None):
    if text is None:
        return slice(None)
    parts = str(text).split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        start = plain_int(parts[0]) if parts[0].strip() else None
        stop = plain_int(parts[1]) if parts[1].strip() else None
    except ValueError:
        raise ParameterError(f"--rows expects START:STOP (Python slice, e.g. 0:5000 or -1001:), got {text!r}") from None
    return slice(start, stop)


# conventional names of a time column in seconds, tried in this order when --time is not given
TIME_COLUMNS = ("time_s", "t_s", "time", "t")
# other names taken as the time column (in the file's order, after those) when it holds increasing
# numbers: time or time with a unit suffix in any case (Time, TIME_S, time_ms, Time_min, ...) and
# t_ms, t_us, t_ns. Not a T with a suffix (T_h: a temperature), t_min or t_h (a minimum, a height),
# nor timestamp (as often epoch milliseconds as seconds)
TIME_PATTERN = re.compile(r"(?i:time(_(s|ms|us|ns|min|h))?)|t_(s|ms|us|ns)")
NO_TIME = "none"  # --time none: no time column, the sample index is the time axis
# a .mat file's scalar variable that gives the sample period in seconds (as MATLAB's iddata Ts),
# tried in this order when the file has no time column and --time is not given
MAT_SAMPLE_TIMES = ("Ts", "dt", "sample_time", "sample_time_s")  # (not ts: a settling time as often)


def _available(path, found) -> str:
    """The file's columns for an error message (those read so far if the whole file cannot be read),
    with a hint when its first row holds numbers (no header row)."""
    from hwpts.io.datasets import is_number, read_table

    try:
        names = sorted(read_table(path))
    except (DataError, OSError, ValueError):
        names = sorted(found)
    text = f"available columns are {names}"
    if not names or all(is_number(n) for n in names):
        text += " (the first row must name the columns: a header row such as u,y)"
    return text


def _load_dataset(path, input_names, output_name, time_name=None, rows=None, uniform=True):
    """``(data, dt, hint)``: the named columns of a data file as an :class:`IODataset`, the sample
    period from the time column (None when the file has none: time = row index), and the clause that
    names a time column found by its name or type, for messages about the rate (else "").
    ``uniform``: a time column that is not uniform is refused (``None``: with ``--resample`` as the
    remedy), or ``False``: taken, with a sample period of ``nan`` (to be resampled).

    Without ``time_name`` the time column is the first of :data:`TIME_COLUMNS` the file holds (a
    numeric column; one that is not a signal), so that a model that knows its sample time is never
    applied silently to data sampled at another rate; ``time_name="none"`` uses the row index.
    """
    from hwpts.dataset import IODataset
    from hwpts.io.datasets import (column_names, csv_datetime_seconds, datetime_columns, numeric_share, read_table,
                                   temporal_columns)
    from hwpts.io.paths import check_input_file

    if not str(path).strip():
        raise ParameterError("DATA: expected a data file path, got an empty string")
    check_input_file(path, expected="a .csv, .parquet or .mat file")  # the file's own problem first
    for flag, given in (("--input", input_names), ("--output", [output_name])):
        if any(not str(name).strip() for name in given):
            raise ParameterError(f"{flag}: expected a column name, got an empty one")
    signals = [*input_names, output_name]
    names, temporal = column_names(path), temporal_columns(path)  # (a CSV's header, a Parquet schema: read once)
    dated = datetime_columns(path)  # (a CSV's first row, read once)
    typed = []
    if time_name == NO_TIME:
        candidates = []
    elif time_name is not None:
        candidates = [time_name]
    else:
        # (none from a .mat file, not read twice for its names: its time is a vector of the
        # conventional names or its Ts)
        others = [c for c in names if TIME_PATTERN.fullmatch(c) and c not in TIME_COLUMNS]
        candidates = [c for c in (*TIME_COLUMNS, *others) if c not in signals]
        # a Parquet file's one column typed as time, whatever its name (pandas writes a DataFrame's
        # time index as __index_level_0__ or under the index's name: 5 ms data were compared with a
        # 10 ms model without a word)
        typed = sorted(temporal - set(signals))
        if len(typed) == 1 and typed[0] not in candidates:
            candidates.append(typed[0])
    # a CSV time column of ISO 8601 date-times (a logger's wall clock), in seconds from its first stamp
    stamps = {c: v for c in candidates if c in dated and (v := csv_datetime_seconds(path, c)) is not None}
    numeric = [c for c in candidates if c not in stamps]
    if time_name not in (None, NO_TIME) and time_name not in stamps and time_name in dated:
        raise DataError(f"--time {time_name}: expected ISO 8601 date-times in every row, with one kind of time zone "
                        f"(all naive, or all with a zone or an offset), got a column of dates that does not read as "
                        f"time stamps (an empty cell, or zones mixed)")
    try:
        columns = read_table(path, [*signals, *numeric])
    except DataError:
        if time_name is not None or not numeric:
            raise
        readable = []
        for name in numeric:  # a conventionally named column that holds text is no time axis ...
            try:
                read_table(path, [*signals, name])
                readable.append(name)
            except DataError:
                if numeric_share(path, name) > 0.5:  # ... but one of numbers with mistyped cells is broken
                    raise
        columns = read_table(path, [*signals, *readable])  # (a bad signal column raises its own error here)
    columns.update(stamps)
    if time_name not in (None, NO_TIME) and time_name not in columns:
        raise DataError(f"{str(path)!r}: no time column {time_name!r}; {_available(path, columns)}")
    missing = [c for c in signals if c not in columns]
    if missing:
        from hwpts.io.datasets import mat_unread

        unread = mat_unread(path)
        if any(c in unread for c in missing):  # there, but not a signal
            c = next(c for c in missing if c in unread)
            raise DataError(f"{str(path)!r}: the variable {c!r} {unread[c]}; save each signal as a numeric "
                            f"vector; {_available(path, columns)}")
        skipped = "; ".join(f"{name!r} {reason}" for name, reason in list(unread.items())[:4])
        raise DataError(f"{str(path)!r}: no column(s) {missing}; {_available(path, columns)}"
                        + (f" (not read: {skipped}; save each signal as a numeric vector)" if skipped else ""))
    sl = _rows(rows)
    total = len(columns[output_name])
    for end in (sl.start, sl.stop):
        if end is not None and not -total <= end <= total:
            raise ParameterError(f"--rows '{rows}': {end} is beyond the file's {total} data rows "
                                 f"(rows 0 to {total - 1}, or -{total} to -1 from the end)")
    cols = {k: np.asarray(v)[sl] for k, v in columns.items()}
    n = len(cols[output_name])
    if n == 0:
        where = f"no rows selected (--rows {rows})" if rows is not None else "the file holds no data rows"
        raise DataError(f"{str(path)!r}: {where}")
    offset = range(total)[sl].start  # the file's data row of the selection's first (--rows counts from 0)
    for name in signals:
        bad = ~np.isfinite(np.asarray(cols[name], dtype=float))
        if bad.any():  # said in the file's rows (the dataset counts within the selection)
            raise DataError(f"{str(path)!r}: column {name!r} has a non-finite value (NaN, inf or an empty cell) at "
                            f"row {offset + int(np.argmax(bad))} (data rows count from 0 after the header, as --rows)")
    # a column of a name beyond the conventional ones is the time axis only where it increases
    # (T_h-like names aside, a time_min column of minima is no axis): else it is left alone; one
    # named by --time is the time axis, or refused (it was dropped, and the rate check with it)
    soft = [c for c in candidates if c in cols and c not in TIME_COLUMNS and time_name is None
            and not (np.all(np.isfinite(np.asarray(cols[c], dtype=float)))
                     and np.all(np.diff(np.asarray(cols[c], dtype=float)) > 0))]
    tname = next((c for c in candidates if c in cols and c not in soft), None)
    period = _mat_sample_time(path, columns) if time_name is None else None
    detected = time_name is None and tname is not None
    how = "its name" if tname in TIME_COLUMNS or TIME_PATTERN.fullmatch(str(tname)) else "its type"
    hint = f" ({tname!r} is taken as the time column by {how}; --time none uses the sample index)" if detected else ""
    timed = tname is not None
    if timed and time_seconds(tname) != 1.0 and tname not in temporal and tname not in stamps:
        # a column of numbers named in ms (time_ms), minutes, ...; a typed Parquet time is in seconds already
        cols[tname] = np.asarray(cols[tname], dtype=float) * time_seconds(tname)
    if tname is None and time_name is None and period is None:
        _warn_unused_time(path, names, typed, signals, dated)
    if tname is None:
        # time = sample index of the file (keeps the original numbering under --rows), in seconds
        # when a .mat file gives its sample period
        cols["__index__"] = np.arange(len(columns[output_name]), dtype=float)[sl] * (period[1] if period else 1.0)
        tname = "__index__"
    try:
        data = IODataset.from_columns(cols, list(input_names), output_name, time_name=tname)
    except DataError as error:  # the hint where the time column is what the error is about
        about_time = str(error).startswith("time ") or repr(tname) in str(error) or "'time'" in str(error)
        raise DataError(f"{str(path)!r}: {error}{hint if about_time else ''}") from None
    remedy = "resample the data, or split the record at the gap"
    if uniform is None:  # a command that resamples when asked: say so
        remedy += ", or pass --resample to interpolate it onto the model's rate"
    try:
        dt = _sample_time(data, path, tname, remedy) if timed else None
    except DataError as error:  # (the only one: a time axis that is not uniform)
        if uniform is not False:
            raise DataError(f"{error}{hint}") from None
        dt = math.nan  # jitter or gaps: a time axis all the same, to be resampled (--resample)
    from hwpts.identification.pwarx import MIN_SAMPLE_TIME

    if dt is not None and dt < MIN_SAMPLE_TIME:  # (said by the model's fit, naming neither the file nor the column)
        raise DataError(f"{str(path)!r}: the time column {tname!r} steps by {dt:.3g} s, expected a sample time of "
                        f"at least {MIN_SAMPLE_TIME:g} s (as a model file holds it); give the time in seconds"
                        + (hint or ", or pass --time none to use the sample index"))
    if period is not None:
        name, value = period
        if dt is None:
            dt = value
        elif abs(dt - value) > SAMPLE_TIME_TOLERANCE * value:
            raise DataError(f"{str(path)!r}: the time column {tname!r} is sampled every {dt:.6g} s but the variable "
                            f"{name!r} says {value:.6g} s; correct one of them, or pass --time none or --time COL")
    return data, dt, hint


def _warn_unused_time(path, names, typed, signals, dated) -> None:
    """Say where a file holds time stamps that were not taken as its time axis (so that the rate check
    was skipped): several Parquet columns typed as time, or a CSV column of ISO dates that is not named
    as a time column or does not read as time stamps (an empty cell, mixed time zones); ``dated``:
    the CSV columns of dates (:func:`hwpts.io.datasets.datetime_columns`)."""
    import warnings

    if len(typed) > 1:
        columns, which = typed, "the one that is the time axis"
    else:
        columns = [c for c in names if c not in signals and c in dated]
        which = "a column of ISO 8601 date-times with no empty cell and one kind of time zone"
    if columns:
        warnings.warn(f"{str(path)!r}: {', '.join(map(repr, columns[:3]))} hold{'s' if len(columns) == 1 else ''} "
                      f"time stamps but no time axis was taken from them, so the sample time is not checked; pass "
                      f"--time COL ({which})", stacklevel=2)


def _mat_sample_time(path, columns) -> tuple[str, float] | None:
    """``(name, seconds)`` of a .mat file's scalar sample-period variable (:data:`MAT_SAMPLE_TIMES`),
    or None; a scalar of that name that is not a positive finite number is refused."""
    from pathlib import Path

    if Path(path).suffix.lower() != ".mat":
        return None
    from hwpts.io.datasets import mat_unread

    unread = None
    for name in MAT_SAMPLE_TIMES:
        value = columns.get(name)
        if value is None:
            unread = mat_unread(path) if unread is None else unread
            if name in unread:  # text, or no vector: said, not passed over (the rate check with it)
                raise DataError(f"{str(path)!r}: the variable {name!r} is taken as the sample time in seconds; "
                                f"expected a positive number, but it {unread[name]} (pass --time COL for a time "
                                f"column, or --time none for the sample index)")
            continue
        if np.size(value) != 1:  # a signal of that name (a vector 'dt'), not a sample time
            if any(other != name and np.size(v) == np.size(value) for other, v in columns.items()):
                continue
            # as long as no signal: not one, and no sample time either (it was passed over: the
            # model's sample_time_s null where the file meant Ts)
            raise DataError(f"{str(path)!r}: the variable {name!r} is taken as the sample time in seconds; expected "
                            f"a positive number, got {np.size(value)} values (as long as no signal of the file; pass "
                            f"--time COL for a time column, or --time none for the sample index)")
        value = float(np.asarray(value, dtype=float).reshape(-1)[0])
        if not (np.isfinite(value) and value > 0):
            raise DataError(f"{str(path)!r}: the variable {name!r} is taken as the sample time in seconds; expected "
                            f"a positive number, got {value:g} (pass --time COL for a time column, or --time none for "
                            f"the sample index)")
        return name, value
    return None


def _selection(args, name: str) -> str:
    """The data file's name for a message, with the ``--rows`` selection when one was given."""
    return name + (f" (--rows {args.rows})" if args.rows else "")


def _sample_time(data, path, tname, remedy: str) -> float | None:
    """The data's sample period [s] from its time column; a non-uniform time axis is refused
    (saying ``remedy``)."""
    return data.uniform_sample_time(f"{str(path)!r}: the time column {tname!r}", remedy)


SAMPLE_TIME_TOLERANCE = 0.01  # relative difference of sample times treated as equal


MAX_RESAMPLED = 20_000_000  # samples a resampled record may have (160 MB per signal)


def _resampled(data, dt, model_dt):
    """``data`` linearly interpolated onto the model's sample time (``--resample``)."""
    from hwpts.dataset import IODataset

    with np.errstate(over="ignore"):  # a model sample time of 1e-310 s: inf samples, said below
        count = (data.time[-1] - data.time[0]) / model_dt + 1
    if not count <= MAX_RESAMPLED:
        raise DataError(f"--resample: the record spans {data.time[-1] - data.time[0]:.6g} s, {count:.3g} samples at the "
                        f"model's {model_dt:.6g} s (at most {MAX_RESAMPLED:.0e}); is the time column in seconds?")
    steps = np.diff(data.time)
    if steps.size:
        widest = int(np.argmax(steps))
        typical = max(float(np.median(steps)), model_dt)
        if steps[widest] > 2.5 * typical:  # a gap, not jitter: a straight line would stand for the data there
            raise DataError(f"--resample: the time column has a gap of {steps[widest]:.6g} s at row {widest + 1} (the "
                            f"samples are {np.median(steps):.6g} s apart): interpolation would invent the data "
                            f"there; split the record at the gap (--rows)")
    t = np.arange(data.time[0], data.time[-1] + 0.5 * model_dt, model_dt)
    t = t[t <= data.time[-1] + 1e-12 * abs(data.time[-1])]
    inputs = np.column_stack([np.interp(t, data.time, data.inputs[:, j]) for j in range(data.inputs.shape[1])])
    return IODataset(t, inputs, np.interp(t, data.time, data.output), data.input_names, data.output_name)


def _check_sample_time(model, data, dt, path, resample: bool):
    """Refuse data sampled at another rate than the model's (or resample them when asked)."""
    model_dt = getattr(model, "sample_time_", None)
    if model_dt is None or dt is None:
        if resample:
            raise ParameterError("--resample needs a time column in DATA and a model that knows its sample time")
        if model_dt is not None:
            # no time column: the samples are taken at the model's rate (their time in seconds, not
            # the sample numbers labelled as seconds in the written time_s column and the plots)
            from hwpts.dataset import IODataset

            return IODataset(data.time * model_dt, data.inputs, data.output, data.input_names, data.output_name,
                             extra=data.extra)
        return data
    if resample and math.isnan(dt):  # a time axis with jitter or gaps: onto the model's uniform grid
        return _resampled(data, dt, model_dt)
    if abs(dt - model_dt) <= SAMPLE_TIME_TOLERANCE * model_dt:
        return data
    if resample:
        return _resampled(data, dt, model_dt)
    raise DataError(f"{str(path)!r}: sample time {dt:.6g} s ({1 / dt:.6g} Hz) differs from the model's "
                    f"{model_dt:.6g} s ({1 / model_dt:.6g} Hz): its lags would mean other delays; resample the "
                    f"data (--resample interpolates linearly) or refit")


# units recognised from a column name's suffix (the plant's and the paper's naming: speed_rpm, ...)
# a time column's unit by its suffix, in seconds (a name without one is in seconds)
TIME_SUFFIXES = {"_ms": 1e-3, "_us": 1e-6, "_ns": 1e-9, "_min": 60.0, "_h": 3600.0}


def time_seconds(name: str) -> float:
    """Seconds per unit of a time column named ``name``: ``time_ms`` is in milliseconds."""
    low = str(name).lower()
    return next((v for k, v in TIME_SUFFIXES.items() if low.endswith(k)), 1.0)


def _units(names, given) -> dict:
    """Units of the named signals: ``--unit NAME=UNIT`` (once a signal, and agreeing with a unit
    its name's suffix says), else from the name's suffix."""
    units, told = {}, {}
    for name in names:
        unit = unit_from_name(name)
        if unit is not None:
            units[name] = unit
    for text in given or ():
        name, sep, unit = str(text).partition("=")
        if not sep or not name.strip() or not unit.strip():
            raise ParameterError(f"--unit expects NAME=UNIT (e.g. y=mm), got {text!r}")
        name, unit = name.strip(), unit.strip()
        if name not in names:
            raise ParameterError(f"--unit {text!r}: {name!r} is not one of the signals {list(names)}")
        if name in told:
            raise ParameterError(f"--unit {text!r}: {name!r} was given the unit {told[name]!r} already; "
                                 f"expected one --unit per signal")
        said = unit_from_name(name)
        known = {*UNIT_SUFFIXES.values(), *(f"{u}/s" for u in UNIT_SUFFIXES.values())}
        if said is not None and unit in known and said != unit:  # as validate refuses a column named in another
            # unit; free text ("rpm") is not compared
            raise ParameterError(f"--unit {text!r}: the column's name says its unit is {said!r}; expected "
                                 f"{said!r} (or no --unit for it), got {unit!r}")
        told[name] = units[name] = unit
    return units


def _fit_summary(model, data, path, out, elapsed, search=None, delays=None):
    from hwpts.identification.metrics import fit_percent, rmse
    from hwpts.identification.selection.search import FREE_RUN_FLOOR

    m = model.structure_.max_lag
    sim = model.simulate(data.inputs, data.output)
    one = model.predict(data.inputs, data.output)
    y = data.output[m:]
    summary = {"model": str(out), "data": str(path), "n_samples": data.n_samples}
    summary.update(model.summary())
    summary["sample_time_s"] = getattr(model, "sample_time_", None)
    summary["units"] = dict(getattr(model, "units_", {}) or {})
    summary["train_fit_percent"] = None if sim.diverged else round(fit_percent(y, sim.output[m:]), 3)
    summary["train_one_step_fit_percent"] = round(fit_percent(y, one[m:]), 3)
    summary["train_rmse"] = None if sim.diverged else rmse(y, sim.output[m:])
    if sim.diverged:
        summary["diverged"] = True
        summary["reason"] = sim.reason
    if search is not None:
        table = search.candidate_table()
        summary["choice"] = {
            "na": model.structure_.na, "nb": list(model.structure_.nb), "nk": list(model.structure_.nk),
            "segmentation": summary["segmentation"], "n_regions": int(model.n_regions_),
            "polished": summary["polished"], "heldout_fit_percent": round(search.best_score_, 3),
            "n_candidates": len(table), "n_blocks": search.n_splits_,
            "scoring": search.scoring_.replace("_", "-"),
            "shared_modes": _modes_gate_summary(search),
            "orders": _orders_summary(search),
            "input_delays": _delays_summary(delays),
            "output_powers": _powers_summary(search, model),
            "why": (f"best mean {'one-step' if search.scoring_ == 'one_step' else 'free-run'} fit over "
                    f"{search.n_splits_} held-out blocks of the training data "
                    f"({len(table)} candidates; "
                    + (f"chosen among those with the {search.n_regions} region(s) asked for: the fewest parameters"
                       if _fixed_count(search) else "the fewest regions, then the fewest parameters,")
                    + f" win unless the best beats them by more than {search.tolerance} points and {search.n_standard_errors:g} "
                    f"standard error(s) of the block differences"
                    + ("" if search.scoring_ == "one_step" else
                       "; a smaller one that predicts one step ahead better than the best by more than the best's free run gains stays")
                    + ")"
                    + (f"; ranked by the one-step fit because no ARX model's held-out free run reached "
                       f"{FREE_RUN_FLOOR:g} % fit" if search.scoring == "auto" and search.scoring_ == "one_step" else "")),
        }
        summary["candidates"] = table
    summary["fit_time_s"] = round(elapsed, 3)
    return summary


def _fixed_count(search) -> bool:
    """Whether the search was told the number of regions (``--regions S``; never with a grid)."""
    return search.n_regions != "auto"


def _powers_summary(search, model):
    """The summary's account of the output power terms: tried by the search or not, and chosen."""
    chosen = list(model.structure_.output_powers)
    rows = [r for r in search.cv_results_ if r.get("stage") == "powers"]
    if not rows:
        why = ("given (--output-powers)" if chosen else
               "not tried (--output-powers none, a grid searched, or no output lag in the model)")
        return {"tried": False, "chosen": chosen, "why": why}
    powers = list(rows[0]["params"]["output_powers"])
    why = (f"the ARX model of the orders of the model chosen so far was scored with the terms ((y(k-1)-c)/s)^p, "
           f"p in {powers}, on the same held-out blocks"
           + (", and so was that model, the ARX model being raced to the end" if len(rows) > 1 else
              " and pruned or diverged, so the regions were not tried with them"
              if rows[0]["mean_fit_percent"] is None else "")
           + ("; they won the choice" if chosen else "; they did not win the choice"))
    return {"tried": True, "powers": powers, "chosen": chosen,
            "heldout_fits_percent": [None if r["mean_fit_percent"] is None else round(r["mean_fit_percent"], 3)
                                     for r in rows], "why": why}


def _delays_summary(delays):
    """The summary's account of the input delays searched (``None`` when ``--nk`` was given)."""
    from hwpts.identification.selection.orders import DELAY_CHANCE, DELAY_TOLERANCE, MAX_DELAY, delay_candidates

    if delays is None:
        return None
    tried = delay_candidates(delays)
    why = (f"delays {tried} tried: an ARX model with each delay from 0 up to {MAX_DELAY} (or a tenth of the "
           f"record; as MATLAB's delayest) "
           + ("found none above 1 that cut the loss of delays 0 and 1 by the larger of "
              f"{100 * DELAY_TOLERANCE:g} % and {DELAY_CHANCE:g} / rows" if max(delays) <= 1
              else "found the dead time " + str(list(delays))))
    return {"estimated": list(delays), "tried": tried, "why": why}


def _orders_summary(search):
    """The summary's account of how the orders carried to the region stage were ranked (``None``
    when the orders were given)."""
    from hwpts.identification.selection.search import NEIGHBOUR_GATE

    info = getattr(search, "orders_ranking_", None)
    if not info:
        return None
    arx, nn = info["arx_one_step_percent"], info["neighbour_one_step_percent"]
    if info["ranked_by"] == "neighbours":
        why = (f"a nearest-neighbour predictor's held-out one-step fit ({nn:.1f} %) beat every ARX model's "
               f"({arx:.1f} %) by more than {NEIGHBOUR_GATE:g} points: no ARX model explains the data, so the "
               f"orders the neighbours predict best with were tried beside the ARX models' best")
    elif nn is None:
        why = f"the orders of the best ARX models (held-out one-step fit {arx:.1f} %) were tried"
    else:
        why = (f"the orders of the best ARX models were tried (held-out one-step fit {arx:.1f} %; a "
               f"nearest-neighbour predictor's {nn:.1f} % was not {NEIGHBOUR_GATE:g} points better)")
    simplest = info.get("parsimonious")
    if simplest:
        short = {"output_order": "na", "input_order": "nb", "input_delay": "nk"}
        said = ", ".join(f"{short.get(k, k)} {v}" for k, v in simplest.items())
        why += (f"; {said} was tried second: the fewest parameters among the ARX models the best one does "
                f"not beat by the choice's rule")
    return {**info, "why": why}


def _modes_gate_summary(search):
    """The summary's account of the shared-modes stage: whether it ran and why."""
    gate = getattr(search, "modes_gate_", None)
    ran = any(r.get("stage") == "modes" for r in search.cv_results_)
    if gate is None:
        return {"tried": ran, "why": "not asked for" if search.shared_modes is False else "not reached"}
    fits = {str(k): round(float(v), 3) for k, v in gate["switched_fits_percent"].items()}
    best = gate["best_one_step"]
    return {"tried": ran, "gate_open": bool(gate["open"]), "from_modes": gate["modes"],
            "switched_in_sample_fits_percent": fits,
            "best_heldout_one_step_fit_percent": round(float(best), 3) if np.isfinite(best) else None}


def _orders_to_search(args):
    """The estimator's orders and the order grid of the search: the orders not given are searched
    (``--nk`` defaults to 1 when ``--na`` and ``--nb`` are both given, as before)."""
    from hwpts.identification.selection import ORDER_GRID

    given = {"output_order": args.na,
             "input_order": None if args.nb is None else _int_list(args.nb, "nb"),
             "input_delay": None if args.nk is None else _int_list(args.nk, "nk")}
    if given["output_order"] is not None and given["input_order"] is not None and given["input_delay"] is None:
        given["input_delay"] = 1
    for key, flag in (("output_order", "--na"), ("input_order", "--nb"), ("input_delay", "--nk")):
        values = given[key] if isinstance(given[key], list) else [given[key]]
        if given[key] is not None and any(v < 0 for v in values):
            raise ParameterError(f"{flag} expects ints >= 0, got {given[key]!r}")
        if isinstance(given[key], list) and len(given[key]) not in (1, len(args.input)):
            raise ParameterError(f"{flag} expects one value or one per input ({len(args.input)}: "
                                 f"{','.join(args.input)}), got {len(given[key])}: {','.join(map(str, given[key]))}")
    searched = {k: list(ORDER_GRID[k]) for k, v in given.items() if v is None}
    fixed = {k: v for k, v in given.items() if v is not None}
    return fixed, searched


def _check_fixed_lags(fixed, searched, n_samples, name, n_inputs=1) -> None:
    """Orders given (``--na``...) whose lags leave the record too short for the model search that
    chooses the others (2 held-out blocks of the lags plus MIN_BLOCK samples), or whose smallest
    candidate has more parameters than the training part of the search's cross-validation has
    samples (every candidate failed: ``--na 90 --nb 90`` on 300 rows), are said as those options
    (the search's message asked for the settings the user had given)."""
    from hwpts.identification import PWARX, PWARXSearch
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.selection.search import MIN_BLOCK, ORDER_GRID, expand_grid

    def largest_lag(grid):  # as the search finds it (PWARXSearch.fit: the largest over its order grid)
        return max(PWARXSearch._max_lag(PWARX(), orders) for orders in expand_grid(grid))

    flags = {"output_order": "--na", "input_order": "--nb", "input_delay": "--nk"}
    given = " ".join(f"{flags[k]} {','.join(str(v) for v in np.atleast_1d(fixed[k]))}" for k in ORDER_GRID if k in fixed)
    lag = largest_lag({k: [fixed[k]] if k in fixed else list(searched[k]) for k in ORDER_GRID})
    if n_samples // (MIN_BLOCK + lag) >= 2:
        smallest = {k: fixed[k] if k in fixed else min(searched[k]) for k in ORDER_GRID}
        structure = RegressorStructure.create(smallest["output_order"], smallest["input_order"],
                                              smallest["input_delay"], n_inputs, True)
        rows = PWARXSearch(PWARX()).n_regressor_rows(n_samples, lag, structure.max_lag)
        if rows < structure.n_parameters + 1:  # PWARX.fit's own limit at the breaks
            raise ParameterError(f"{given}: expected orders whose model can be fitted in the search's cross-"
                                 f"validation on the {n_samples} samples of {name} (each candidate is fitted "
                                 f"without a held-out block, each stretch after its {structure.max_lag} initial "
                                 f"conditions: {max(rows, 0)} regressor rows), got orders whose smallest candidate "
                                 f"({structure.describe_orders()}) has {structure.n_parameters} parameters and needs "
                                 f"{structure.n_parameters + 1} rows; give smaller orders, or every order")
        return
    if n_samples // (MIN_BLOCK + largest_lag({k: list(searched.get(k, ORDER_GRID[k])) for k in ORDER_GRID})) < 2:
        return  # too short whatever the orders: the search says so
    raise ParameterError(f"{given}: expected orders whose largest lag is at most {n_samples // 2 - MIN_BLOCK} for the "
                         f"{n_samples} samples of {name} (the search that chooses the other orders holds out 2 "
                         f"blocks of the lags + {MIN_BLOCK} samples and fits each candidate on the rest), got a "
                         f"largest lag of {lag}; give smaller orders, or every order")


def _check_region_count(n_regions, n_samples, fixed, searched, n_inputs, searching, powers=()) -> None:
    """``--regions S`` leaves every region ``ROWS_PER_PARAMETER`` rows a parameter of the smallest
    candidate model (the orders given, else the smallest of the search's grid), in the rows each
    candidate is fitted on (``searching``: the training part of the search's cross-validation): the
    model search's own limit when it grows the regions (fewer leave a local model barely
    determined, and a learned segmentation then drops regions that received no row: `--regions 50`
    on 300 rows gave a 2-region model and exit 0)."""
    import itertools

    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.selection import PWARXSearch
    from hwpts.identification.selection.search import ROWS_PER_PARAMETER

    if not isinstance(n_regions, int) or n_regions < 2:
        return
    grid = [[fixed[k]] if k in fixed else list(searched.get(k, [])) for k in ("output_order", "input_order",
                                                                             "input_delay")]
    best = None
    for na, nb, nk in itertools.product(*grid):
        try:
            st = RegressorStructure.create(na, nb, nk, n_inputs, True, output_powers=powers)
        except ParameterError:
            continue  # e.g. na = 0 with nb = 0: refused where the model is built, with its own message
        rows = PWARXSearch().n_training_rows(n_samples, st.max_lag) if searching else n_samples
        limit = (rows - st.max_lag) // (ROWS_PER_PARAMETER * st.n_parameters)
        if best is None or limit > best[0]:
            best = (limit, st, rows)
    if best is None:
        return
    limit, st, rows = best
    p = st.n_parameters
    if n_regions > limit:
        where = (f"the {rows} training samples of each cross-validation split of {n_samples}" if searching
                 else f"{n_samples} samples")
        raise ParameterError(
            f"--regions {n_regions}: expected at most {max(limit, 1)} for {where} ({ROWS_PER_PARAMETER} rows a "
            f"parameter, {p} parameters a region with {st.describe_orders()}), got {n_regions}")


def _check_signals(inputs, output) -> None:
    """Each signal once, and the output not among the inputs (a model of y from y(k) is no model)."""
    seen = set()
    for name in inputs:
        if name in seen:
            raise ParameterError(f"--input {name!r} is given twice; name each input column once")
        seen.add(name)
    if output in seen:
        raise ParameterError(f"--output {output!r} is also an --input: the output cannot be one of the model's "
                             f"inputs (it would predict y(k) from y(k) itself)")


def _check_partition_columns(args, fixed, searched, powers=()) -> None:
    """Every ``--partition-column`` names a regressor column of some candidate structure (the
    largest orders of the search, each delay), so a misspelt name fails at once and names the flag."""
    if not args.partition_column:
        return
    twice = next((c for i, c in enumerate(args.partition_column) if c in args.partition_column[:i]), None)
    if twice is not None:  # (stored twice, while --input u --input u is refused)
        raise ParameterError(f"--partition-column {twice!r} is given twice; give each column once")
    names = _candidate_columns(args, fixed, searched, powers)
    valid = {*names, *args.input, args.output}
    for name in args.partition_column:
        if name not in valid:
            raise ParameterError(f"--partition-column {name!r} is not a regressor column; valid names are "
                                 f"{names} or the signals {[*args.input, args.output]}")


def _check_hyperplanes(args, hyperplanes, fixed, searched, powers=()) -> None:
    """Every ``--hyperplane`` fits some candidate structure: by position, at most one coefficient
    an input; by name (``@col1,col2``), regressor columns of the largest orders of the search. Said
    at once and as the option: inside the search every candidate failed with a message of the
    cross-validation's folds."""
    names = None
    for text, plane in zip(args.hyperplane, hyperplanes):
        if plane.columns is None:
            if len(plane.coefficients) > len(args.input):
                raise ParameterError(f"--hyperplane {text}: expected at most {len(args.input)} coefficient"
                                     f"{'s' if len(args.input) > 1 else ''} and the offset (by position, the "
                                     f"coefficients are of the inputs {args.input}; name other regressor columns "
                                     f"with '@col1,col2'), got {len(plane.coefficients)} coefficients")
            continue
        names = names if names is not None else _candidate_columns(args, fixed, searched, powers)
        missing = [c for c in plane.columns if c not in {*names, *args.input, args.output}]
        if missing:
            raise ParameterError(f"--hyperplane {text}: expected regressor columns after '@' ({names}) or the "
                                 f"signals {[*args.input, args.output]}, got {', '.join(map(repr, missing))}")


def _candidate_columns(args, fixed, searched, powers=()) -> list:
    """The regressor columns of the search's candidate structures (the largest orders, each delay)."""
    from hwpts.identification.regressors import RegressorStructure

    na = fixed.get("output_order", max(searched.get("output_order", [0])))
    nb = fixed.get("input_order", max(searched.get("input_order", [1])))
    delays = [fixed["input_delay"]] if "input_delay" in fixed else list(searched.get("input_delay", [1]))
    names = []
    for nk in delays:
        structure = RegressorStructure.create(na, nb, nk, len(args.input), True, args.input, args.output,
                                              powers if na >= 1 else ())
        names += [name for name in structure.feature_names if name not in names]
    return names


def cmd_identify(args) -> int:
    """``hwpts identify``: fit a PWARX model (what is not given is chosen by :class:`PWARXSearch`), write it, print a JSON summary."""
    from hwpts.identification import PWARX, PWARXSearch
    from hwpts.identification.partition import Hyperplane
    from hwpts.identification.regressors import RegressorStructure
    from hwpts.identification.selection import DEFAULT_METHODS
    from hwpts.identification.segmentation import SEGMENTATION_METHODS
    from hwpts.identification.selection.search import METHOD_PARAMS
    from hwpts.io.models import save_model

    _check_signals(args.input, args.output)
    powers = _output_powers(args.output_powers)
    given_powers = () if powers == "auto" else powers  # the model's own; "auto" leaves them to the search
    fixed, searched = _orders_to_search(args)
    if given_powers and fixed.get("output_order") == 0:
        raise ParameterError(f"--output-powers {args.output_powers}: the power terms are of y(k-1), which --na 0 "
                             f"leaves out of the regressor; give --na >= 1 or --output-powers none")
    count = getattr(SEGMENTATION_METHODS.get(args.segmentation), "fixed_regions", None)
    if count is not None and args.regions != "auto" and str(args.regions).strip() != str(count):
        # a method that makes its own regions: --regions must agree or be left out
        raise ParameterError(f"--regions {args.regions}: --segmentation {args.segmentation} makes {count} "
                             f"region{'s' if count > 1 else ''}; leave --regions out or choose another method")
    data, dt, _ = _load_dataset(args.data, args.input, args.output, args.time, args.rows)
    units = _units([*args.input, args.output], args.unit)
    delays = None
    if "input_delay" in searched:  # the delays 0 and 1 of the grid, or the dead time the data show
        from hwpts.identification.selection.orders import delay_candidates, estimate_delays

        delays = estimate_delays(data.inputs, data.output)
        searched["input_delay"] = delay_candidates(delays)
    # after the delays: "u(k-5)" names a column then; a power term is a column when --output-powers gives it
    _check_partition_columns(args, fixed, searched, given_powers)
    if not searched:
        structure = RegressorStructure.create(fixed["output_order"], fixed["input_order"], fixed["input_delay"],
                                              len(args.input), True, args.input, args.output,
                                              given_powers)
        structure.check_length(data.n_samples, what=_selection(args, repr(str(args.data))))
    hyperplanes = [Hyperplane.parse(h) for h in args.hyperplane]
    _check_hyperplanes(args, hyperplanes, fixed, searched, given_powers)
    segmentation = args.segmentation
    if hyperplanes and segmentation is None:
        segmentation = "hyperplane"
    segmentation = segmentation or "auto"
    if segmentation == "hyperplane" and not hyperplanes:
        raise ParameterError("--segmentation hyperplane needs at least one --hyperplane \"a,b,c\"")
    if hyperplanes and segmentation != "hyperplane":
        raise ParameterError(f"--hyperplane needs --segmentation hyperplane, not {segmentation!r}")
    if hyperplanes and args.regions != "auto" and str(args.regions).strip() != str(len(hyperplanes) + 1):
        raise ParameterError(f"--regions {args.regions}: {len(hyperplanes)} --hyperplane make {len(hyperplanes) + 1} "
                             f"regions (a decision list); leave --regions out")
    regions = args.regions
    if regions == "auto":
        n_regions = "auto"
    else:
        try:
            n_regions = plain_int(regions)
        except ValueError:
            raise ParameterError(f"--regions expects an int >= 1 or 'auto', got {regions!r}") from None
        if n_regions < 1:
            raise ParameterError(f"--regions expects an int >= 1, got {n_regions}")
    share = getattr(SEGMENTATION_METHODS[segmentation](), "min_share", None) if segmentation in SEGMENTATION_METHODS \
        else None  # a method whose split leaves each region a share of the rows (threshold's)
    if share is not None and isinstance(n_regions, int) and n_regions > int(np.ceil(1 / share)) - 1:
        # the split's own limit (each region at least min_share of the rows), said as --regions
        raise ParameterError(f"--regions {n_regions}: expected at most {int(np.ceil(1 / share)) - 1} for "
                             f"--segmentation {segmentation} (a threshold split leaves each region at least "
                             f"{100 * share:g} % of the rows), got {n_regions}")
    # a given partition (the user's hyperplanes, average's one region, zscore's rule): neither
    # learned nor drawn on the data, so no count to check against the rows and no method to choose
    fixed_partition = segmentation in SEGMENTATION_METHODS and SEGMENTATION_METHODS[segmentation].given_partition()
    method = SEGMENTATION_METHODS.get(segmentation)
    if method is not None and not method.takes_partition_columns() and args.partition_column:  # (it was ignored)
        raise ParameterError(f"--partition-column restricts the boundaries a segmentation learns; --segmentation "
                             f"{segmentation} has a given partition (leave one of them out)")
    if args.all_partition_columns and method is not None and method.returns_partition:  # (it was ignored)
        raise ParameterError(f"--all-partition-columns keeps every regressor column in a learned classifier's "
                             f"boundaries; --segmentation {segmentation} makes its partition without one (leave one "
                             f"of them out)")
    if args.shared_modes == "on" and segmentation != "auto":  # (it was ignored)
        raise ParameterError(f"--shared-modes on: the search tries the switched segmentation beside its methods; "
                             f"--segmentation {segmentation} fixes the method (leave one of them out)")
    will_search = bool(searched) or (segmentation == "auto" and n_regions != 1) or (n_regions == "auto"
                                                                                   and not fixed_partition)
    if not fixed_partition and will_search and fixed:
        # (a fixed partition's grid search splits by the given orders' lags alone)
        _check_fixed_lags(fixed, searched, data.n_samples, _selection(args, repr(str(args.data))), len(args.input))
    if not fixed_partition:
        _check_region_count(n_regions, data.n_samples, fixed, searched, len(args.input),
                            searching=bool(searched) or segmentation == "auto",
                            powers=given_powers)
    region_models = None
    if args.zero_region:
        low = min(args.zero_region)
        if low < 1:  # said before what the count needs: regions are numbered from 1 whatever it is
            raise ParameterError(f"--zero-region: expected a region number >= 1 (regions are numbered from 1), "
                                 f"got {low}")
        own = getattr(SEGMENTATION_METHODS.get(segmentation), "fixed_regions", None)  # zscore's 2
        n_hyper = len(hyperplanes) + 1 if segmentation == "hyperplane" else own if own is not None else n_regions
        if n_hyper == 1:
            raise ParameterError("--zero-region: a model of one region as the zero mode y = 0 leaves nothing to "
                                 "fit; give --regions 2 or more")
        if not isinstance(n_hyper, int):
            raise ParameterError("--zero-region needs a fixed number of regions (--regions S or hyperplanes)")
        region_models = ["affine"] * n_hyper
        for r in args.zero_region:
            if not 1 <= r <= n_hyper:
                raise ParameterError(f"--zero-region {r}: regions are numbered 1..{n_hyper}")
            region_models[r - 1] = "zero"
        if all(kind == "zero" for kind in region_models):  # a model y = 0 everywhere: nothing is fitted
            raise ParameterError(f"--zero-region: expected at most {n_hyper - 1} of the {n_hyper} regions as the "
                                 f"zero mode y = 0 (every one leaves nothing to fit), got {len(set(args.zero_region))}")
    model = PWARX(
        **{"output_order": 1, "input_order": 1, "input_delay": 1, **fixed},
        n_regions=n_regions if isinstance(n_regions, int) else 2,
        segmentation=segmentation if segmentation != "auto" else "clustering",
        hyperplanes=hyperplanes or None, region_models=region_models,
        ridge=args.ridge, polish=args.polish, random_state=args.seed,
        partition_columns=args.partition_column or None, sparse_partition=not args.all_partition_columns,
        output_powers=given_powers,
    )
    search = None
    # the search scores the winner with the polish too, unless --polish already polishes every candidate
    try_polish = "auto" if not args.polish else False
    if segmentation == "auto" and n_regions == 1:  # one region: a single ARX model, no method to choose
        model.set_params(segmentation="average")
        if searched:
            search = PWARXSearch(model, param_grid=dict(searched), progress=True,
                                 try_polish=try_polish)
    elif region_models is not None and isinstance(n_regions, int) and (searched or segmentation == "auto"):
        # --zero-region: every candidate has the S regions the zero modes are numbered in (the
        # adaptive search's ARX models have one), so a grid at that count: each default method, or
        # the one given, with the orders left open
        chosen = DEFAULT_METHODS if segmentation == "auto" else (segmentation,)
        grid = [{**searched, "segmentation": [m], "n_regions": [n_regions],
                 "segmentation_params": [METHOD_PARAMS.get(m)]} for m in chosen]
        search = PWARXSearch(model, param_grid=grid, progress=True, try_polish=try_polish)
    elif searched or (n_regions == "auto" and not fixed_partition) or (segmentation == "auto"
                                                                      and isinstance(n_regions, int)):
        if segmentation == "auto" or not fixed_partition:
            # what is not given is chosen by the adaptive search: the orders ranked as ARX models,
            # then the method (each of the default methods, and the split refined into oblique
            # boundaries where the split's free run is worse than none) and the count, or at the
            # count given (a tank that empties and overflows, --regions 3: 81.9 % free run with the
            # two methods alone, 98.6 % with the refinement, as without --regions)
            methods = DEFAULT_METHODS if segmentation == "auto" else (segmentation,)
            search = PWARXSearch(model, methods=methods, orders=searched or None, progress=True,
                                 try_polish=try_polish, n_regions=n_regions)
        else:
            search = PWARXSearch(model, param_grid=dict(searched), progress=True, try_polish=False)
    if args.shared_modes == "on" and (search is None or search.param_grid is not None or n_regions != "auto"):
        # (it was ignored: the stage belongs to the adaptive search choosing the number of regions)
        fixing = "--zero-region" if args.zero_region else f"--regions {args.regions}"
        raise ParameterError(f"--shared-modes on: the switched segmentation is tried by the search that chooses the "
                             f"number of regions; {fixing} fixes it (leave one of them out)")
    if search is None and args.scoring != "auto":  # (it was ignored)
        raise ParameterError(f"--scoring {args.scoring} ranks the candidates of a search; with the orders, the "
                             f"segmentation and the regions all given there is none (leave --scoring out)")
    if search is not None:
        shared = {"auto": "auto", "on": True, "off": False}[args.shared_modes]
        if segmentation not in (None, "auto"):
            shared = False  # the method is the user's: no other is tried
        search.set_params(scoring=args.scoring.replace("-", "_"), shared_modes=shared,
                          output_powers="auto" if powers == "auto" else None)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if search is not None:
            search.fit(data.inputs, data.output, input_names=args.input, output_name=args.output,
                       sample_time=dt, units=units)
            model = search.best_estimator_
        else:
            model.fit(data.inputs, data.output, input_names=args.input, output_name=args.output,
                      sample_time=dt, units=units)
    elapsed = time.perf_counter() - t0
    summary = _fit_summary(model, data, args.data, args.out, elapsed, search, delays)
    notes = _warning_lines([w.message for w in caught if issubclass(w.category, UserWarning)])
    if notes:
        summary["warnings"] = notes
    text = json_text(summary) + "\n"
    closed = []

    def report():  # the summary is printed before the model file is committed: a run that cannot
        # print it (a full disk behind stdout) or is stopped meanwhile leaves no file behind
        if sys.stdout is None:  # started with stdout closed (>&-): nothing to print to
            return
        try:
            sys.stdout.write(text)
            sys.stdout.flush()
        except BrokenPipeError as error:  # the reader stopped early (| head): the model is still wanted
            closed.append(error)
        except OSError as error:
            raise DataError(f"standard output: cannot write the summary ({error.strerror or error}); "
                            f"{args.out} was not written") from None

    save_model(model, args.out, before_commit=report, argument="--out")
    if closed:
        raise closed[0]  # handled as every command's closed pipe
    return 0


def _warning_lines(messages) -> list[str]:
    """The summary's ``warnings``: each message once, in the order they came, with the region
    warnings of one kind in one line (a cascade of drops, 26 -> 11 -> 8 regions, or several
    ill-conditioned or starved regions), at the place of the first."""
    from hwpts.identification.local_models import RegionWarning

    groups: dict[str, list] = {}
    lines: list = []  # strings, or the kind of a group (filled in below)
    for message in messages:
        kind = message.kind if isinstance(message, RegionWarning) else None
        if kind in ("dropped", "ill_conditioned", "starved"):
            if kind not in groups:
                groups[kind] = []
                lines.append((kind,))
            groups[kind].append(message)
        else:
            lines.append(str(message))
    out = []
    for line in lines:
        if isinstance(line, tuple):
            group = groups[line[0]]
            chained = line[0] != "dropped" or all(a.details["after"] == b.details["before"]
                                                   for a, b in zip(group[:-1], group[1:]))
            if len(group) == 1 or not chained:
                out.extend(str(w) for w in group)
            else:
                out.append(_merged(line[0], [w.details for w in group]))
        else:
            out.append(line)
    return list(dict.fromkeys(out))


def _merged(kind: str, details: list[dict]) -> str:
    """One line for several region warnings of one ``kind`` (see :func:`_warning_lines`)."""
    if kind == "dropped":
        counts = [details[0]["before"]] + [d["after"] for d in details]
        first, last = counts[0], counts[-1]
        from hwpts.identification.partition.learner import dropped_message

        return dropped_message(first, last, f" ({' -> '.join(str(c) for c in counts)})")
    last = {d["region"]: d for d in details}  # a region warned twice: its last fit's numbers
    regions = sorted(last)
    names = ", ".join(str(r) for r in regions)
    if kind == "ill_conditioned":
        conds = ", ".join(f"{last[r]['condition']:.3g}" for r in regions)
        return (f"regions {names}: least squares is ill-conditioned (condition numbers {conds}); their inputs "
                f"may not be exciting enough, consider a ridge penalty")
    rows = ", ".join(str(last[r]["rows"]) for r in regions)
    return (f"regions {names} have {rows} samples for {last[regions[0]]['parameters']} parameters; their "
            f"parameters are the minimum-norm least-squares solution")


def _validate_numbers(model, data):
    from hwpts.identification.metrics import fit_percent, rmse

    model.structure_.check_length(data.n_samples, what="DATA")
    m = model.structure_.max_lag
    y = data.output[m:]
    sim = model.simulate(data.inputs, data.output)
    one = model.predict(data.inputs, data.output)
    regions = sim.regions[m:]
    share = np.bincount(regions[regions >= 0], minlength=model.n_regions_) / max(1, np.sum(regions >= 0))
    result = {
        "fit_percent": None if sim.diverged else fit_percent(y, sim.output[m:]),
        "one_step_fit_percent": fit_percent(y, one[m:]),
        "rmse": None if sim.diverged else rmse(y, sim.output[m:]),
        "one_step_rmse": rmse(y, one[m:]),
        "n_samples": int(data.n_samples),
        "n_initial_conditions": int(m),
        "n_regions": int(model.n_regions_),
        "region_share": [round(float(v), 6) for v in share],
        "diverged": bool(sim.diverged),
    }
    if sim.diverged:
        result["diverged_at"] = sim.diverged_at
        result["reason"] = sim.reason
    result["beyond_training_range"] = _beyond_training(model, data)
    return result


def _percent(value: float) -> str:
    """A share in % with two significant digits, whole from 10 on (``100``, not ``1e+02``)."""
    return f"{value:.0f}" if value >= 10 else f"{value:.2g}"


def _beyond_line(shares: dict) -> str:
    """The line that says :func:`_beyond_training`'s shares, or "" where no sample lies outside."""
    beyond = [f"{name!r} {_percent(100 * v['share'])} % (identified on {v['training_range'][0]:.4g} to "
              f"{v['training_range'][1]:.4g})" for name, v in shares.items() if v["share"] > 0]
    return f"beyond the training range: {', '.join(beyond)} of the samples: the model extrapolates there" if beyond else ""


def _beyond_training(model, data) -> dict:
    """:func:`~hwpts.identification.analysis.beyond_training_range` of ``model`` on ``data``."""
    from hwpts.identification.analysis import beyond_training_range

    return beyond_training_range(model, data.inputs, data.output)


def _check_mapped_units(model, inputs, output) -> None:
    """A column mapped onto a model's signal (``--input``/``--output``) whose name says another unit
    than the model's for that signal is refused: a model of ``pos_mm`` validated on ``pos_m``
    scored -118055 % without a word on why."""
    st = model.structure_
    units = getattr(model, "units_", {}) or {}
    pairs = [("--input", name, column) for name, column in zip(st.input_names, inputs)]
    pairs.append(("--output", st.output_name, output))
    for flag, name, column in pairs:
        # only a unit the model took from its signal's own name (--unit text is free: 'rpm', 'v')
        known, says = units.get(name), unit_from_name(column)
        if column != name and known and says and known == unit_from_name(name) and known != says:
            raise DataError(f"{flag} {column!r}: the model's {name!r} is in {known}, and this column's name says "
                            f"{says}; convert the data to {known} (or map a column in {known})")


def _model_and_data(args):
    """``(model, data, timed)``: the model, the data mapped onto its signals (by name, or by
    --input/--output) at its rate, and whether their time is in seconds (else the sample index)."""
    from hwpts.io.models import load_model

    model = load_model(args.model)
    st = model.structure_
    inputs = list(args.input) if args.input else list(st.input_names)
    if len(inputs) != st.n_inputs:
        raise ParameterError(f"--input was given {len(inputs)} time(s); the model has {st.n_inputs} inputs "
                             f"{list(st.input_names)} (map each, in order)")
    output = args.output or st.output_name
    _check_signals(inputs, output)
    _check_mapped_units(model, inputs, output)
    resamplable = getattr(model, "sample_time_", None) is not None  # (--resample needs the model's rate)
    data, dt, hint = _load_dataset(args.data, inputs, output, args.time, args.rows,
                                   uniform=False if args.resample else None if resamplable else True)
    try:
        data = _check_sample_time(model, data, dt, args.data, args.resample)
    except DataError as error:  # which column gave the rate, where a name chose it (a temperature t)
        raise DataError(f"{error}{hint}") from None
    st.check_length(data.n_samples, what=_selection(args, repr(str(args.data))))
    # the data's time is in seconds when they have a time column or the model a sample time (else it
    # is the sample index): a figure's axis says which (it said "sample" under the data's seconds)
    return model, data, dt is not None or getattr(model, "sample_time_", None) is not None


def cmd_validate(args) -> int:
    """``hwpts validate``: free-run and one-step fit of MODEL on DATA (text or JSON), optionally a figure."""
    model, data, timed = _model_and_data(args)
    m = model.structure_.max_lag
    if data.n_samples > m and np.ptp(data.output[m:]) == 0:
        raise DataError(f"{_selection(args, repr(str(args.data)))}: the output {data.output_name!r} is constant "
                        f"({data.output[m]:.6g}) after the {m} initial conditions; fit % is undefined there "
                        f"(`hwpts predict` simulates the model on these data)")
    result = _validate_numbers(model, data)
    if args.plot is not None:
        _write_validation_plot(model, data, result, args, timed)
        result["plot"] = str(args.plot)
    if args.json:
        print(json_text(result))
        return 0
    st = model.structure_
    print(f"model: {args.model} ({model.n_regions_} regions, {st.describe_orders()}, "
          f"inputs {list(st.input_names)}, output {st.output_name!r})")
    first = result["n_initial_conditions"]
    print(f"data: {args.data} ({result['n_samples']} samples, "
          f"{'the first is the initial condition' if first == 1 else f'first {first} are initial conditions'})")
    if result["diverged"]:
        print(f"free-run fit: none - {result['reason']}")
    else:
        print(f"free-run fit: {result['fit_percent']:.2f} %  (rmse {result['rmse']:.6g})")
    print(f"one-step fit: {result['one_step_fit_percent']:.2f} %  (rmse {result['one_step_rmse']:.6g})")
    beyond = _beyond_line(result["beyond_training_range"])
    if beyond:
        print(beyond)
    if args.plot is not None:
        print(f"wrote {args.plot}")
    return 0


def _write_validation_plot(model, data, result, args, timed: bool):
    from hwpts.io.atomic import write_bytes_atomic
    from hwpts.reporting.analysis import validation_figure

    sim = model.simulate(data.inputs, data.output)
    units = getattr(model, "units_", {}) or {}
    png = validation_figure(
        data.time, data.output, sim.output, sim.regions, n_initial=model.structure_.max_lag,
        output_name=model.structure_.output_name, unit=units.get(model.structure_.output_name),
        fit_percent=result["fit_percent"], time_unit="s" if timed else None,
        title=f"{args.model} on {args.data}")
    write_bytes_atomic(args.plot, png, argument="--plot")


def cmd_predict(args) -> int:
    """``hwpts predict``: write DATA with the model's free-run, one-step or k-step prediction and the active region."""
    import sys

    from hwpts.io.datasets import is_stdout, write_table

    model, data, _ = _model_and_data(args)
    model.structure_.check_length(data.n_samples, what="DATA")
    name = data.output_name
    written = ("time_s", f"{name}_predicted", "region")
    clash = [nm for nm in (*data.input_names, name) if nm in written]
    if clash:  # one dict entry would overwrite the other: a column lost without a word
        raise DataError(f"--out: the signal {clash[0]!r} has the name of a column predict writes "
                        f"({', '.join(written)}); expected other signal names, got {clash[0]!r} "
                        f"(rename that column in the data and identify again)")
    if args.horizon is not None:
        if args.mode is not None:
            raise ParameterError("--horizon K is a k-step prediction: do not combine it with --mode")
        yhat = model.predict(data.inputs, data.output, horizon=args.horizon)
        regions = model.predict_regions(data.inputs, data.output) if args.horizon == 1 else None
        if regions is None:
            from hwpts.identification.simulation import k_step_pwarx

            center, half = model.divergence_band()
            _, regions = k_step_pwarx(model.structure_, model.partition_, model.theta_, data.inputs, data.output,
                                      args.horizon, center, half)
        mode = f"{args.horizon}-step"
    elif args.mode in (None, "simulate"):
        sim = model.simulate(data.inputs, data.output)
        if sim.diverged:
            raise SimulationError(f"{sim.reason}; no file written (try --mode one-step)")
        yhat, regions, mode = sim.output, sim.regions, "simulate"
    else:
        yhat = model.predict(data.inputs, data.output)
        regions = model.predict_regions(data.inputs, data.output)
        mode = "one-step"
    columns = {"time_s": data.time}
    for j, nm in enumerate(data.input_names):
        columns[nm] = data.inputs[:, j]
    columns[name] = data.output
    columns[f"{name}_predicted"] = yhat
    columns["region"] = regions + 1  # 1-based; 0 marks the initial conditions
    write_table(args.out, columns)
    stream = sys.stderr if is_stdout(args.out) else sys.stdout
    print(f"wrote {shown_path(args.out)} ({data.n_samples} rows, mode {mode}; region 0 = initial conditions)",
          file=stream)
    beyond = _beyond_line(_beyond_training(model, data))
    if beyond:  # as validate says it
        print(beyond, file=stream)
    return 0


def _common_data_args(parser):
    parser.add_argument("--time", metavar="COL", default=None,
                        help="time column, in s unless its name ends in _ms, _us, _ns, _min or _h (default: the "
                             "first of time_s, t_s, time, t present, then Time, time_ms, t_us, ... where they "
                             "increase, else a .mat file's scalar Ts, else the sample index; 'none': the sample "
                             "index); its step is the sample time")
    parser.add_argument("--rows", metavar="START:STOP", default=None,
                        help="use only these rows (Python slice: 0:5000; write --rows=-1001: for a negative start)")


# the registry's names, written out so that `hwpts --help` does not import the library (a test
# checks that they match hwpts.identification.segmentation.SEGMENTATION_METHODS)
SEGMENTATION_NAMES = ("alternating", "average", "clustering", "hinging", "hyperplane", "kmeans", "switched",
                      "threshold", "threshold-alternating", "zscore")


def _mapping_args(parser):
    parser.add_argument("--input", metavar="COL", action="append", default=None,
                        help="data column for the model's inputs, in order (repeat; default: the model's names)")
    parser.add_argument("--output", metavar="COL", default=None,
                        help="data column for the model's output (default: the model's name)")
    parser.add_argument("--resample", action="store_true",
                        help="interpolate data sampled at another rate onto the model's sample time "
                             "(default: refuse them)")


def _png_path(text: str):
    import argparse

    if not str(text).lower().endswith(".png"):
        raise argparse.ArgumentTypeError(f"expected a .png file name, got {text!r}")
    return text


def register(subparsers):
    """Add the ``identify``, ``validate`` and ``predict`` sub-commands to ``subparsers``."""
    from hwpts.commands._args import file_with_suffix, integer, non_negative_int, positive_int

    p = subparsers.add_parser(
        "identify", help="fit a PWARX model to a data file",
        description="Fit a PWARX model (paper section IV) and write it as JSON (schema hwpts.pwarx/1). "
                    "Prints a JSON summary.",
    )
    p.add_argument("data", metavar="DATA", help="data file: .csv, .parquet or .mat")
    p.add_argument("--input", metavar="COL", action="append", required=True, help="input column (repeat for several)")
    p.add_argument("--output", metavar="COL", required=True, help="output column")
    p.add_argument("--na", type=integer, default=None, metavar="N",
                   help="output order (default: chosen on the data, 0-4)")
    p.add_argument("--nb", default=None, metavar="N",
                   help="input order, an int or one per input: 4,4 (default: chosen on the data, 1-4)")
    p.add_argument("--nk", default=None, metavar="N",
                   help="input delay, 0 uses u(k) (default: chosen on the data, 0-1 or an estimated dead time "
                        "and one less; 1 when --na and --nb are given)")
    p.add_argument("--segmentation", choices=["auto", *SEGMENTATION_NAMES], default=None,
                   help="segmentation method (default auto: chosen on the data among threshold, alternating "
                        "(and threshold-alternating where a threshold split's free run is worse than none); "
                        "hyperplane when --hyperplane is given)")
    p.add_argument("--regions", default="auto", metavar="S",
                   help="number of regions (default auto: grown while the held-out fit improves; an int: the "
                        "methods and the orders left open are chosen at that count)")
    p.add_argument("--hyperplane", action="append", default=[], metavar='"a,b,c"',
                   help="a*x1 + b*x2 + c >= 0 on the first two inputs, or 'a,b,c@col1,col2' on named "
                        "regressor columns; repeat for a decision list (m hyperplanes, m+1 regions); write "
                        "--hyperplane=-1,0,2.8 when the first coefficient is negative")
    p.add_argument("--zero-region", type=integer, action="append", default=[], metavar="I",
                   help="region I (1-based) is the zero mode y = 0 (paper eq. 18)")
    p.add_argument("--partition-column", action="append", default=[], metavar="COL",
                   help="regressor column the region classifier may use, e.g. 'y(k-1)' (repeat; default all)")
    p.add_argument("--all-partition-columns", action="store_true",
                   help="keep every allowed column in a learned partition (default: drop the columns its "
                        "boundaries hardly use)")
    p.add_argument("--ridge", type=_ridge, default=0.0,
                   help="ridge penalty of the local least squares (relative to the regressors' scale, 0 to "
                        "1e12; default 0)")
    p.add_argument("--polish", action="store_true", help="refine parameters on the free-run simulation error")
    p.add_argument("--scoring", choices=["auto", "free-run", "one-step"], default="auto",
                   help="what ranks the candidate models on the held-out blocks (default auto: the free-run "
                        "fit, or the one-step fit when no ARX model's free run reaches 10 %% fit, as on a "
                        "system whose free run is chaotic)")
    p.add_argument("--shared-modes", choices=["auto", "on", "off"], default="auto",
                   help="also try the switched segmentation (the distinct local models first, then the regions "
                        "each covers: equal parameters on disjoint regions); default auto: when some number of "
                        "switched linear models fits the training data far better than every candidate's regions")
    p.add_argument("--output-powers", default="auto", metavar="auto|none|P,...",
                   help="powers p of the standardised last output ((y(k-1)-c)/s)^p added to every mode's regressor, "
                        "for a nonlinearity of the output such as a cubic spring (default auto: the model search "
                        "tries 2,3 on the ARX model of its best model's orders, then on that model if the ARX model "
                        "holds its own; none: never; 2,3: always)")
    p.add_argument("--seed", type=non_negative_int, default=0, metavar="N", help="random seed (default 0)")
    p.add_argument("--unit", action="append", default=[], metavar="NAME=UNIT",
                   help="unit of a signal for plots and exports, e.g. y=mm (repeat; default: from the column "
                        "name's suffix: _rpm r/min, _v V, _bar bar, _mm mm, ...)")
    p.add_argument("--out", required=True, metavar="MODEL.json", type=file_with_suffix(".json"),
                   help="model file to write (.json)")
    _common_data_args(p)
    p.set_defaults(handler=cmd_identify)

    v = subparsers.add_parser("validate", help="free-run and one-step fit of a model on data",
                              description="Free-run simulation and one-step prediction of MODEL on DATA.")
    v.add_argument("model", metavar="MODEL.json")
    v.add_argument("data", metavar="DATA")
    v.add_argument("--json", action="store_true", help="print one JSON object")
    v.add_argument("--plot", metavar="FILE.png", type=_png_path, default=None,
                   help="write a figure: measured and simulated output, residual, active region")
    _mapping_args(v)
    _common_data_args(v)
    v.set_defaults(handler=cmd_validate, prints_result="validate")

    r = subparsers.add_parser("predict", help="write a model's predictions for DATA to CSV",
                              description="Free-run (simulate) or one-step predictions of MODEL on DATA.")
    r.add_argument("model", metavar="MODEL.json")
    r.add_argument("data", metavar="DATA")
    r.add_argument("--out", required=True, metavar="FILE.csv", type=file_with_suffix(".csv", ".parquet", stdout=True),
                   help="output table: .csv, .parquet, or - for CSV on standard output")
    r.add_argument("--mode", choices=["simulate", "one-step"], default=None,
                   help="free run (simulate, the default) or one-step-ahead prediction")
    r.add_argument("--horizon", type=positive_int, default=None, metavar="K",
                   help="K-step-ahead prediction y(t|t-K): 1 is one-step, K >= the data length is the free run")
    _mapping_args(r)
    _common_data_args(r)
    r.set_defaults(handler=cmd_predict)
