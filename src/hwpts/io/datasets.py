"""Reading and writing tables of named columns: CSV, Parquet and MATLAB .mat (chosen by extension).

Every reader returns ``dict[str, ndarray]`` of float columns; every error is a :class:`DataError`
naming the file and what is wrong with it.
"""

from __future__ import annotations

import csv
import functools
import io
import itertools
import os
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from hwpts.errors import DataError
from hwpts.io.atomic import atomic_path, write_text_atomic
from hwpts.text import plain_float

SUPPORTED_SUFFIXES = (".csv", ".parquet", ".mat")


def read_table(path: str | os.PathLike, columns=None) -> dict[str, np.ndarray]:
    """Read a table of numeric columns from ``.csv``, ``.parquet`` or ``.mat``.

    ``columns``: the names the caller needs; a CSV's other columns may hold anything (text, dates)
    and are not converted. Without it every column must be numeric.
    """
    from hwpts.io.paths import check_input_file

    p = check_input_file(path, expected="a .csv, .parquet or .mat file")
    suffix = p.suffix.lower()
    if suffix == ".csv":
        return read_csv(p, columns)
    if suffix == ".parquet":
        table = _read_parquet(p, columns)
    elif suffix == ".mat":
        table = _read_mat(p)
    else:
        raise DataError(
            f"{str(p)!r}: unsupported extension {p.suffix!r}; expected one of {list(SUPPORTED_SUFFIXES)}"
        )
    wanted = [c for c in (columns if columns is not None else table) if c in table]
    lengths = {c: int(np.asarray(table[c]).shape[0]) for c in wanted}
    if len(set(lengths.values())) > 1:
        raise DataError(f"{str(p)!r}: the variables differ in length ({', '.join(f'{k} {v}' for k, v in lengths.items())}); "
                        f"every signal needs one value per sample")
    return table


DELIMITERS = (",", ";", "\t")


def _sniff(p: Path, head: bytes | None = None) -> str:
    """The delimiter of the header line (in ``head``, the file's first bytes, read when not given):
    the most frequent of comma, semicolon and tab."""
    if head is None:
        try:
            with p.open("rb") as f:
                head = f.read(65536)
        except OSError as error:
            raise DataError(f"{str(p)!r}: cannot read ({error.strerror or error})") from None
    text = head[:65536].decode("utf-8-sig", errors="replace")
    first = next((line for line in text.splitlines() if line.strip()), "")
    outside = re.sub(r'"[^"]*"', "", first)  # not inside quoted names ("u, V";"y, rpm" is a semicolon file)
    counts = {d: outside.count(d) for d in DELIMITERS}
    best = max(counts, key=counts.get)
    return best if counts[best] > 0 else ","


def read_csv(path: str | os.PathLike, columns=None) -> dict[str, np.ndarray]:
    """Read a CSV file with one header row of column names (pyarrow's reader).

    The delimiter (comma, semicolon or tab) is detected from the header; a byte-order mark, CRLF
    line ends, quoted names and trailing empty columns (a comma at the end of every row, as the
    official Silverbox file) are accepted. Only the ``columns`` asked for (default: all) must be
    numeric. A malformed file is diagnosed line by line (the line number in the message).
    """
    import pyarrow as pa
    import pyarrow.csv as pacsv

    p = Path(path)
    try:
        data = p.read_bytes()  # read once: the delimiter, the blank-line check and both parses use it
    except OSError as error:
        raise DataError(f"{str(p)!r}: cannot read ({error.strerror or error})") from None
    delimiter = _sniff(p, data)
    if _BLANK_INSIDE.search(data):  # pyarrow skips it: the line-by-line reader refuses one between data rows
        return _read_csv_python(p, delimiter, columns)
    try:
        table = pacsv.read_csv(pa.BufferReader(data), parse_options=pacsv.ParseOptions(delimiter=delimiter))
    except (pa.ArrowInvalid, pa.ArrowTypeError, UnicodeDecodeError):
        return _read_csv_python(p, delimiter, columns)  # raises the precise error
    try:
        names = [str(n).strip() for n in table.column_names]
    except UnicodeDecodeError:  # a header that is not UTF-8
        return _read_csv_python(p, delimiter, columns)  # raises the precise error
    # an unnamed column (a trailing delimiter on every row, or the row index pandas' to_csv writes
    # first) cannot be asked for: it is not read
    keep = [i for i, n in enumerate(names) if n]
    if not keep or len({names[i] for i in keep}) != len(keep) or all(is_number(names[i]) for i in keep):
        return _read_csv_python(p, delimiter, columns)  # no, duplicate or numeric names: said precisely
    if table.num_rows == 0:
        raise DataError(f"{str(p)!r}: no data rows after the header")
    wanted = [i for i in keep if columns is None or names[i] in set(columns)]
    out = {}
    for i in wanted:
        name = names[i]
        column = table.column(i)
        if not (pa.types.is_floating(column.type) or pa.types.is_integer(column.type) or pa.types.is_null(column.type)):
            return _read_csv_python(p, delimiter, columns)
        # unsafe: an integer beyond 2^53 (a nanosecond epoch time) rounds to the nearest float
        # instead of raising pyarrow's range error; a missing cell is NaN (refused where it is used)
        out[name] = column.cast(pa.float64(), safe=False).to_numpy(zero_copy_only=False)
    integers = [table.column_names[i] for i in wanted if pa.types.is_integer(table.column(i).type)]
    if integers and _has_hex(data, delimiter, integers):  # pyarrow reads "0x10" as 16; no CSV writer means that
        return _read_csv_python(p, delimiter, columns)  # refuses the cell, naming its line
    return out


