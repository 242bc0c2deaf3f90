"""Exports of a model's per-mode state space (``hwpts export``): JSON, MATLAB ``.mat`` and a
python-control script. The arrays come from
:func:`hwpts.identification.analysis.state_space_export`; this module only writes them.

Each mode ``i`` is the affine system of eq. 7 of the paper::

    x(k+1) = A_i x(k) + B_i u(k) + e_i
    y(k)   = C_i x(k) + D_i u(k) + c_i

active while the regressor vector lies in the region ``{x : H_i x + g_i <= 0}`` (eq. 9; the first
region that holds it, else the one it violates least, as the simulator does).
"""

from __future__ import annotations

import json
import os

import numpy as np

from hwpts.errors import DataError
from hwpts.io.atomic import atomic_path, write_text_atomic

__all__ = ["EXPORT_FORMATS", "STATESPACE_SCHEMA", "write_export"]

STATESPACE_SCHEMA = "hwpts.statespace/1"
EXPORT_FORMATS = {"json": ".json", "matlab": ".mat", "control": ".py"}


def _list(a) -> list:
    arr = np.asarray(a, dtype=float)
    return arr.tolist()


def statespace_json(doc: dict, generator: str) -> str:
    """The export as JSON text (schema ``hwpts.statespace/1``); complex poles as [re, im] pairs."""
    out = {
        "schema": STATESPACE_SCHEMA, "generator": generator,
        "sample_time_s": doc["sample_time_s"], "inputs": doc["inputs"], "output": doc["output"],
        "units": doc["units"], "state_names": doc["state_names"], "regressor_names": doc["regressor_names"],
        "equations": "x(k+1) = A x(k) + B u(k) + e;  y(k) = C x(k) + D u(k) + c;  "
                     "mode i active where H_i r(k) + g_i <= 0 (r: the regressor vector)",
        "modes": [{
            "region": m["region"], "model": m["model"], "A": _list(m["A"]), "B": _list(m["B"]),
            "C": _list(m["C"]), "D": _list(m["D"]), "e": _list(m["e"]), "c": float(m["c"]),
            "poles": [[float(p.real), float(p.imag)] for p in np.asarray(m["poles"], dtype=complex)],
            "H": _list(h), "g": _list(g),
        } for m, h, g in zip(doc["modes"], doc["H"], doc["g"])],
    }
    return json.dumps(out, indent=1, allow_nan=False) + "\n"


def _mat_header_text() -> bytes:
    """The 116 bytes of text that open a MAT-file (version 5), without a date: the same model gives
    the same file."""
    from hwpts import __version__

    return f"MATLAB 5.0 MAT-file, written by hwpts {__version__}".encode("ascii")[:116].ljust(116, b" ")


def _mat_dict(doc: dict) -> dict:
    """MATLAB variables: A, B, C, D as 3-D arrays (mode last), e, c, H and g as cell arrays."""
    modes = doc["modes"]
    n = modes[0]["A"].shape[0]
    p = len(doc["inputs"])

    def stack(key, shape):
        return np.stack([np.asarray(m[key], dtype=float).reshape(shape) for m in modes], axis=-1)

    def cell(items):
        arr = np.empty((len(items), 1), dtype=object)
        for i, item in enumerate(items):
            arr[i, 0] = item
        return arr

    return {
        "A": stack("A", (n, n)), "B": stack("B", (n, p)), "C": stack("C", (1, n)), "D": stack("D", (1, p)),
        "e": stack("e", (n, 1)), "c": np.array([[float(m["c"]) for m in modes]]),
        "H": cell([np.asarray(h, dtype=float) for h in doc["H"]]),
        "g": cell([np.asarray(g, dtype=float).reshape(-1, 1) for g in doc["g"]]),
        "Ts": np.nan if doc["sample_time_s"] is None else float(doc["sample_time_s"]),
        "InputName": cell(list(doc["inputs"])), "OutputName": doc["output"],
        "StateName": cell(list(doc["state_names"])), "RegressorName": cell(list(doc["regressor_names"])),
        "n_modes": float(len(modes)),
    }


