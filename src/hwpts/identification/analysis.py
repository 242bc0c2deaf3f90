"""Analysis and export of an identified model: each mode as a python-control state-space system.

Each mode of a PWARX model is the affine system of eq. 7 (:mod:`hwpts.identification.statespace`)::

    x_{k+1} = A x_k + B u_k + e
    y_k     = C x_k + D u_k + c

python-control has no affine systems, so :func:`to_control` returns the linear system with the
offset as one more input held at 1: ``B_aug = [B  e]``, ``D_aug = [D  c]``; its input names are the
model's inputs followed by ``"offset"``. Restricted to one mode (the switching ignored), the free
run of hwpts and the response of that system from the same initial state agree to rounding.

python-control is an optional dependency (``pip install hwpts[control]``).
"""

from __future__ import annotations

import numpy as np

from hwpts.errors import ParameterError

__all__ = ["to_control", "mode_initial_state"]


def _control():
    try:
        import control
    except ImportError:  # pragma: no cover - depends on the environment
        raise ParameterError("exporting to python-control needs the optional dependency: "
                             "pip install 'hwpts[control]'") from None
    return control


def to_control(model, dt=None) -> list:
    """One python-control ``StateSpace`` per mode of a fitted ``PWARX`` (offset as the last input).

    ``dt``: the sample time in seconds; ``None`` gives a discrete-time system with an unspecified
    sample time (``dt=True`` in python-control).
    """
    control = _control()
    if dt is not None and (isinstance(dt, bool) or not np.isfinite(dt) or dt <= 0):
        raise ParameterError(f"dt must be a positive number of seconds or None, got {dt!r}")
    out = []
    names = [*model.structure_.input_names, "offset"]
    for i, ss in enumerate(model.state_space()):
        B = np.column_stack([ss.B, ss.e]) if ss.A.size else np.zeros((0, len(names)))
        D = np.concatenate([ss.D.ravel(), [ss.c]]).reshape(1, -1)
        sys = control.ss(ss.A, B, ss.C, D, True if dt is None else float(dt),
                         inputs=names, outputs=[model.structure_.output_name], name=f"mode{i + 1}")
        out.append(sys)
    return out


def mode_initial_state(structure, inputs, output, k: int) -> np.ndarray:
    """The state ``x_k`` of eq. 7 from measured signals: ``[y(k-1..k-na), u_j(k-1..k-m_j)]``."""
    u = np.asarray(inputs, dtype=float).reshape(len(output), -1)
    y = np.asarray(output, dtype=float)
    x = [y[k - i] for i in range(1, structure.na + 1)]
    for j, (nb, nk) in enumerate(zip(structure.nb, structure.nk)):
        m = nk + nb - 1 if nb > 0 else 0
        x += [u[k - i, j] for i in range(1, m + 1)]
    return np.asarray(x, dtype=float)
