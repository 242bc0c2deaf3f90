"""PWARX model files: JSON, schema ``"hwpts.pwarx/1"`` (a contract other tools read). No pickle.

A model file holds the orders and signal names (``structure``), one entry per region with its
parameters ``theta`` (eq. 5, offset last) and model kind, the partition as polyhedra
``{x : H_i x + g_i <= 0}`` (eq. 9), the training ranges, and a SHA-256 checksum of those numeric
sections. :func:`load_model` validates everything and refuses, with a :class:`DataError` naming
the problem, a file of another schema, with missing keys, wrong shapes, non-finite numbers or
numbers edited after saving (checksum mismatch).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import warnings

import numpy as np

from hwpts.errors import DataError, HwptsError, ParameterError

SCHEMA = "hwpts.pwarx/1"
CHECKED_SECTIONS = ("structure", "regions", "partition", "training", "signals")
REQUIRED_SECTIONS = CHECKED_SECTIONS[:4]  # "signals" (sample time, units) came later: optional

__all__ = ["SCHEMA", "model_to_dict", "model_from_dict", "save_model", "load_model", "dumps_model"]


def _jsonable(value):
    """Plain JSON types from numpy scalars/arrays, tuples and nested containers."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        v = float(value)
        return v if math.isfinite(v) else None
    return value


# the estimator's settings a model file keeps (the orders, constant and output powers are in its
# structure), so that a loaded model refits as it was fitted (``clone(load_model(p)).fit(...)``)
SETTINGS = ("segmentation", "n_regions", "hyperplanes", "region_models", "ridge", "refinement_rounds",
            "classifier_C", "segmentation_params", "polish", "partition_columns", "sparse_partition",
            "max_rows", "classifier_rows", "random_state")


def _hyperplane_text(h) -> str:
    """A hyperplane as the ``"a,b,c@col1,col2"`` text :meth:`Hyperplane.parse` reads (exact floats)."""
    if isinstance(h, str):
        return h
    body = ",".join(repr(float(v)) for v in (*h.coefficients, h.offset))
    return body if h.columns is None else body + "@" + ",".join(h.columns)


def _settings(model) -> dict:
    """The JSON-able settings of :data:`SETTINGS` (one that is not, e.g. a numpy Generator as the
    seed, is left out and keeps its default on loading). A segmenter instance is kept as its name
    with its own parameters as the method's ``segmentation_params``."""
    params = model.get_params(deep=False)
    segmenter = params["segmentation"]
    if not isinstance(segmenter, str):
        params["segmentation"] = getattr(segmenter, "name", None)
        if not params.get("segmentation_params") and hasattr(segmenter, "get_params"):
            params["segmentation_params"] = segmenter.get_params(deep=False) or None
    if params.get("hyperplanes") is not None:
        params["hyperplanes"] = [_hyperplane_text(h) for h in params["hyperplanes"]]
    seed = params.get("random_state")
    if isinstance(seed, np.random.SeedSequence) and not seed.spawn_key and isinstance(seed.entropy, int) \
            and seed.pool_size == np.random.SeedSequence().pool_size:
        params["random_state"] = seed.entropy  # default_rng(SeedSequence(s)) draws what default_rng(s) does
    elif seed is not None and not isinstance(seed, (int, np.integer)):
        warnings.warn(f"random_state ({type(seed).__name__}) is not written to the model file: the loaded model "
                      f"refits with random_state=None; fit with an int seed to keep it", UserWarning, stacklevel=5)
    out = {}
    for key in SETTINGS:
        value = _jsonable(params.get(key))
        try:
            json.dumps(value, allow_nan=False)
        except (TypeError, ValueError):
            continue
        out[key] = value
    return out