def _py_array(a) -> str:
    arr = np.asarray(a, dtype=float)
    return "np.array(" + repr(arr.tolist()) + ", dtype=float).reshape(" + repr(arr.shape) + ")"


def _docstring_text(text: str) -> str:
    """``text`` safe inside a triple-quoted docstring: its ``repr`` without the outer quotes (line
    breaks and backslashes escaped), with every double quote escaped too."""
    return repr(str(text))[1:-1].replace('"', '\\"')


def control_script(doc: dict, generator: str, model_name: str) -> str:
    """A Python module that builds one python-control ``StateSpace`` per mode (``MODES``).

    The offset is the last input, held at 1 (python-control has no affine systems); the regions'
    ``H``, ``g`` are in ``REGIONS``. Numbers are written with ``repr``: exact round trip.
    """
    dt = doc["sample_time_s"]
    from hwpts.identification.statespace import offset_input_name

    inputs = [*doc["inputs"], offset_input_name(doc["inputs"])]
    # the names go into the docstring as a Python literal's text: a file name holding quotes or a
    # line break (a crafted '"""' then code) cannot end the docstring or add a line of code
    lines = [
        f'"""python-control systems of the PWARX model {_docstring_text(model_name)} ({_docstring_text(generator)}).',
        "",
        "Mode i: x(k+1) = A x(k) + [B e] [u(k); 1],  y(k) = C x(k) + [D c] [u(k); 1]  (paper eq. 7),",
        "active where H_i r(k) + g_i <= 0 over the regressor r named REGRESSOR_NAMES (eq. 9).",
        '"""',
        "",
        "import control",
        "import numpy as np",
        "",
        f"SAMPLE_TIME = {dt!r}  # seconds; None: unknown (discrete time, dt=True)",
        f"INPUTS = {inputs!r}",
        f"OUTPUT = {doc['output']!r}",
        f"STATE_NAMES = {list(doc['state_names'])!r}",
        f"REGRESSOR_NAMES = {list(doc['regressor_names'])!r}",
        "",
        "MODES = [",
    ]
    for m in doc["modes"]:
        n = m["A"].shape[0]
        B = np.column_stack([m["B"], m["e"]]) if n else np.zeros((0, len(inputs)))
        D = np.concatenate([np.ravel(m["D"]), [m["c"]]]).reshape(1, -1)
        lines += [
            f"    control.ss({_py_array(m['A'])},",
            f"               {_py_array(B)},",
            f"               {_py_array(m['C'])},",
            f"               {_py_array(D)},",
            "               True if SAMPLE_TIME is None else SAMPLE_TIME, inputs=INPUTS, outputs=[OUTPUT],",
            f"               name={'mode' + str(m['region'])!r}),",
        ]
    lines.append("]")
    lines.append("")
    lines.append("REGIONS = [")
    for h, g in zip(doc["H"], doc["g"]):
        lines.append(f"    ({_py_array(h)}, {_py_array(g)}),")
    lines.append("]")
    return "\n".join(lines) + "\n"


def write_export(path: str | os.PathLike, fmt: str, doc: dict, generator: str, model_name: str) -> None:
    """Write the export ``doc`` in format ``fmt`` (json, matlab, control) atomically."""
    if fmt == "json":
        write_text_atomic(path, statespace_json(doc, generator))
    elif fmt == "control":
        write_text_atomic(path, control_script(doc, generator, model_name))
    elif fmt == "matlab":
        from scipy.io import savemat

        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                savemat(fh, _mat_dict(doc), do_compression=True, oned_as="column")
                # the header's text: scipy writes the time of writing there ("Created on: ..."), so
                # two exports of one model differed; the format leaves its 116 bytes free-form
                fh.seek(0)
                fh.write(_mat_header_text())
    else:
        raise DataError(f"--format {fmt!r}: expected one of {sorted(EXPORT_FORMATS)}")
