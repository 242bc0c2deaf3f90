"""Tables: CSV, Parquet and MATLAB .mat read into named float columns; errors are DataError."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.io import savemat

from hwpts.errors import DataError
from hwpts.io.datasets import read_table, write_csv, write_table


def test_csv_round_trip(tmp_path):
    path = tmp_path / "d.csv"
    write_csv(path, {"time_s": np.arange(3.0), "u": np.array([0.5, 1.5, -2.0])})
    cols = read_table(path)
    assert list(cols) == ["time_s", "u"]
    np.testing.assert_array_equal(cols["u"], [0.5, 1.5, -2.0])


@settings(max_examples=30, deadline=None)
@given(values=st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=1, max_size=20))
def test_csv_keeps_every_digit(tmp_path_factory, values):
    """What CSV writes reads back to the same floats: an epoch time axis sampled at 1 ms, an output
    near 1e9 (ten significant digits, the old format, made 1.7e9 + k ms two distinct values)."""
    path = tmp_path_factory.mktemp("digits") / "d.csv"
    epoch = 1.7e9 + 0.001 * np.arange(len(values))
    write_csv(path, {"time_s": epoch, "y": np.array(values), "region": np.arange(len(values))})
    cols = read_table(path)
    np.testing.assert_array_equal(cols["time_s"], epoch)
    np.testing.assert_array_equal(cols["y"], values)
    assert path.read_text().splitlines()[1].endswith(",0")  # integers stay integers


def test_parquet_round_trip(tmp_path):
    path = tmp_path / "d.parquet"
    write_table(path, {"a": np.arange(4.0), "b": np.ones(4)})
    cols = read_table(path)
    np.testing.assert_array_equal(cols["a"], np.arange(4.0))


def test_mat_vectors_and_matrices(tmp_path):
    path = tmp_path / "d.mat"
    savemat(path, {"u": np.arange(5.0).reshape(-1, 1), "m": np.ones((5, 2)), "s": "text",
                   "w": np.arange(10.0).reshape(2, 5), "q": np.eye(3)})
    cols = read_table(path)
    # a matrix's longer side is its samples; a square one could be either way round and is not read
    assert set(cols) == {"u", "m_1", "m_2", "w_1", "w_2"}
    np.testing.assert_array_equal(cols["u"], np.arange(5.0))
    np.testing.assert_array_equal(cols["w_2"], np.arange(5.0, 10.0))


@pytest.mark.parametrize("text, match", [
    ("", "empty file"),
    ("a,b\n", "no data rows"),
    ("a,a\n1,2\n", "duplicate column"),
    ("a,b\n1,2\n3\n", "line 3: 1 fields, expected 2"),
    ("a,b\n1,x\n", "column 'b': expected a number, got 'x'"),
    # comment lines or Excel's delimiter line above the header: said as such (two comment lines, or a
    # MATLAB %, were "line 3: 3 fields, expected 1 (as in the header)")
    ("# logger v1\n# 2024-01-01\na,b\n1,2\n", "line 1: expected the header row .* got a comment .* remove the 2 lines"),
    ("% logger v1\na,b\n1,2\n", "line 1: expected the header row .* got a comment \\('% logger v1'\\)"),
    ("sep=;\na;b\n1;2\n", "line 1: expected the header row .* got Excel's delimiter line"),
])
def test_bad_csv(tmp_path, text, match):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(DataError, match=match):
        read_table(path)


def test_bad_paths(tmp_path):
    with pytest.raises(DataError, match="no such file"):
        read_table(tmp_path / "absent.csv")
    (tmp_path / "x.txt").write_text("a\n1\n")
    with pytest.raises(DataError, match="unsupported extension"):
        read_table(tmp_path / "x.txt")
    (tmp_path / "x.mat").write_bytes(b"garbage")
    with pytest.raises(DataError, match="not a readable MATLAB"):
        read_table(tmp_path / "x.mat")


def test_missing_cells_are_nan_in_either_reader_and_a_hex_cell_is_refused_with_its_line(tmp_path):
    """A missing cell (empty, "nan", "NA") is NaN whichever reader reads the file (the dataset
    refuses it where the rows are used: --rows may leave it out); a row of empty fields is a row of
    missing values (the line-by-line reader dropped it, shifting every later sample); a
    hexadecimal cell, which pyarrow reads as a number, is no number; error lines count blank lines."""
    path = tmp_path / "n.csv"
    for text in ("u,y\n1,2\nnan,3\n4,NA\n", "u,y,\n1,2,\nnan,3,\n4,NA,\n"):  # fast reader, line-by-line reader
        path.write_text(text)
        cols = read_table(path)
        assert np.isnan(cols["u"][1]) and np.isnan(cols["y"][2]) and cols["u"][2] == 4.0
    path.write_text("u,y,\n1,2,\n,\n2,3,\n")  # the trailing commas send it to the line-by-line reader
    assert np.isnan(read_table(path)["u"][1]) and read_table(path)["u"][2] == 2.0
    path.write_text("u,y\n1,2\n0x10,3\n")
    with pytest.raises(DataError, match="line 3, column 'u': expected a number, got '0x10'"):
        read_table(path)
    path.write_text("u,y,note\n1,2,id 0x2A\n3,4,b\n")  # a hex-looking text in a column not read
    np.testing.assert_array_equal(read_table(path, ["u", "y"])["u"], [1.0, 3.0])
    path.write_text("\nu,y\n\n1,2\n3,abc\n")
    with pytest.raises(DataError, match="line 5, column 'y': expected a number, got 'abc'"):
        read_table(path)
    path.write_text("u,y\n \n1,2\n2,3\u00a0\n\n \n")  # blank lines around the rows are no rows; a no-break space is a space
    np.testing.assert_array_equal(read_table(path)["y"], [2.0, 3.0])


@pytest.mark.parametrize("gap", ["\n", " \n", "\t\r\n"])
@pytest.mark.parametrize("tail", [",", ""])  # the line-by-line reader (a trailing comma), pyarrow's
def test_a_blank_line_between_data_rows_is_refused_with_its_line(tmp_path, gap, tail):
    """A blank line between data rows was skipped by both readers: the samples on either side were
    read as neighbours, silently (a record of 600 rows with row 100 blanked read as 599 samples;
    two records separated by a blank line read as one)."""
    path = tmp_path / "b.csv"
    path.write_text(f"u,y{tail}\n1,2{tail}\n3,4{tail}\n{gap}5,6{tail}\n")
    with pytest.raises(DataError, match=r"line 4: expected a data row, got a blank line between data rows"):
        read_table(path)
    for end in ("\r", "\r\n"):  # old Mac line ends (pyarrow read them past the check), Windows'
        path.write_bytes(f"u,y{tail}{end}1,2{tail}{end}3,4{tail}{end}{end}5,6{tail}{end}".encode())
        with pytest.raises(DataError, match=r"line 4: expected a data row, got a blank line between data rows"):
            read_table(path)


@pytest.mark.parametrize("text", [
    '"V1","V2",\n0.5,1.5,\n-2,3,\n',          # the official Silverbox file: quoted names, trailing comma
    "V1;V2\r\n0.5;1.5\r\n-2;3\r\n",             # semicolons and CRLF
    "\ufeffV1\tV2\n0.5\t1.5\n-2\t3\n",          # a byte-order mark and tabs
    ',V1,V2\n0,0.5,1.5\n1,-2,3\n',              # pandas' to_csv: its unnamed row index first (it was refused)
    '"V1";"V2";"x, y"\n0.5;1.5;7\n-2;3;8\n',     # commas inside quoted names (it was read as comma-separated)
    '"V1"\t"V2"\t"a, b, c"\n0.5\t1.5\t7\n-2\t3\t8\n',
])
def test_csv_forms_read_as_published(tmp_path, text):
    path = tmp_path / "d.csv"
    path.write_text(text, encoding="utf-8")
    cols = read_table(path)  # every column: the unnamed ones (a trailing comma, pandas' index) not among them
    assert list(cols)[:2] == ["V1", "V2"] and set(cols) - {"V1", "V2"} <= {"x, y", "a, b, c"}
    np.testing.assert_array_equal(cols["V1"], [0.5, -2.0])
    np.testing.assert_array_equal(cols["V2"], [1.5, 3.0])


def test_only_the_named_columns_are_parsed(tmp_path):
    path = tmp_path / "d.csv"
    path.write_text("date,u,y\n2026-11-22,1,2\n2026-11-23,3,4\n")
    cols = read_table(path, ["u", "y"])
    assert list(cols) == ["u", "y"]
    with pytest.raises(DataError, match="line 2, column 'date': expected a number, got '2026-11-22'"):
        read_table(path)


def test_parquet_time_stamps_are_seconds_and_big_integers_are_read(tmp_path):
    """A Parquet time stamp column is read in seconds whatever its unit (10 ms steps were read as
    10 "seconds"); a CSV integer beyond 2^53 (a nanosecond epoch) is read as the nearest float
    instead of raising pyarrow's range error; duplicate Parquet names are one line."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    ticks = (np.arange(5) * 10).astype("datetime64[ms]")
    pq.write_table(pa.table({"t": pa.array(ticks), "y": np.arange(5.0)}), tmp_path / "ts.parquet")
    np.testing.assert_allclose(read_table(tmp_path / "ts.parquet")["t"], np.arange(5) * 0.01)
    (tmp_path / "ns.csv").write_text("t,y\n" + "".join(f"{1700000000000000000 + i * 10**9},{i}\n" for i in range(5)))
    t = read_table(tmp_path / "ns.csv")["t"]
    np.testing.assert_allclose(np.diff(t), 1e9)
    pq.write_table(pa.table({"a": np.ones(3), "b": np.ones(3)}).rename_columns(["u", "u"]), tmp_path / "dup.parquet")
    with pytest.raises(DataError, match=r"duplicate column name\(s\) \['u'\]"):
        read_table(tmp_path / "dup.parquet")