def checksum(doc: dict, sections=CHECKED_SECTIONS) -> str:
    """SHA-256 of the canonical JSON of the numeric sections (sorted keys, no spaces)."""
    payload = {k: doc.get(k) for k in sections}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def model_to_dict(model) -> dict:
    """The JSON document of a fitted :class:`~hwpts.identification.PWARX`."""
    from hwpts import __version__

    if not hasattr(model, "structure_"):
        if hasattr(model, "best_estimator_"):
            raise ParameterError("a model file holds one model: save the search's best_estimator_")
        raise ParameterError(f"only a fitted PWARX model can be saved, got {type(model).__name__} "
                             f"{'(not fitted)' if hasattr(model, 'fit') else ''}".rstrip())

    st = model.structure_
    regions = []
    std = model.parameter_std_
    cov = getattr(model, "parameter_cov_", None)
    for i, ss in enumerate(model.state_space()):
        regions.append({
            "region": i + 1,
            "model": model.region_models_[i],
            "theta": [float(v) for v in model.theta_[i]],
            "theta_std": _jsonable(std[i]),
            "theta_covariance": None if cov is None else _jsonable(cov[i]),
            "n_train_samples": int(model.region_counts_[i]),
            "max_pole_modulus": float(ss.max_pole_modulus),
            "stable": bool(ss.stable),
        })
    doc = {
        "schema": SCHEMA,
        "generator": f"hwpts {__version__}",
        "structure": _jsonable(st.to_dict()),
        "regions": regions,
        "partition": _jsonable(model.partition_.to_dict()),
        "training": {
            "output_range": [float(v) for v in model.output_range_],
            "input_ranges": [[float(a), float(b)] for a, b in np.asarray(model.input_ranges_)],
            "n_samples": int(np.sum(model.region_counts_)) + st.max_lag,
        },
        "signals": {
            "sample_time_s": getattr(model, "sample_time_", None),
            "units": dict(getattr(model, "units_", {}) or {}),
        },
        "segmentation": _jsonable({"method": model.summary()["segmentation"], **model.segmentation_info_}),
        "settings": _settings(model),
    }
    doc["checksum"] = {"algorithm": "sha256", "sections": list(CHECKED_SECTIONS), "value": checksum(doc)}
    return doc


def dumps_model(model) -> str:
    """The model file's text (indented JSON, schema ``hwpts.pwarx/1``); a model that
    :func:`load_model` would refuse (a parameter beyond +-1e100: signals of very different scales)
    is refused here, before any file is written (``identify`` wrote it and exited 0)."""
    doc = model_to_dict(model)
    text = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    try:
        model_from_dict(json.loads(text))
    except ModelNumberError as error:
        raise DataError(f"the fitted model cannot be written as a model file: {error}; rescale the signals so "
                        f"that the model's parameters stay within +-{MAX_MODEL_NUMBER:.0e}") from None
    except HwptsError as error:
        raise DataError(f"the fitted model cannot be written as a model file: {error}") from None
    return text


def save_model(model, path: str | os.PathLike, before_commit=None, argument: str = "path") -> None:
    """Write the model file atomically (temporary file, then rename); ``before_commit()`` runs
    between the two (:func:`hwpts.io.atomic.write_text_atomic`); ``argument`` names ``path`` in an
    error (the command line's ``--out``). A missing parent folder is created; an existing folder,
    a symbolic link or a device at ``path`` is refused.

    >>> import tempfile, pathlib, numpy as np
    >>> from hwpts.identification import PWARX
    >>> u = np.linspace(-1, 1, 200)[:, None]
    >>> model = PWARX(0, 1, 0, n_regions=1, segmentation="average").fit(u, 3 * u[:, 0] + 1)
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "m.json"
    >>> save_model(model, path)
    >>> np.round(load_model(path).theta_, 6)
    array([[3., 1.]])
    """
    from hwpts.io.atomic import write_text_atomic

    _check_path(path, argument)
    write_text_atomic(path, dumps_model(model), before_commit, argument)


def _check_path(path, argument: str = "path") -> None:
    """``path`` a file path (``str`` or ``os.PathLike``), else one line naming ``argument``."""
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bool):
        raise ParameterError(f"{argument} must be a file path (a str or pathlib.Path), got {path!r}")


