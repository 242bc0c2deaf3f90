"""State-space form of each ARX mode (paper eq. 7) and its poles.

With the state ``x_k = [y(k-1) .. y(k-na), u_j(k-1) .. u_j(k-m_j) for each input j]`` (eq. 7, with
``m_j = nk_j + nb_j - 1`` the largest lag of input ``j``), a mode ``theta`` of eq. 5 is::

    x_{k+1} = A x_k + B u_k + e
    y_k     = C x_k + D u_k + c

``D`` is non-zero only for inputs with ``nk_j = 0`` (the paper's ``h_i(k)`` in eq. 18). The poles are
the eigenvalues of ``A``; the input-shift blocks only add poles at 0. A mode with a pole of modulus
>= 1 is unstable on its own (the switched system may still be stable, or not: see ``simulate``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ModeStateSpace", "mode_state_space", "offset_input_name"]


@dataclass(frozen=True)
class ModeStateSpace:
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    e: np.ndarray
    c: float
    poles: np.ndarray

    @property
    def max_pole_modulus(self) -> float:
        """Largest pole modulus (0 for a static mode); below 1 is stable."""
        return float(np.max(np.abs(self.poles))) if self.poles.size else 0.0

    @property
    def stable(self) -> bool:
        """Schur stable: every pole strictly inside the unit circle."""
        return self.max_pole_modulus < 1.0


def mode_state_space(structure, theta: np.ndarray) -> ModeStateSpace:
    """State-space matrices (eq. 7) of one mode ``theta`` (length n_features + 1, offset last)."""
    theta = np.asarray(theta, dtype=float)
    na = structure.na
    a = theta[:na]
    m = [nk + nb - 1 if nb > 0 else 0 for nb, nk in zip(structure.nb, structure.nk)]
    n_state = na + sum(m)
    p = structure.n_inputs
    A = np.zeros((n_state, n_state))
    B = np.zeros((n_state, p))
    C = np.zeros(n_state)
    D = np.zeros(p)
    C[:na] = a
    col = na
    offset = na
    for j, (nb, nk) in enumerate(zip(structure.nb, structure.nk)):
        for lag in range(nk, nk + nb):
            coef = theta[col]
            col += 1
            if lag == 0:
                D[j] = coef
            else:
                C[offset + lag - 1] = coef
        if m[j] > 0:
            B[offset, j] = 1.0
            for i in range(1, m[j]):
                A[offset + i, offset + i - 1] = 1.0
        offset += m[j]
    e = np.zeros(n_state)
    if na > 0:
        A[0, :] = C
        B[0, :] = D
        e[0] = theta[-1]
        for i in range(1, na):
            A[i, i - 1] = 1.0
    poles = np.linalg.eigvals(A) if n_state else np.zeros(0)
    poles = poles[np.argsort(-np.abs(poles))]
    return ModeStateSpace(A, B, C.reshape(1, -1), D.reshape(1, -1), e, float(theta[-1]), poles)


def offset_input_name(input_names) -> str:
    """The name of the constant input (held at 1) that carries a mode's offset in an exported
    state space: ``offset``, or ``offset_1``, ``offset_2``, ... when an input has that name (a
    python-control system merges equal labels, and ``sys[:, "offset"]`` took the constant)."""
    taken = set(input_names)
    name, k = "offset", 0
    while name in taken:
        k += 1
        name = f"offset_{k}"
    return name