_EOL = rb"(?:\r\n|\n|\r(?!\n))"  # a line end: CRLF, LF, or a lone CR (old Mac files)
_BLANK_INSIDE = re.compile(_EOL + rb"[ \t\f\v]*" + _EOL + rb"\s*\S")  # a blank line with text after it


def _has_hex(data: bytes, delimiter: str, names: list[str]) -> bool:
    """Whether a cell of the columns ``names`` (read as integers) of the CSV ``data`` was written in
    hexadecimal."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.csv as pacsv

    try:
        text = pacsv.read_csv(pa.BufferReader(data), parse_options=pacsv.ParseOptions(delimiter=delimiter),
                              convert_options=pacsv.ConvertOptions(include_columns=names,
                                                                   column_types={n: pa.string() for n in names}))
    except (pa.ArrowInvalid, OSError):
        return True  # let the line-by-line reader say what it is
    return any(pc.any(pc.match_substring(text.column(n), "x", ignore_case=True)).as_py() for n in names)


def column_names(path: str | os.PathLike) -> list[str]:
    """The names of a CSV's or a Parquet file's columns without reading their data (the header
    row, the schema); ``[]`` for another format or when they cannot be read (the reader says why)."""
    import csv
    import io

    p = Path(path)
    suffix = p.suffix.lower()
    try:
        if suffix == ".csv":
            with p.open("rb") as f:
                head = f.read(65536)
            text = head.decode("utf-8-sig", errors="replace")
            first = next((line for line in text.splitlines() if line.strip()), "")
            row = next(csv.reader(io.StringIO(first), delimiter=_sniff(p, head)), [])
            return [name.strip() for name in row if name.strip()]
        if suffix == ".parquet":
            import pyarrow.parquet as pq

            return list(pq.read_schema(p).names)
    except Exception:  # noqa: BLE001 - an unreadable file is said by the reader
        return []
    return []


def temporal_columns(path: str | os.PathLike) -> set[str]:
    """The columns of a Parquet file typed as time stamps, durations, dates or times of day (read in
    seconds already, whatever their names say); none for another format."""
    p = Path(path)
    if p.suffix.lower() != ".parquet":
        return set()
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq

        schema = pq.read_schema(p)
    except Exception:  # noqa: BLE001 - an unreadable file is said by the reader
        return set()
    return {f.name for f in schema if pa.types.is_temporal(f.type)}


def _csv_rows(path: str | os.PathLike, first: bool = False) -> tuple[list[str], list[list[str]]] | None:
    """``(header, data rows)`` of a CSV file, the header's names stripped and blank rows skipped (with
    ``first``, the first data row only, read from the file's first 64 KB); None for another format."""
    p = Path(path)
    try:
        if p.suffix.lower() != ".csv" or not p.is_file():  # (a FIFO would block the read)
            return None
        with p.open("rb") as f:
            raw = f.read(65536) if first else f.read()
    except OSError:  # a name too long, a folder we may not search
        return None
    text = io.StringIO(raw.decode("utf-8-sig", errors="replace"), newline=None)  # universal newlines, as read_text
    reader = csv.reader(text, delimiter=_sniff(p, raw[:65536]))
    try:
        rows = [r for r in itertools.islice((r for r in reader if any(c.strip() for c in r)), 2 if first else None)]
    except csv.Error:  # not a table: the reader of the data says what is wrong with it
        return None
    return ([h.strip() for h in rows[0]], rows[1:]) if rows else None