def _reject_constant(token):
    raise ValueError(f"non-finite number {token} in a model file")


def load_model(path: str | os.PathLike):
    """Read and validate a model file; return a fitted :class:`~hwpts.identification.PWARX`."""
    from hwpts.io.paths import check_input_file

    _check_path(path)
    p = check_input_file(path, "model ", "a .json model file")
    try:
        text = p.read_text(encoding="utf-8-sig")  # a byte-order mark (a Windows editor's) is no content
        doc = json.loads(text, parse_constant=_reject_constant)
    except UnicodeDecodeError:
        raise DataError(f"model {str(p)!r}: not a UTF-8 JSON file") from None
    except ValueError as error:
        raise DataError(f"model {str(p)!r}: not a valid JSON model file ({error})") from None
    except RecursionError:
        raise DataError(f"model {str(p)!r}: JSON nested too deeply; not a model file") from None
    except OSError as error:
        raise DataError(f"model {str(p)!r}: cannot read it ({error.strerror or error})") from None
    try:
        return model_from_dict(doc)
    except HwptsError as error:
        raise DataError(f"model {str(p)!r}: {error}") from None
    except (TypeError, ValueError, KeyError, AttributeError, IndexError, RecursionError) as error:
        # a field of the wrong type that the checks below did not name: still one clear line
        raise DataError(f"model {str(p)!r}: a field has the wrong type or shape ({type(error).__name__}: "
                        f"{error}); refit the model with 'hwpts identify'") from None


def _require(doc, key, kind, where):
    if not isinstance(doc, dict) or key not in doc:
        raise DataError(f"missing key {key!r} in {where}")
    value = doc[key]
    if kind is not None and not isinstance(value, kind):
        raise DataError(f"{where}.{key} must be {getattr(kind, '__name__', kind)}, got {type(value).__name__}")
    return value


MAX_MODEL_NUMBER = 1e100  # beyond it a parameter or boundary overflows in the first products
MAX_LAG_WITHOUT_RECORD = 1000  # largest lag of a model file that does not say its record's length


class ModelNumberError(DataError):
    """A model file's number beyond +-:data:`MAX_MODEL_NUMBER` (:func:`dumps_model` adds the remedy)."""


def _has_leaf(value, kind: type) -> bool:
    """Whether ``value`` (nested lists) holds a ``kind`` (``bool``, ``str``) anywhere."""
    if isinstance(value, kind):
        return True
    return isinstance(value, list) and any(_has_leaf(v, kind) for v in value)


def _numbers(value, shape_desc: str, where: str) -> np.ndarray:
    if _has_leaf(value, bool):
        raise DataError(f"{where} must be {shape_desc} (JSON numbers), got true/false")
    if _has_leaf(value, str):  # numpy reads "0.5" as 0.5: a JSON number written as text is no number
        raise DataError(f"{where} must be {shape_desc} (JSON numbers), got text")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise DataError(f"{where} must be {shape_desc} of numbers (got ragged or non-numeric values)") from None
    if not np.all(np.isfinite(arr)):
        raise DataError(f"{where} holds a non-finite number")
    if arr.size and np.max(np.abs(arr)) > MAX_MODEL_NUMBER:
        raise ModelNumberError(f"{where} holds {arr.flat[int(np.argmax(np.abs(arr)))]:.3g}, "
                               f"beyond +-{MAX_MODEL_NUMBER:.0e}")
    return arr


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _check_structure_types(st: dict) -> None:
    """The structure's fields by type: orders ints (or lists of ints), names strings, constant bool."""
    if not _is_int(st["na"]):
        raise DataError(f"structure.na must be an int, got {type(st['na']).__name__}")
    for key in ("nb", "nk"):
        v = st[key]
        if not (_is_int(v) or (isinstance(v, list) and v and all(_is_int(x) for x in v))):
            raise DataError(f"structure.{key} must be an int or a list of ints, got {v!r}"[:200])
    names = st["input_names"]
    if not (isinstance(names, list) and names and all(isinstance(x, str) and x for x in names)):
        raise DataError(f"structure.input_names must be a list of non-empty strings, got {names!r}"[:200])
    if not isinstance(st["output_name"], str) or not st["output_name"]:
        raise DataError(f"structure.output_name must be a non-empty string, got {st['output_name']!r}"[:200])
    twice = sorted({x for x in names if names.count(x) > 1})
    if twice:
        raise DataError(f"structure.input_names names {twice[0]!r} twice")
    if st["output_name"] in names:
        raise DataError(f"structure.output_name {st['output_name']!r} is also an input's name")

    if not isinstance(st["constant"], bool):
        raise DataError(f"structure.constant must be true or false, got {st['constant']!r}"[:200])
    powers = st.get("output_powers")
    if powers is not None:  # optional: a model with power terms of the output (later than schema /1's first files)
        if not (isinstance(powers, list) and all(_is_int(x) for x in powers)):
            raise DataError(f"structure.output_powers must be a list of ints, got {powers!r}"[:200])
        for key in ("power_center", "power_scale"):
            v = st.get(key)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise DataError(f"structure.{key} must be a number when output_powers is given, got {v!r}"[:200])


