"""Small dense linear systems in compiled kernels, shared by the plant's integrator and the
identification's alternation (neither imports the other).

``np.linalg.solve`` inside a numba kernel brings numba's LAPACK bindings and their error
formatting into the kernel's first compilation, for systems of a few unknowns: the alternating
segmenter's kernel took 8.9 s to compile with it, 4.3 s with these loops (``hwpts reproduce
--quick`` from an empty cache: 18.2 -> 13.9 s).
"""

from __future__ import annotations

import math

import numba


@numba.njit(cache=True)
def lu_factor(a, piv):  # pragma: no cover - compiled
    """LU factors of the square ``a`` in place, with partial pivoting (LAPACK ``getrf``'s steps):
    ``piv[k]`` the row swapped with row ``k``; False where a pivot is zero or not finite."""
    n = a.shape[0]
    for k in range(n):
        p = k
        big = abs(a[k, k])
        for i in range(k + 1, n):
            if abs(a[i, k]) > big:
                big = abs(a[i, k])
                p = i
        piv[k] = p
        if big == 0.0 or not math.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                tmp = a[k, j]
                a[k, j] = a[p, j]
                a[p, j] = tmp
        for i in range(k + 1, n):
            a[i, k] /= a[k, k]
            f = a[i, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    a[i, j] -= f * a[k, j]
    return True


@numba.njit(cache=True)
def lu_solve(a, piv, b):  # pragma: no cover - compiled
    """``b = A^-1 b`` in place from :func:`lu_factor`'s ``a`` and ``piv`` (``getrs``)."""
    n = b.shape[0]
    for k in range(n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for i in range(n):
        s = b[i]
        for j in range(i):
            s -= a[i, j] * b[j]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= a[i, j] * b[j]
        b[i] = s / a[i, i]