def _csv_cells(path: str | os.PathLike, column: str) -> list[str] | None:
    """The stripped cells of a CSV column; None for another format or a file without that column."""
    got = _csv_rows(path)
    if got is None or column not in got[0]:
        return None
    j = got[0].index(column)
    return [r[j].strip() if j < len(r) else "" for r in got[1]]


def numeric_share(path: str | os.PathLike, column: str) -> float:
    """The share of a CSV column's non-empty cells that read as numbers (0 for another format or
    a file without that column): a time column of numbers with one mistyped cell (near 1) is a
    broken time axis, a column of dates or labels (near 0) is not a time axis at all."""
    cells = [c for c in _csv_cells(path, column) or () if c]
    return sum(is_number(c) for c in cells) / len(cells) if cells else 0.0


ISO_DATE = re.compile(r"\d{4}-\d{2}-\d{2}")


def datetime_columns(path: str | os.PathLike) -> set[str]:
    """The CSV columns whose first cell is an ISO 8601 date or date-time (the file's head read once;
    empty for another format)."""
    got = _csv_rows(path, first=True)
    if got is None or not got[1]:
        return set()
    header, (row,) = got
    return {h for j, h in enumerate(header) if h and j < len(row) and ISO_DATE.match(row[j].strip())}


def csv_datetime_seconds(path: str | os.PathLike, column: str) -> np.ndarray | None:
    """A CSV column of ISO 8601 date-times (``2024-01-01 00:00:00.005``, ``...T...Z``, with an offset,
    a decimal comma, or plain dates) in seconds from its first stamp; None when the file is no CSV,
    has no such column, or a cell is empty or not such a date-time (a logger's wall-clock stamps as
    the time axis: read as text they were dropped, and the data compared at the model's rate without
    a word). The whole file is read: ask it of the :func:`datetime_columns` only."""
    cells = _csv_cells(path, column)
    if not cells or not all(cells):
        return None
    import pyarrow as pa

    cells = [re.sub(r"(\d{2}:\d{2}:\d{2}),(\d)", r"\1.\2", c) for c in cells]  # ISO 8601's decimal comma
    for kind in (pa.timestamp("ns"), pa.timestamp("ns", tz="UTC")):  # naive, then with a zone or offset
        try:
            ns = pa.array(cells).cast(kind).cast(pa.int64()).to_numpy(zero_copy_only=False)
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
            continue
        return (ns - ns[0]).astype(float) / 1e9
    return None


def is_number(text: str) -> bool:
    """Whether ``text`` reads as a number (a header cell that is a number: no header row)."""
    try:
        plain_float(text)
    except ValueError:
        return False
    return True