def _signals_section(section, structure) -> tuple[float | None, dict]:
    """The sample time [s] (or None) and the units from the optional ``signals`` section."""
    if section is None:
        return None, {}
    if not isinstance(section, dict):
        raise DataError("signals must be an object")
    from hwpts.identification.pwarx import MIN_SAMPLE_TIME

    dt = section.get("sample_time_s")
    if dt is not None and (isinstance(dt, bool) or not isinstance(dt, (int, float)) or not math.isfinite(dt)
                           or dt < MIN_SAMPLE_TIME):  # 1e-320 s was read, and said as "(inf Hz)"
        raise DataError(f"signals.sample_time_s must be a number of seconds >= {MIN_SAMPLE_TIME:g}, or null, "
                        f"got {dt!r}")
    units = section.get("units") or {}
    if not isinstance(units, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in units.items()):
        raise DataError("signals.units must map signal names to unit strings")
    known = {*structure.input_names, structure.output_name}
    dropped = sorted(name for name, unit in units.items() if name not in known or not unit.isprintable())
    if dropped:  # (files that fits before 2026-11-27 wrote: they load, without those units)
        warnings.warn(f"signals.units: the units of {dropped} are left out (no signal of the model, or not "
                      f"printable text: a line break went on into the exports)", UserWarning, stacklevel=4)
        units = {name: unit for name, unit in units.items() if name not in dropped}
    return (None if dt is None else float(dt)), dict(units)


def _covariance(reg: dict, i: int, nf: int) -> np.ndarray:
    """A region's parameter covariance (optional in the file: older files have none -> nan;
    ``null`` entries, written for unknown values, are nan)."""
    value = reg.get("theta_covariance")
    if value is None:
        return np.full((nf + 1, nf + 1), np.nan)
    if not isinstance(value, list) or len(value) != nf + 1 or not all(
            isinstance(row, list) and len(row) == nf + 1 for row in value):
        raise DataError(f"regions[{i}].theta_covariance must be a {nf + 1} x {nf + 1} matrix")
    try:
        arr = np.array([[np.nan if v is None else v for v in row] for row in value], dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"regions[{i}].theta_covariance must hold numbers") from None
    diagonal = np.diagonal(arr)
    # (nan: unknown; a fit's round-off leaves -4e-26 beside variances of 1e-3 on a column it pins)
    if np.any(diagonal < -1e-9 * np.nanmax(np.abs(diagonal), initial=0.0)):
        raise DataError(f"regions[{i}].theta_covariance has a negative variance on its diagonal")
    return arr


