"""Reading and writing tables of named columns: CSV, Parquet and MATLAB .mat (chosen by extension).

Every reader returns ``dict[str, ndarray]`` of float columns; every error is a :class:`DataError`
naming the file and what is wrong with it.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from hwpts.errors import DataError
from hwpts.io.atomic import atomic_path, write_text_atomic

SUPPORTED_SUFFIXES = (".csv", ".parquet", ".mat")


def read_table(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a table of numeric columns from ``.csv``, ``.parquet`` or ``.mat``."""
    p = Path(path)
    if not p.exists():
        raise DataError(f"{str(p)!r}: no such file")
    if p.is_dir():
        raise DataError(f"{str(p)!r}: is a folder, expected a .csv, .parquet or .mat file")
    suffix = p.suffix.lower()
    if suffix == ".csv":
        return read_csv(p)
    if suffix == ".parquet":
        return _read_parquet(p)
    if suffix == ".mat":
        return _read_mat(p)
    raise DataError(
        f"{str(p)!r}: unsupported extension {p.suffix!r}; expected one of {list(SUPPORTED_SUFFIXES)}"
    )


def read_csv(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read a CSV file with one header row of column names and numeric rows."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise DataError(f"{str(p)!r}: not a UTF-8 text file, expected CSV") from None
    rows = list(csv.reader(io.StringIO(text)))
    rows = [r for r in rows if any(cell.strip() for cell in r)]
    if not rows:
        raise DataError(f"{str(p)!r}: empty file, expected a header row of column names")
    header = [h.strip() for h in rows[0]]
    if len(set(header)) != len(header):
        dup = sorted({h for h in header if header.count(h) > 1})
        raise DataError(f"{str(p)!r}: duplicate column name(s) {dup}")
    if any(not h for h in header):
        raise DataError(f"{str(p)!r}: empty column name in the header row")
    body = rows[1:]
    if not body:
        raise DataError(f"{str(p)!r}: no data rows after the header")
    values = np.empty((len(body), len(header)))
    for i, row in enumerate(body, start=2):
        if len(row) != len(header):
            raise DataError(
                f"{str(p)!r} line {i}: {len(row)} fields, expected {len(header)} (as in the header)"
            )
        for j, cell in enumerate(row):
            try:
                values[i - 2, j] = float(cell)
            except ValueError:
                raise DataError(
                    f"{str(p)!r} line {i}, column {header[j]!r}: expected a number, got {cell.strip()!r}"
                ) from None
    return {name: values[:, j].copy() for j, name in enumerate(header)}


def write_csv(path: str | os.PathLike, columns: Mapping[str, np.ndarray], fmt: str = "%.10g") -> None:
    """Write named columns of equal length to CSV, atomically. String columns are written as is."""
    names = list(columns)
    arrays = [np.asarray(columns[n]) for n in names]
    n = {a.shape[0] for a in arrays}
    if len(n) > 1:
        raise DataError(f"columns have different lengths: { {k: a.shape[0] for k, a in zip(names, arrays)} }")
    buf = io.StringIO()
    buf.write(",".join(names) + "\n")
    formatted = [
        a.astype(str) if a.dtype.kind in "USO" else np.char.mod(fmt, a.astype(float)) for a in arrays
    ]
    if formatted:
        buf.write("\n".join(",".join(row) for row in zip(*formatted)))
        buf.write("\n")
    write_text_atomic(path, buf.getvalue())


def write_table(path: str | os.PathLike, columns: Mapping[str, np.ndarray]) -> None:
    """Write named numeric columns to ``.csv`` or ``.parquet`` (by extension), atomically."""
    p = Path(path)
    if p.suffix.lower() == ".parquet":
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:  # pragma: no cover - pyarrow is a dependency
            raise DataError("writing Parquet needs pyarrow; install pyarrow") from None
        table = pa.table({k: np.asarray(v) for k, v in columns.items()})
        with atomic_path(p) as tmp:
            pq.write_table(table, tmp)
        return
    write_csv(p, columns)


def _read_parquet(p: Path) -> dict[str, np.ndarray]:
    try:
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - pyarrow is a dependency
        raise DataError("reading Parquet needs pyarrow; install pyarrow") from None
    try:
        table = pq.read_table(p)
    except Exception as error:  # pyarrow raises several types for corrupt files
        raise DataError(f"{str(p)!r}: not a readable Parquet file ({error})") from None
    out = {}
    for name in table.column_names:
        col = table.column(name).to_numpy(zero_copy_only=False)
        try:
            out[name] = np.asarray(col, dtype=float)
        except (TypeError, ValueError):
            raise DataError(f"{str(p)!r}: column {name!r} is not numeric") from None
    return out


def _read_mat(p: Path) -> dict[str, np.ndarray]:
    """Each variable of a MATLAB file becomes a column (vectors) or several (``name_1``... for matrices)."""
    from scipy.io import loadmat

    try:
        raw = loadmat(p, squeeze_me=False)
    except Exception as error:  # scipy raises ValueError/TypeError/MatReadError
        raise DataError(f"{str(p)!r}: not a readable MATLAB .mat file ({error})") from None
    out = {}
    for name, value in raw.items():
        if name.startswith("__"):
            continue
        arr = np.asarray(value)
        if arr.dtype.kind not in "biuf" or arr.size == 0:
            continue
        arr = arr.astype(float)
        if arr.ndim == 2 and 1 in arr.shape:
            out[name] = arr.reshape(-1)
        elif arr.ndim == 2:
            if arr.shape[0] < arr.shape[1]:
                arr = arr.T
            for j in range(arr.shape[1]):
                out[f"{name}_{j + 1}"] = arr[:, j]
    if not out:
        raise DataError(f"{str(p)!r}: no numeric vector variables in the .mat file")
    return out
