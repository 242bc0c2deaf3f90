"""The input/output dataset every layer speaks: the test bed records one, identification fits one.

It lives outside both :mod:`hwpts.plant` and :mod:`hwpts.identification` so the identification
library never imports the plant.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from hwpts.errors import DataError

MAX_ABS_VALUE = 1e100  # largest magnitude of a signal value (its squares, and sums of them, stay finite)


def dense_real(values, label: str) -> np.ndarray:
    """``values`` as a float array; sparse, complex or non-numeric input is refused (a cast would
    drop the imaginary part or fail without saying which argument)."""
    if hasattr(values, "tocsr") or hasattr(values, "toarray"):
        raise DataError(f"{label} is a sparse matrix; pass a dense array ({label}.toarray())")
    try:
        arr = np.asarray(values)
    except ValueError:  # rows of different lengths: numpy's "inhomogeneous shape"
        raise DataError(f"{label} must be an array of numbers with rows of one length (a ragged list was "
                        f"given)") from None
    if arr.dtype.kind == "O" and arr.ndim == 0:  # None, a dict, a generator: no array (a 0-d object
        # array of it failed deep inside: 'bool' object has no attribute 'astype')
        raise DataError(f"{label} must be an array of numbers, got {type(arr.item()).__name__}")
    if np.iscomplexobj(arr):
        raise DataError(f"{label} is complex; hwpts models real signals (pass the real part or the magnitude)")
    if arr.dtype.kind in "mM":  # numpy casts dates to nanosecond counts without a word
        raise DataError(f"{label} holds dates or durations ({arr.dtype}); hwpts models numeric signals (pass the "
                        f"time as the dataset's time axis, not as a signal)")
    if arr.dtype.kind in "US" or (arr.dtype.kind == "O" and any(isinstance(v, (str, bytes)) for v in arr.flat)):
        # as scikit-learn: text is not read as numbers, even where it could be (a DataFrame column
        # of strings, an object array, a numpy array of text alike)
        raise DataError(f"{label} holds text ({arr.dtype}); convert it to numbers first "
                        f"({label}.astype(float) where every entry is one)")
    if arr.dtype.kind == "O" and arr.size:  # pandas' nullable columns: a missing value (pd.NA, None) is NaN
        missing = np.frompyfunc(lambda v: v is None or type(v).__name__ == "NAType", 1, 1)(arr).astype(bool)
        if missing.any():
            arr = np.where(missing, np.nan, arr)
    if arr.dtype.kind not in "biuf":
        try:
            arr = arr.astype(float)
        except (TypeError, ValueError):
            raise DataError(f"{label} must hold numbers, got values of type {arr.dtype}") from None
    return np.asarray(arr, dtype=float)


@dataclass(frozen=True)
class IODataset:
    """Sampled multi-input single-output data.

    Attributes
    ----------
    time : ndarray, shape (n_samples,)
        Sample instants [s], strictly increasing.
    inputs : ndarray, shape (n_samples, n_inputs)
        Input signals, one column per name in ``input_names``.
    output : ndarray, shape (n_samples,)
        The measured output signal.
    input_names : tuple of str
        Column names of the inputs (e.g. ``("valve_voltage_v", "pump_speed_rpm")``).
    output_name : str
        Name of the output (e.g. ``"motor_a_speed_rpm"``).
    extra : dict of str -> ndarray
        Other recorded columns (states, true spool position...), same length, not used for fitting.
    """

    time: np.ndarray
    inputs: np.ndarray
    output: np.ndarray
    input_names: tuple[str, ...]
    output_name: str
    extra: dict = field(default_factory=dict)

    def __post_init__(self):
        time = np.asarray(self.time)
        if time.dtype.kind in "mM" and time.ndim == 1:  # time stamps or durations: seconds from the first
            if np.any(np.isnat(time)):
                raise DataError(f"time has a missing stamp (NaT) at row {int(np.argmax(np.isnat(time)))}")
            start = time[0] if time.size and time.dtype.kind == "M" else np.timedelta64(0, "ns")
            time = (time - start).astype("timedelta64[ns]").astype(np.int64) / 1e9
        time = dense_real(time, "time")  # complex or text refused, not cast
        inputs = dense_real(self.inputs, "inputs")
        output = dense_real(self.output, "output")
        if inputs.ndim == 1:
            inputs = inputs[:, None]
        names = tuple(str(n) for n in self.input_names)
        if time.ndim != 1 or output.ndim != 1 or inputs.ndim != 2:
            raise DataError(
                f"time and output must be 1-D and inputs 2-D; got shapes {time.shape}, "
                f"{output.shape}, {inputs.shape}"
            )
        n = time.shape[0]
        if output.shape[0] != n or inputs.shape[0] != n:
            raise DataError(
                f"time, inputs and output must have the same length; got {n}, "
                f"{inputs.shape[0]}, {output.shape[0]}"
            )
        if len(names) != inputs.shape[1]:
            raise DataError(f"{inputs.shape[1]} input columns but {len(names)} input names {names}")
        if not isinstance(self.output_name, str) or not self.output_name:
            raise DataError(f"output_name must be a non-empty string, got {self.output_name!r}")
        if len(set(names)) != len(names) or self.output_name in names:
            raise DataError(f"the input names {list(names)} and the output name {self.output_name!r} must be distinct")
        checks = [("time", time), (str(self.output_name), output)]
        checks += [(name, inputs[:, j]) for j, name in enumerate(names)]
        for label, values in checks:
            if not np.all(np.isfinite(values)):
                bad = int(np.argmax(~np.isfinite(values)))
                raise DataError(f"column {label!r} has a non-finite value (NaN, inf or an empty cell) at row {bad}")
            if label != "time" and np.any(np.abs(values) > MAX_ABS_VALUE):
                bad = int(np.argmax(np.abs(values) > MAX_ABS_VALUE))
                raise DataError(f"column {label!r} has the value {values[bad]:.3g} at row {bad}, beyond "
                                f"+-{MAX_ABS_VALUE:.0e}: its squares would overflow; rescale the signal")
        if n > 1 and not np.all(np.diff(time) > 0):
            bad = int(np.argmax(~(np.diff(time) > 0))) + 1
            raise DataError(f"time must be strictly increasing; it is not at row {bad}")
        extra = {str(k): dense_real(v, f"extra column {str(k)!r}") for k, v in dict(self.extra).items()}
        for key, values in extra.items():
            if values.shape != (n,):
                raise DataError(f"extra column {key!r} has shape {values.shape}, expected ({n},)")
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "inputs", inputs)
        object.__setattr__(self, "output", output)
        object.__setattr__(self, "input_names", names)
        object.__setattr__(self, "output_name", str(self.output_name))
        object.__setattr__(self, "extra", extra)

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.time.shape[0])

    @property
    def sample_time(self) -> float:
        """Median sample period [s] (``nan`` for fewer than two samples)."""
        if self.n_samples < 2:
            return float("nan")
        return float(np.median(np.diff(self.time)))

    def uniform_sample_time(self, what: str = "the time column",
                            remedy: str = "resample the data, or split the record at the gap") -> float | None:
        """The sample period [s] when the time axis is uniform (:func:`uniform_sample_time`)."""
        return uniform_sample_time(self.time, what, remedy)

    def input(self, name: str) -> np.ndarray:
        """One input column by name."""
        try:
            return self.inputs[:, self.input_names.index(name)]
        except ValueError:
            raise DataError(f"no input named {name!r}; inputs are {list(self.input_names)}") from None

    def slice(self, start: int | None = None, stop: int | None = None) -> IODataset:
        """Rows ``start:stop`` as a new dataset."""
        sl = slice(start, stop)
        return IODataset(
            self.time[sl],
            self.inputs[sl],
            self.output[sl],
            self.input_names,
            self.output_name,
            {k: v[sl] for k, v in self.extra.items()},
        )

    def columns(self) -> dict[str, np.ndarray]:
        """All columns by name: time_s, the inputs, the output, then the extra columns."""
        cols = {"time_s": self.time}
        for i, name in enumerate(self.input_names):
            cols[name] = self.inputs[:, i]
        cols[self.output_name] = self.output
        cols.update(self.extra)
        return cols

    @classmethod
    def from_columns(
        cls,
        columns: dict[str, np.ndarray],
        input_names: Sequence[str],
        output_name: str,
        time_name: str | None = "time_s",
        sample_time: float = 1.0,
    ) -> IODataset:
        """Build a dataset from named columns; a missing column raises :class:`DataError`.

        Without a time column (``time_name=None`` or absent), time is ``arange(n) * sample_time``.
        """
        wanted = list(input_names) + [output_name]
        missing = [c for c in wanted if c not in columns]
        if missing:
            raise DataError(
                f"missing column(s) {missing}; available columns are {sorted(columns)}"
            )
        n = len(columns[output_name])
        if time_name is not None and time_name in columns:
            time = np.asarray(columns[time_name], dtype=float)
            if not np.all(np.isfinite(time)):  # said here, where the column's name is known
                bad = int(np.argmax(~np.isfinite(time)))
                raise DataError(f"the time column {time_name!r} has a non-finite value (NaN, inf or an empty "
                                f"cell) at row {bad}")
            if time.ndim == 1 and time.size > 1 and not np.all(np.diff(time) > 0):
                bad = int(np.argmax(~(np.diff(time) > 0))) + 1
                raise DataError(f"the time column {time_name!r} must be strictly increasing; it is not at row {bad}")
        else:
            if isinstance(sample_time, bool) or not isinstance(sample_time, (int, float, np.integer, np.floating)) \
                    or not (np.isfinite(sample_time) and sample_time > 0):
                where = "no time column" if time_name is None else f"no time column {time_name!r}"
                raise DataError(f"sample_time must be a positive number of seconds (the data have {where}), got "
                                f"{sample_time!r}")
            time = np.arange(n) * float(sample_time)
        inputs = np.column_stack([dense_real(columns[c], repr(c)) for c in input_names])
        return cls(time, inputs, columns[output_name], tuple(input_names), output_name)


def uniform_sample_time(time, what: str = "the time column",
                        remedy: str = "resample the data, or split the record at the gap") -> float | None:
    """The sample period [s] of the times ``time`` when they are uniform (every step within 1 % of
    the median; ``None`` for fewer than two samples), else a :class:`DataError` naming the first
    row where they are not: lagged regressors across a gap or a jitter mean other delays."""
    time = np.asarray(time, dtype=float)
    n = time.size
    if n < 2:
        return None
    steps = np.diff(time)
    dt = float(f"{float(np.median(steps)):.12g}")  # 0.01, not 0.009999999999999787 from the time column's rounding
    worst = float(np.max(np.abs(steps - dt)))
    if worst > 0.01 * dt and np.array_equal(time, time.astype(np.float32)):
        # a single-precision time axis (MATLAB single, float32 Parquet): a uniform grid rounded
        # to float32 has steps off by its spacing at the largest time (at 1000 s, 6e-5 s: 60 % of
        # a 10 kHz step); it is uniform when rounding the least-squares grid gives it back
        k = np.arange(n) - 0.5 * (n - 1)
        slope = float(np.dot(k, time - time.mean()) / np.dot(k, k))
        grid = time.mean() + k * slope
        if np.max(np.abs(grid.astype(np.float32) - time)) <= np.spacing(np.float32(np.max(np.abs(time)))):
            return float(f"{slope:.6g}")
    if worst > 0.01 * dt:
        row = int(np.argmax(np.abs(steps - dt))) + 1
        raise DataError(f"{what} is not uniformly sampled (step {dt:.6g} s, but {steps[row - 1]:.6g} s at row "
                        f"{row}); PWARX models need a constant sample time: {remedy}")
    # the mean step, to the fewest digits the time values' own resolution allows: each step of
    # an epoch axis (1.7e9 s) is rounded to 2.4e-7 s, and the median gave 0.000999927520752 s
    # for 1 ms; the mean over the record is n times finer
    mean = float(time[-1] - time[0]) / (n - 1)
    tol = 2.0 * float(np.spacing(np.max(np.abs(time)))) / (n - 1)
    return next((float(f"{mean:.{d}g}") for d in range(6, 18) if abs(float(f"{mean:.{d}g}") - mean) <= tol), mean)
