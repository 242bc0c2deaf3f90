"""Tables: CSV, Parquet and MATLAB .mat read into named float columns; errors are DataError."""

import numpy as np
import pytest
from scipy.io import savemat

from hwpts.errors import DataError
from hwpts.io.datasets import read_table, write_csv, write_table


def test_csv_round_trip(tmp_path):
    path = tmp_path / "d.csv"
    write_csv(path, {"time_s": np.arange(3.0), "u": np.array([0.5, 1.5, -2.0])})
    cols = read_table(path)
    assert list(cols) == ["time_s", "u"]
    np.testing.assert_array_equal(cols["u"], [0.5, 1.5, -2.0])


def test_parquet_round_trip(tmp_path):
    path = tmp_path / "d.parquet"
    write_table(path, {"a": np.arange(4.0), "b": np.ones(4)})
    cols = read_table(path)
    np.testing.assert_array_equal(cols["a"], np.arange(4.0))


def test_mat_vectors_and_matrices(tmp_path):
    path = tmp_path / "d.mat"
    savemat(path, {"u": np.arange(5.0).reshape(-1, 1), "m": np.ones((5, 2)), "s": "text"})
    cols = read_table(path)
    assert set(cols) == {"u", "m_1", "m_2"}
    np.testing.assert_array_equal(cols["u"], np.arange(5.0))


@pytest.mark.parametrize("text, match", [
    ("", "empty file"),
    ("a,b\n", "no data rows"),
    ("a,a\n1,2\n", "duplicate column"),
    ("a,b\n1,2\n3\n", "line 3: 1 fields, expected 2"),
    ("a,b\n1,x\n", "column 'b': expected a number, got 'x'"),
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


def test_nan_is_read_then_refused_by_the_dataset(tmp_path):
    from hwpts.dataset import IODataset

    path = tmp_path / "n.csv"
    path.write_text("u,y\n1,2\nnan,3\n")
    cols = read_table(path)
    with pytest.raises(DataError, match="non-finite"):
        IODataset.from_columns(cols, ["u"], "y", time_name=None)