def test_a_mat_matrix_column_and_a_variable_of_its_name_are_refused(tmp_path):
    """Column 1 of matrix u became u_1 and a variable u_1 silently replaced it (or the reverse)."""
    savemat(tmp_path / "clash.mat", {"u": np.ones((10, 2)), "u_1": -np.ones(10), "y": np.arange(10.0)})
    with pytest.raises(DataError, match="column 1 of matrix 'u' and the variable 'u_1'"):
        read_table(tmp_path / "clash.mat")


def test_a_mat_file_without_vectors_names_what_it_skipped(tmp_path):
    """A struct of signals or a square matrix alone: the variables skipped and why (it was "no
    numeric vector variables" with no hint)."""
    savemat(tmp_path / "s.mat", {"exp": {"u": np.ones(10), "y": np.arange(10.0)}})
    with pytest.raises(DataError, match=r"no numeric vector variables .*'exp' holds no numbers .*a struct"):
        read_table(tmp_path / "s.mat")
    savemat(tmp_path / "q.mat", {"data": np.eye(5)})
    with pytest.raises(DataError, match=r"'data' is a square 5x5 matrix"):
        read_table(tmp_path / "q.mat")


def test_a_text_variable_does_not_clash_with_a_matrix_column(tmp_path):
    savemat(tmp_path / "ok.mat", {"u": np.ones((10, 2)), "u_1": "a note", "y": np.arange(10.0)})
    assert sorted(read_table(tmp_path / "ok.mat")) == ["u_1", "u_2", "y"]