def _read_csv_python(p: Path, delimiter: str = ",", columns=None) -> dict[str, np.ndarray]:
    """The line-by-line reader: slow, but it names the line of every problem."""
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        with p.open("rb") as f:
            utf16 = f.read(2) in (b"\xff\xfe", b"\xfe\xff")  # Excel's "Unicode text"
        raise DataError(f"{str(p)!r}: " + ("a UTF-16 text file; save it as CSV UTF-8" if utf16 else
                                           "not a UTF-8 text file, expected CSV")) from None
    except OSError as error:
        raise DataError(f"{str(p)!r}: cannot read ({error.strerror or error})") from None
    # (line number, row); a blank line before the first data row or after the last is skipped, but
    # one between data rows is refused: skipped, it joined the samples on either side (two records
    # separated by a blank line read as one); a row of empty fields (",,") is a row of missing
    # values: dropped, it shifted every later sample in silence
    reader = csv.reader(io.StringIO(text), delimiter=delimiter)
    numbered, line, blank = [], 1, None
    for row in reader:
        if len(row) > 1 or (row and row[0].strip()):
            if blank is not None:
                raise DataError(f"{str(p)!r} line {blank}: expected a data row, got a blank line between data rows "
                                f"(the samples on either side would be read as neighbours); remove it, or split "
                                f"the file where one record ends")
            numbered.append((line, row))
        elif len(numbered) >= 2 and blank is None:
            blank = line
        line = reader.line_num + 1
    if not numbered:
        raise DataError(f"{str(p)!r}: empty file, expected a header row of column names")
    header = [h.strip() for h in numbered[0][1]]
    while header and not header[-1]:  # trailing empty columns (a comma at the end of every row)
        header.pop()
    def remark(row):  # a comment line (# or MATLAB's %) or Excel's "sep=;" line above the header
        first = row[0].strip() if row else ""
        return first.startswith(("#", "%")) or bool(re.fullmatch(r"sep=.?", delimiter.join(row).strip()))

    n = next((k for k, (_, row) in enumerate(numbered) if not remark(row)), len(numbered))
    excel = bool(header) and header[0].lower().startswith("sep=")
    def width(row):  # fields, less trailing empty ones (a delimiter at the end of every data row)
        return len(row) - next((k for k, cell in enumerate(reversed(row)) if cell.strip()), len(row))

    if header and n and n < len(numbered) and (excel or width(numbered[n][1]) != width(numbered[0][1])):
        what = "Excel's delimiter line" if excel else "a comment"
        raise DataError(f"{str(p)!r} line {numbered[0][0]}: expected the header row of column names, got {what} "
                        f"({delimiter.join(numbered[0][1])[:40]!r}); remove the {n} line{'s' if n > 1 else ''} "
                        f"above the header")
    named = [h for h in header if h]  # an unnamed column (pandas' row index) cannot be asked for: not read
    if named and all(is_number(h) for h in named):
        raise DataError(f"{str(p)!r}: expected a header row of column names first (a header row such as u,y), got numbers "
                        f"({delimiter.join(header[:4])}{', ...' if len(header) > 4 else ''})")
    if len(set(named)) != len(named):
        dup = sorted({h for h in named if named.count(h) > 1})
        raise DataError(f"{str(p)!r}: duplicate column name(s) {dup}")
    if not named:
        raise DataError(f"{str(p)!r}: no column names in the header row")
    body = numbered[1:]
    if not body:
        raise DataError(f"{str(p)!r}: no data rows after the header")
    wanted = [j for j, h in enumerate(header) if h and (columns is None or h in set(columns))]
    missing = _missing_cells()
    values = np.empty((len(body), len(header)))
    for k, (i, row) in enumerate(body):
        while len(row) > len(header) and not row[-1].strip():
            row = row[:-1]
        if len(row) != len(header):
            raise DataError(
                f"{str(p)!r} line {i}: {len(row)} fields, expected {len(header)} (as in the header)"
            )
        for j in wanted:
            cell = row[j]
            if cell.strip() in missing:  # as the fast reader: NaN, refused only where the rows are used
                values[k, j] = np.nan
                continue
            try:
                values[k, j] = plain_float(cell)
            except ValueError:
                # a European file's 0,5 or 12,75 (not 1,000: a thousands separator as likely)
                comma = re.fullmatch(r"[+-]?(0?,\d+|\d+,(\d{1,2}|\d{4,}))([eE][+-]?\d+)?", cell.strip())
                raise DataError(f"{str(p)!r} line {i}, column {header[j]!r}: expected a number, "
                                f"got {cell.strip()!r}"
                                f"{' (a decimal comma: write the numbers with a point, 0.5)' if comma else ''}") from None
    return {header[j]: values[:, j].copy() for j in wanted}


def _missing_cells() -> frozenset:
    """The cells pyarrow's CSV reader reads as missing (null): NaN in the line-by-line reader too."""
    import pyarrow.csv as pacsv

    return frozenset(pacsv.ConvertOptions().null_values)


