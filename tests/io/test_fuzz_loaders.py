"""Hypothesis fuzzing of the loaders (issue 10): whatever the bytes, a loader returns columns or
raises an error of the package's tree (:class:`hwpts.errors.HwptsError`), never anything else."""

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from hwpts.errors import HwptsError
from hwpts.io.datasets import read_table
from hwpts.io.models import checksum, load_model

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _load(name: str, data: bytes, columns=None):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        path.write_bytes(data)
        try:
            return read_table(path, columns)
        except HwptsError:
            return None


@SETTINGS
@given(st.binary(max_size=2000))
@example(b"\x80\n")  # a header that is not UTF-8: once leaked pyarrow's UnicodeDecodeError
def test_csv_random_bytes(data):
    _load("x.csv", data, ["a", "b"])
    _load("x.csv", data)


cells = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.integers().map(str),
                  st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=6), st.just(""),
                  st.just('"quoted, cell"'), st.just("1e400"))


@SETTINGS
@given(st.lists(st.lists(cells, min_size=1, max_size=5), min_size=0, max_size=12),
       st.sampled_from([",", ";", "\t", "|"]), st.booleans(), st.booleans())
def test_csv_structured_but_broken(rows, delimiter, bom, crlf):
    header = delimiter.join(["a", "b", "c"][: max(1, len(rows[0]) if rows else 1)])
    end = "\r\n" if crlf else "\n"
    text = header + end + end.join(delimiter.join(r) for r in rows) + end
    data = (b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8")
    out = _load("x.csv", data, ["a", "b"])
    if out is not None:
        assert all(np.asarray(v).dtype.kind == "f" for v in out.values())


@SETTINGS
@given(st.dictionaries(st.text(alphabet="abcxyz_", min_size=1, max_size=4),
                       st.one_of(st.lists(st.floats(allow_nan=True), max_size=8),
                                 st.lists(st.integers(-10**6, 10**6), max_size=8),
                                 st.lists(st.text(max_size=3), max_size=8),
                                 st.lists(st.booleans(), max_size=8)),
                       min_size=1, max_size=4))
def test_parquet_columns(columns):
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pa.table({k: pa.array(v) for k, v in columns.items()})
    except (pa.ArrowInvalid, pa.ArrowTypeError, ValueError):
        return  # ragged columns: pyarrow refuses to build the table itself
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "x.parquet"
        pq.write_table(table, path)
        try:
            read_table(path, list(columns)[:2])
        except HwptsError:
            pass


@SETTINGS
@given(st.binary(max_size=600))
def test_parquet_and_mat_random_bytes(data):
    _load("x.parquet", b"PAR1" + data + b"PAR1")
    _load("x.mat", data)


arrays = st.one_of(
    st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), max_size=6).map(np.array),
    st.lists(st.integers(-100, 100), max_size=6).map(lambda v: np.array(v, dtype=np.int16)),
    st.lists(st.complex_numbers(allow_nan=False, allow_infinity=False, max_magnitude=1e6), min_size=1,
             max_size=4).map(np.array),
    st.tuples(st.integers(1, 3), st.integers(1, 3)).map(lambda s: np.ones(s)),
    st.just(np.array(["text"])),
    st.just(np.zeros((0,))),
)


@SETTINGS
@given(st.dictionaries(st.sampled_from(["u1", "u2", "y", "t", "x_1"]), arrays, min_size=1, max_size=4))
def test_mat_variables(variables):
    from scipy.io import savemat

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "x.mat"
        savemat(path, variables)
        try:
            read_table(path, ["u1", "y"])
        except HwptsError:
            pass


@pytest.fixture(scope="module")
def model_doc(tmp_path_factory):
    from hwpts.identification import PWARX
    from hwpts.identification.synthetic import make_system
    from hwpts.io.models import model_to_dict

    d = make_system(5, rng=0, n=400)
    model = PWARX(2, 2, 1, n_regions=2, segmentation="threshold").fit(d.inputs, d.output)
    return model_to_dict(model)


json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10, 10), st.floats(allow_nan=False, allow_infinity=False),
              st.text(max_size=4)),
    lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=3), inner, max_size=3)),
    max_leaves=8,
)


def _paths(doc, prefix=()):
    """Every (path, value) inside a JSON document."""
    yield prefix
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _paths(v, (*prefix, i))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_structurally_edited_model_files(model_doc, data):
    doc = json.loads(json.dumps(model_doc))
    paths = [p for p in _paths(doc) if p and p[0] != "checksum"]
    path = data.draw(st.sampled_from(paths))
    action = data.draw(st.sampled_from(["replace", "delete"]))
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    if action == "delete":
        del parent[path[-1]]
    else:
        parent[path[-1]] = data.draw(json_values)
    doc["checksum"]["value"] = checksum(doc, doc["checksum"]["sections"])  # the checksum cannot catch it
    with tempfile.TemporaryDirectory() as folder:
        file = Path(folder) / "m.json"
        file.write_text(json.dumps(doc))
        try:
            load_model(file)
        except HwptsError:
            pass


def test_a_mat_file_that_crashes_scipys_reader_is_one_error(tmp_path):
    """scipy's compiled reader can die (segmentation fault) on a corrupt element type; the file is
    read in a child process, so hwpts says the file is corrupt instead of dying (found by the fuzzing
    of a parallel branch of this work)."""
    import io

    from scipy.io import savemat

    buf = io.BytesIO()
    savemat(buf, {"a": np.arange(5.0), "y": np.ones((3, 2))})
    data = bytearray(buf.getvalue())
    data[273] = 62  # the type of y's data element: 9 (double) becomes 15881
    path = tmp_path / "crash.mat"
    path.write_bytes(bytes(data))
    with pytest.raises(HwptsError, match="not a readable MATLAB .mat file"):
        read_table(path)