def test_a_column_name_with_a_comma_or_a_quote_is_quoted_and_reads_back(tmp_path):
    from hwpts.io.datasets import write_csv

    path = tmp_path / "q.csv"
    write_csv(path, {"u,raw": np.array([1.0, 2.0]), 'say "y"': np.array([3.0, 4.0])})
    assert path.read_text().splitlines()[0] == '"u,raw","say ""y"""'
    back = read_table(path)
    assert list(back) == ["u,raw", 'say "y"'] and back["u,raw"].tolist() == [1.0, 2.0]


def test_parquet_dates_and_times_of_day_are_read_in_seconds(tmp_path):
    """A date32 column of days was read as 1 s a sample (its raw count); a time-of-day column
    was not numeric and dropped as a time axis without a word."""
    import datetime as dt

    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    days = [dt.date(2026, 1, 1) + dt.timedelta(days=i) for i in range(3)]
    clock = [(dt.datetime(2026, 1, 1) + dt.timedelta(milliseconds=10 * i)).time() for i in range(3)]
    table = pa.table({"d32": pa.array(days, pa.date32()), "d64": pa.array(days, pa.date64()),
                      "t64": pa.array(clock, pa.time64("us")), "t32": pa.array(clock, pa.time32("ms"))})
    pq.write_table(table, tmp_path / "t.parquet")
    cols = read_table(tmp_path / "t.parquet")
    for name in ("d32", "d64"):
        np.testing.assert_allclose(np.diff(cols[name]), 86400.0)
    for name in ("t64", "t32"):
        np.testing.assert_allclose(np.diff(cols[name]), 0.01)


def test_an_epoch_time_axis_gives_the_sample_time_it_was_sampled_at():
    """Steps of an epoch axis (1.7e9 s) are rounded to 2.4e-7 s each: the median step read
    0.000999927520752 s for 1 ms; the mean over the record, to the digits its resolution allows,
    is 0.001."""
    from hwpts.dataset import IODataset

    for time, step in ((1.7e9 + np.arange(1000) * 0.001, 0.001), (np.arange(1000) * 0.01, 0.01),
                       (0.5 + np.arange(100) * 1e-4, 1e-4)):
        data = IODataset(time, np.zeros((time.size, 1)), np.arange(time.size, dtype=float), ["u"], "y")
        assert data.uniform_sample_time() == step


def test_an_unreadable_mat_file_is_named_as_given(tmp_path, monkeypatch):
    """A MATLAB v7.3 (HDF5) file: said, with the path the user gave (it was the resolved absolute path)."""
    (tmp_path / "d").mkdir()
    head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, HDF5 schema 1.00 .".ljust(116, b" ") + bytes(8) + b"\x00\x02IM"
    (tmp_path / "d" / "v73.mat").write_bytes(head.ljust(512, b"\x00") + b"\x89HDF\r\n\x1a\n" + bytes(100))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(DataError, match=r"^'d/v73.mat': a MATLAB v7.3 \(HDF5\) file"):
        read_table("d/v73.mat")


def test_a_utf16_file_is_named_as_such(tmp_path):
    """Excel's "Unicode text" saved as .csv is UTF-16: said (it was "not a UTF-8 text file")."""
    path = tmp_path / "excel.csv"
    path.write_bytes("a\tb\n1\t2\n".encode("utf-16"))  # with its byte-order mark
    with pytest.raises(DataError, match="a UTF-16 text file; save it as CSV UTF-8"):
        read_table(path)