def _cells(a: np.ndarray, fmt: str | None) -> list:
    """The CSV cells of one column: strings as they are, integers as integers, floats with ``fmt``
    or, by default, the shortest text that reads back to the same number (Python's ``repr``): ten
    significant digits turned an epoch time axis (1.7e9 s sampled at 1 ms) into two distinct
    values, and an output near 1e9 into steps of 1."""
    if a.dtype.kind in "USO":
        return a.astype(str).tolist()
    if a.dtype.kind in "iub":
        return a.astype(np.int64).astype(str).tolist()
    if fmt is not None:
        return np.char.mod(fmt, a.astype(float)).tolist()
    return [repr(v) for v in a.astype(float).tolist()]


def csv_text(columns: Mapping[str, np.ndarray], fmt: str | None = None) -> str:
    """Named columns of equal length as CSV text (header row, comma-separated); floats exact
    (see :func:`_cells`) unless ``fmt`` (a ``%`` format) says otherwise."""
    names = list(columns)
    arrays = [np.asarray(columns[n]) for n in names]
    n = {a.shape[0] for a in arrays}
    if len(n) > 1:
        raise DataError(f"columns have different lengths: { {k: a.shape[0] for k, a in zip(names, arrays)} }")
    buf = io.StringIO()
    # the csv module quotes a name or text cell holding a comma, a quote or a line break (joined
    # by hand, a column "u,raw" shifted every later column for any reader)
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(names)
    writer.writerows(zip(*[_cells(a, fmt) for a in arrays]))
    return buf.getvalue()


def write_csv(path: str | os.PathLike, columns: Mapping[str, np.ndarray], fmt: str | None = None) -> None:
    """Write named columns of equal length to CSV, atomically. String columns are written as is."""
    write_text_atomic(path, csv_text(columns, fmt))


def is_stdout(path) -> bool:
    """Whether an output path is ``-`` (standard output)."""
    return str(path) == "-"


def _write_stdout(text: str) -> None:
    """``text`` on standard output in full, or :class:`BrokenPipeError` (the reader stopped early:
    ``| head``). Through the file descriptor, each partial write resumed: Python's buffered stream
    dropped the rest of a large write that the pipe took only in part, without an error, and the
    command said "wrote to standard output (400000 rows ...)" after ``| head -c 100``."""
    import sys

    stream = sys.stdout
    try:
        fd = stream.fileno()
    except (AttributeError, ValueError, io.UnsupportedOperation):  # not a file (a test's capture)
        stream.write(text)
        stream.flush()
        return
    stream.flush()
    view = memoryview(text.encode(getattr(stream, "encoding", None) or "utf-8", errors="backslashreplace"))
    while view:
        view = view[os.write(fd, view):]


def write_table(path: str | os.PathLike, columns: Mapping[str, np.ndarray]) -> None:
    """Write named columns to ``.csv`` or ``.parquet`` (by extension), atomically; ``-`` writes CSV
    to standard output."""
    if is_stdout(path):
        _write_stdout(csv_text(columns))
        return
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


def _read_parquet(p: Path, columns=None) -> dict[str, np.ndarray]:
    """Numeric columns of a Parquet file (only ``columns`` when given: the others may hold text)."""
    try:
        import pyarrow.parquet as pq
    except ImportError:  # pragma: no cover - pyarrow is a dependency
        raise DataError("reading Parquet needs pyarrow; install pyarrow") from None
    import pyarrow as pa

    try:
        names = [str(n) for n in pq.read_schema(p).names]
        dup = sorted({n for n in names if names.count(n) > 1})
        table = None if dup else pq.read_table(p)
    except Exception as error:  # pyarrow raises several types for corrupt files
        first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise DataError(f"{str(p)!r}: not a readable Parquet file ({first})") from None
    if dup:
        raise DataError(f"{str(p)!r}: duplicate column name(s) {dup}")
    out = {}
    for i, name in enumerate(names):
        if columns is not None and name not in columns:
            continue
        column = table.column(i)
        kind = column.type
        if pa.types.is_timestamp(kind) or pa.types.is_duration(kind) or pa.types.is_time(kind) \
                or pa.types.is_date(kind):
            # a time stamp, duration, time of day or date is read in seconds, whatever its unit (not
            # its raw count: a date32 column of days read as a sample time of 1 s, a time of day was dropped)
            if pa.types.is_date32(kind):
                per_second, ticks = 1.0 / 86400.0, column.cast(pa.int32())
            elif pa.types.is_date64(kind):
                per_second, ticks = 1e3, column.cast(pa.int64())
            else:
                per_second = {"s": 1.0, "ms": 1e3, "us": 1e6, "ns": 1e9}[kind.unit]
                ticks = column.cast(pa.int32() if pa.types.is_time32(kind) else pa.int64())
            out[name] = np.asarray(ticks.to_numpy(zero_copy_only=False), dtype=float) / per_second
            continue
        col = column.to_numpy(zero_copy_only=False)
        try:
            out[name] = np.asarray(col, dtype=float)
        except (TypeError, ValueError):
            raise DataError(f"{str(p)!r}: column {name!r} is not numeric") from None
    return out