def model_from_dict(doc: dict):
    """Validate a model document and build the estimator (see module doc for what is checked)."""
    from hwpts.identification.partition import RegionPartition
    from hwpts.identification.pwarx import PWARX
    from hwpts.identification.regressors import RegressorStructure

    if not isinstance(doc, dict):
        raise DataError("a model file must hold a JSON object")
    schema = doc.get("schema")
    if schema != SCHEMA:
        raise DataError(f"schema {schema!r} is not {SCHEMA!r}; this is not an hwpts PWARX model file")
    for key in (*REQUIRED_SECTIONS, "checksum"):
        _require(doc, key, None, "the model")
    cs = _require(doc, "checksum", dict, "the model")
    value = _require(cs, "value", str, "checksum")
    sections = CHECKED_SECTIONS if "signals" in doc else REQUIRED_SECTIONS
    try:
        expected = checksum(doc, sections)
    except ValueError:
        raise DataError("the model holds a non-finite number") from None
    if value != expected:
        raise DataError(
            "checksum mismatch: the numbers in the file were changed after it was saved "
            "(or it is corrupt); refit the model with 'hwpts identify'"
        )
    st_doc = _require(doc, "structure", dict, "the model")
    for key in ("na", "nb", "nk", "constant", "input_names", "output_name"):
        _require(st_doc, key, None, "structure")
    _check_structure_types(st_doc)
    try:
        structure = RegressorStructure.from_dict(st_doc)
    except HwptsError as error:
        raise DataError(f"structure: {error}") from None
    nf = structure.n_features
    regions = _require(doc, "regions", list, "the model")
    if not regions:
        raise DataError("the model has no region")
    theta, kinds, covs = [], [], []
    for i, reg in enumerate(regions):
        th = _numbers(_require(reg, "theta", list, f"regions[{i}]"), f"{nf + 1} numbers", f"regions[{i}].theta")
        if th.shape != (nf + 1,):
            what = f"{th.size} numbers" if th.ndim == 1 else f"shape {list(th.shape)}"
            raise DataError(f"regions[{i}].theta has {what}, expected a list of {nf + 1} numbers for "
                            f"{structure.describe_orders()}")
        kind = _require(reg, "model", str, f"regions[{i}]")
        if kind not in ("affine", "constant", "zero"):
            raise DataError(f"regions[{i}].model is {kind!r}; expected affine, constant or zero")
        # the fields must agree: a model that says one thing and computes another is refused
        if kind == "zero" and np.any(th != 0):
            raise DataError(f"regions[{i}].model is 'zero' but its theta is not all zeros")
        if kind == "constant" and np.any(th[:-1] != 0):
            raise DataError(f"regions[{i}].model is 'constant' but its theta has nonzero regressor coefficients")
        if not structure.constant and kind == "affine" and th[-1] != 0:  # a 'constant' region has its level
            raise DataError(f"structure.constant is false but regions[{i}].theta ends with the offset {th[-1]:.6g}")
        count = reg.get("n_train_samples", 0)
        if not _is_int(count) or not 0 <= count < 2 ** 53:
            raise DataError(f"regions[{i}].n_train_samples must be an int >= 0, got {count!r}"[:200])
        theta.append(th)
        kinds.append(kind)
        covs.append(_covariance(reg, i, nf))
    part_doc = _require(doc, "partition", dict, "the model")
    polys = _require(part_doc, "polyhedra", list, "partition")
    if len(polys) != len(regions):
        raise DataError(f"partition has {len(polys)} polyhedra for {len(regions)} regions")
    H, g = [], []
    for i, poly in enumerate(polys):
        h = _numbers(_require(poly, "H", list, f"partition.polyhedra[{i}]"), "equal-length rows", f"partition.polyhedra[{i}].H")
        gi = _numbers(_require(poly, "g", list, f"partition.polyhedra[{i}]"), "numbers", f"partition.polyhedra[{i}].g")
        h = h.reshape(0, nf) if h.size == 0 else h
        if h.ndim != 2 or h.shape[1] != nf:
            raise DataError(f"partition.polyhedra[{i}].H must have {nf} columns, got shape {h.shape}")
        if gi.shape != (h.shape[0],):
            raise DataError(f"partition.polyhedra[{i}].g must have {h.shape[0]} numbers, got {gi.size}")
        H.append(h)
        g.append(gi)
    kind = part_doc.get("kind", "polyhedra")
    if not isinstance(kind, str):
        raise DataError(f"partition.kind must be a string, got {kind!r}"[:200])
    partition = RegionPartition(H, g, kind=kind)
    training = _require(doc, "training", dict, "the model")
    out_range = _numbers(_require(training, "output_range", list, "training"), "2 numbers", "training.output_range")
    if out_range.shape != (2,) or out_range[0] > out_range[1]:
        raise DataError("training.output_range must be [low, high]")
    in_ranges = _numbers(_require(training, "input_ranges", list, "training"), "pairs", "training.input_ranges")
    if in_ranges.shape != (structure.n_inputs, 2):
        raise DataError(f"training.input_ranges must have {structure.n_inputs} [low, high] pairs")
    if np.any(in_ranges[:, 0] > in_ranges[:, 1]):
        raise DataError("training.input_ranges must be [low, high] pairs, got a low above its high")
    n_samples = training.get("n_samples")
    if n_samples is not None and not (_is_int(n_samples) and n_samples >= 0):
        raise DataError(f"training.n_samples must be an int >= 0, got {n_samples!r}"[:200])
    if _is_int(n_samples) and structure.max_lag > n_samples:  # (a model from parts has n_samples = max_lag)
        # a fit needs more samples than lags: orders edited beyond the record (nk 20000 on 4,000
        # samples took gigabytes to export)
        raise DataError(f"the orders' largest lag ({structure.max_lag}) is beyond training.n_samples "
                        f"({n_samples}): no fit on that record could have them")
    if n_samples is None and structure.max_lag > MAX_LAG_WITHOUT_RECORD:
        # the key left out (files before it, or deleted): nk 3000 exported a 181 MB file
        raise DataError(f"the orders' largest lag ({structure.max_lag}) is beyond {MAX_LAG_WITHOUT_RECORD:,} in a "
                        f"file without training.n_samples; refit the model with 'hwpts identify'")
    seg = doc.get("segmentation") or {}
    model = PWARX.from_parts(structure, partition, np.array(theta), kinds, out_range, in_ranges,
                             segmentation_info=seg if isinstance(seg, dict) else {})
    model.parameter_cov_ = np.array(covs)
    model.sample_time_, model.units_ = _signals_section(doc.get("signals"), structure)
    model.region_counts_ = np.array([int(r.get("n_train_samples", 0)) for r in regions], dtype=np.int64)
    if isinstance(seg, dict) and isinstance(seg.get("method"), str):
        model.segmentation = seg["method"]
    settings = doc.get("settings") or {}  # optional (files written before it refit with the defaults)
    if not isinstance(settings, dict):
        raise DataError(f"settings must be a JSON object, got {type(settings).__name__}")
    unknown = sorted(set(settings) - set(SETTINGS))
    if unknown:
        raise DataError(f"settings has unknown keys {unknown}; valid are {list(SETTINGS)}")
    model.set_params(**settings)
    _check_settings(model, settings)
    return model


def _check_settings(model, settings: dict) -> None:
    """The settings section by what the estimator takes (it is not under the checksum): a file
    that said ``"ridge": "x"`` or ``"n_regions": -3`` loaded and failed at the refit."""
    from hwpts.identification.settings import is_count

    try:
        if "n_regions" in settings and not is_count(settings["n_regions"], 1):
            raise ParameterError(f"n_regions must be an int >= 1, got {settings['n_regions']!r}")
        model._check_settings()
        model._segmenter()  # the method's name and its own settings
    except HwptsError as error:
        raise DataError(f"settings: {error}"[:300]) from None