_MAT_READER = """
import io, json, sys
import numpy as np
import scipy.sparse
from scipy.io import loadmat
try:
    raw = loadmat(sys.argv[1], squeeze_me=False)
except MemoryError:
    sys.stdout.write("the variables it declares do not fit in memory (a corrupt size)"); sys.exit(3)
except Exception as error:
    sys.stdout.write(str(error) or type(error).__name__); sys.exit(3)
names, kinds, arrays = [], [], {}
for name, value in raw.items():
    if name.startswith("__"):
        continue
    names.append(name)
    if scipy.sparse.issparse(value):
        kinds.append("sparse")
        continue
    arr = np.asarray(value)
    kinds.append("array" if arr.dtype.kind in "biufc" else "other")
    if kinds[-1] == "array":
        arrays[f"v{len(names) - 1}"] = arr
buf = io.BytesIO()
np.savez(buf, **arrays)
sys.stdout.buffer.write(json.dumps({"names": names, "kinds": kinds}).encode() + b"\\n" + buf.getvalue())
"""


def _loadmat_isolated(p: Path) -> dict:
    """:func:`_loadmat_child`'s result, kept for the last file read (the same file read again, for
    the variables it skipped, started a second child process: 0.34 -> 0.7 s)."""
    try:
        st = p.stat()
    except OSError:
        return _loadmat_child(p)  # (said by the reader)
    resolved = str(p.resolve())
    try:
        return _loadmat_last(resolved, st.st_size, st.st_mtime_ns, st.st_ino)
    except DataError as error:  # named as the user gave it (the cache's key is the resolved path)
        raise DataError(str(error).replace(repr(resolved), repr(str(p)), 1)) from None


@functools.lru_cache(maxsize=1)
def _loadmat_last(path: str, size: int, mtime_ns: int, inode: int) -> dict:
    """The file ``path`` as it is (its size, time and inode in the key: a file rewritten is read again)."""
    return _loadmat_child(Path(path))


def _loadmat_child(p: Path) -> dict:
    """``scipy.io.loadmat`` in a child process: its compiled reader can crash the process on a
    corrupt file (an unknown element type: a segmentation fault, not an exception), which must end
    in one clear line. Returns the numeric arrays by name, ``"sparse"`` for sparse variables and
    ``None`` for the others (text, cells, structs)."""
    import json
    import subprocess
    import sys

    from scipy.io.matlab import matfile_version

    try:  # the header, in pure Python: most non-MAT files stop here, without a child process
        with p.open("rb") as f:
            major, _ = matfile_version(f)
    except OSError as error:
        raise DataError(f"{str(p)!r}: cannot read ({error.strerror or error})") from None
    except Exception as error:  # noqa: BLE001 - scipy raises ValueError, MatReadError, ...
        raise DataError(f"{str(p)!r}: not a readable MATLAB .mat file ({error})") from None
    if major == 2:
        raise DataError(f"{str(p)!r}: a MATLAB v7.3 (HDF5) file; save it with save(..., '-v7') to read it here")
    proc = subprocess.run([sys.executable, "-c", _MAT_READER, str(p)], capture_output=True, check=False)
    if proc.returncode == 3:
        message = proc.stdout.decode("utf-8", errors="replace").strip()
        raise DataError(f"{str(p)!r}: not a readable MATLAB .mat file ({message})")
    if proc.returncode != 0:
        raise DataError(f"{str(p)!r}: not a readable MATLAB .mat file (the reader crashed on it: the file is corrupt)")
    head, _, body = proc.stdout.partition(b"\n")
    meta = json.loads(head)
    with np.load(io.BytesIO(body), allow_pickle=False) as arrays:
        return {name: (arrays[f"v{i}"] if kind == "array" else "sparse" if kind == "sparse" else None)
                for i, (name, kind) in enumerate(zip(meta["names"], meta["kinds"]))}


def mat_unread(path: str | os.PathLike) -> dict[str, str]:
    """The variables of a .mat file that are not read as columns, each with why (text, cells and
    structs; empty, square and 3-D arrays); ``{}`` for another format or an unreadable file."""
    p = Path(path)
    if p.suffix.lower() != ".mat":
        return {}
    try:
        raw = _loadmat_isolated(p)
    except DataError:
        return {}
    reasons = {name: _mat_unread_reason(value) for name, value in raw.items() if not name.startswith("__")}
    return {name: reason for name, reason in reasons.items() if reason is not None}


def _mat_unread_reason(value) -> str | None:
    """Why a .mat variable (as :func:`_loadmat_isolated` gives it) is not read as columns, or
    ``None`` when it is (sparse and complex variables are refused, not skipped: ``None`` too)."""
    if value is None:
        return "holds no numbers (text, a cell array or a struct)"
    if isinstance(value, str):
        return None
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf":
        return None if arr.dtype.kind == "c" else "holds no numbers"
    shape = "x".join(map(str, arr.shape))
    if arr.size == 0:
        return f"is empty ({shape})"
    if arr.ndim > 2:
        return f"is a {arr.ndim}-D array ({shape})"
    if arr.ndim == 2 and 1 not in arr.shape and arr.shape[0] == arr.shape[1]:
        return f"is a square {shape} matrix (its samples could run down or across)"
    return None


def _read_mat(p: Path) -> dict[str, np.ndarray]:
    """Each variable of a MATLAB file becomes a column (vectors) or several (``name_1``... for matrices).

    The file is parsed in a child process (:func:`_loadmat_isolated`); text, cells, structs and
    square matrices (whose samples could run down or across) are skipped; complex and sparse
    variables are refused. A matrix's longer side is its samples.
    """
    raw = _loadmat_isolated(p)
    out = {}
    for name, value in raw.items():
        if name.startswith("__"):
            continue
        if isinstance(value, str):  # "sparse"
            raise DataError(f"{str(p)!r}: variable {name!r} is a sparse matrix; save it as a full (dense) array")
        arr = np.asarray(value)
        if arr.dtype.kind == "c":
            raise DataError(f"{str(p)!r}: variable {name!r} is complex; hwpts models real signals "
                            f"(save the real part, or the magnitude, as its own variable)")
        if _mat_unread_reason(arr) is not None:  # text, empty, square (samples down or across?), 3-D
            continue
        arr = arr.astype(float)
        if arr.ndim == 2 and 1 in arr.shape:
            out[name] = arr.reshape(-1)
        elif arr.ndim == 2:
            if arr.shape[0] < arr.shape[1]:  # the longer side is the samples
                arr = arr.T
            for j in range(arr.shape[1]):
                column = f"{name}_{j + 1}"
                other = raw.get(column)
                numeric = other is not None and not isinstance(other, str) and np.asarray(other).dtype.kind in "biuf"
                if numeric or column in out:  # a numeric variable of that name: neither may shadow the other
                    raise DataError(f"{str(p)!r}: column {j + 1} of matrix {name!r} and the variable {column!r} "
                                    f"would both be the column {column!r}; rename one of them")
                out[column] = arr[:, j]
    if not out:
        skipped = mat_unread(p)  # (the file was just read: its last reading is kept)
        why = "; ".join(f"{name!r} {reason}" for name, reason in list(skipped.items())[:4])
        raise DataError(f"{str(p)!r}: no numeric vector variables in the .mat file"
                        + (f" ({why}); save each signal as a numeric vector" if why else ""))
    return out
