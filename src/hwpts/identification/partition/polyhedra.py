"""Polyhedral partitions of the regressor set (paper eqs. 8-10).

A :class:`RegionPartition` holds, for each region ``i``, the polyhedron (paper eq. 9)::

    chi_i = {x : H_i x + g_i <= 0}

over the standard regression vector ``x_k`` (eq. 7). A regressor belongs to the *first* region
whose inequalities all hold (so boundaries shared by two closed polyhedra go to the lower index);
a regressor outside every polyhedron (possible only through rounding, or outside the domain of a
user-given partition) goes to the region it violates least. The discrete mode of eq. 8 is
``sigma(k) = predict(x_k)``.

Partitions come from a multicategory linear classifier trained on labelled regressors
(:func:`fit_linear_partition`: region ``i`` = {x : s_i(x) >= s_j(x) for all j}, with linear scores
``s_i(x) = w_i' x + b_i``, which is a polyhedron), or from user-given hyperplanes
(:func:`hyperplane_partition`, the paper's fracture line of eq. 16).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from hwpts.errors import DataError, ParameterError
from hwpts.identification.partition.logistic import newton_logistic
from hwpts.text import plain_float

__all__ = ["RegionPartition", "fit_linear_partition", "hyperplane_partition", "Hyperplane"]


class RegionPartition:
    """A complete partition of the regressor set into convex polyhedra (paper eq. 9).

    Parameters
    ----------
    H : list of ndarray, shape (q_i, n_features)
    g : list of ndarray, shape (q_i,)
        Region ``i`` is ``{x : H[i] @ x + g[i] <= 0}``. A region with ``q_i = 0`` is everything.
    kind : str
        How it was built (``"linear-classifier"``, ``"hyperplanes"``, ``"single"``); informative.
    """

    def __init__(self, H: Sequence[np.ndarray], g: Sequence[np.ndarray], kind: str = "polyhedra"):
        if len(H) != len(g) or len(H) == 0:
            raise ParameterError(f"a partition needs as many H as g blocks (>= 1); got {len(H)}, {len(g)}")
        Hs = [np.atleast_2d(np.asarray(h, dtype=float)) for h in H]
        n = {h.shape[1] for h in Hs if h.size}
        if len(n) > 1:
            raise ParameterError(f"polyhedra over different dimensions: {sorted(n)}")
        self.n_features = n.pop() if n else None
        if self.n_features is None:
            self.n_features = Hs[0].shape[1] if Hs[0].ndim == 2 else 0
        # (no features: a block of no rows, which reshape(-1, 0) cannot size)
        self.H = [h.reshape(-1, self.n_features) if self.n_features else h.reshape(h.shape[0], 0) for h in Hs]
        self.g = [np.asarray(gi, dtype=float).reshape(-1) for gi in g]
        for i, (h, gi) in enumerate(zip(self.H, self.g)):
            if h.shape[0] != gi.shape[0]:
                raise ParameterError(f"region {i + 1}: H has {h.shape[0]} rows but g has {gi.shape[0]}")
            if not (np.all(np.isfinite(h)) and np.all(np.isfinite(gi))):
                raise ParameterError(f"region {i + 1}: non-finite polyhedron coefficients")
        self.kind = kind
        self.scores = None  # (W, b) of the linear classifier when learned: s(x) = W x + b
        # (column, ascending thresholds) when region i is {t_(i-1) < x_column <= t_i} (a threshold
        # partition): predict is then one sorted search of a column instead of every inequality
        self.cuts = None

    def log_proba(self, X: np.ndarray) -> np.ndarray | None:
        """Log class probabilities (softmax of the classifier scores), or None if not learned."""
        if self.scores is None:
            return None
        W, b = self.scores
        S = np.asarray(X, dtype=float) @ W.T + b
        S -= S.max(axis=1, keepdims=True)
        return S - np.log(np.exp(S).sum(axis=1, keepdims=True))

    @classmethod
    def single(cls, n_features: int) -> RegionPartition:
        """The trivial partition: one region, the whole regressor set (plain ARX)."""
        return cls([np.zeros((0, n_features))], [np.zeros(0)], kind="single")

    @property
    def n_regions(self) -> int:
        """Number of regions (polyhedra)."""
        return len(self.H)

    def violations(self, X: np.ndarray) -> np.ndarray:
        """Largest constraint value max_q (H_i x + g_i)_q per sample and region, shape (n, s)."""
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != self.n_features:
            raise DataError(f"regressors must have shape (n, {self.n_features}); got {X.shape}")
        out = np.full((X.shape[0], self.n_regions), -np.inf)
        for i, (h, gi) in enumerate(zip(self.H, self.g)):
            if h.shape[0]:
                out[:, i] = (X @ h.T + gi).max(axis=1)
        return out

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Region index (0-based) of each regressor row: first polyhedron containing it (eq. 8).

        For a learned partition, whose region ``i`` is ``{x : s_i(x) >= s_j(x) for all j}``, that
        is the first largest classifier score: ``s`` scores a row instead of ``s (s - 1)``
        inequalities (the same region but where two scores tie to rounding)."""
        if self.scores is not None and self.kind == "linear-classifier":
            X = np.asarray(X, dtype=float)
            if X.ndim != 2 or X.shape[1] != self.n_features:
                raise DataError(f"regressors must have shape (n, {self.n_features}); got {X.shape}")
            W, b = self.scores
            return np.argmax(X @ W.T + b, axis=1).astype(np.int64)
        if self.cuts is not None:
            X = np.asarray(X, dtype=float)
            if X.ndim == 2 and X.shape[1] == self.n_features:
                column, t = self.cuts
                x = X[:, column]
                if np.all(np.isfinite(x)):  # the unique region holding x: how many cuts lie below it
                    return np.searchsorted(t, x, side="left").astype(np.int64)
        v = self.violations(X)
        inside = v <= 0.0
        first = np.argmax(inside, axis=1)
        none = ~inside.any(axis=1)
        if none.any():
            first[none] = np.argmin(v[none], axis=1)
        return first.astype(np.int64)

    def shifted(self, m: np.ndarray) -> RegionPartition:
        """The same regions over ``x - m``: a row ``x_s`` lies in region ``i`` of the copy
        exactly when ``x_s + m`` lies in region ``i`` of this partition (``g + H m``, the
        classifier's ``b + W m``, the cuts less ``m`` of their column)."""
        m = np.asarray(m, dtype=float)
        out = RegionPartition([h.copy() for h in self.H], [gi + h @ m for h, gi in zip(self.H, self.g)],
                              kind=self.kind)
        if self.scores is not None:
            W, b = self.scores
            out.scores = (np.array(W, dtype=float), np.asarray(b, dtype=float) + np.asarray(W, dtype=float) @ m)
        if self.cuts is not None:
            column, t = self.cuts
            out.cuts = (column, np.asarray(t, dtype=float) - m[column])
        return out

    def flat(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stacked rows for compiled loops: H_all (R, n), g_all (R,), row_start (s + 1,)."""
        counts = [h.shape[0] for h in self.H]
        row_start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        H_all = np.vstack(self.H) if sum(counts) else np.zeros((0, self.n_features))
        g_all = np.concatenate(self.g) if sum(counts) else np.zeros(0)
        return np.ascontiguousarray(H_all, dtype=float), np.ascontiguousarray(g_all, dtype=float), row_start

    def to_dict(self) -> dict:
        """JSON-ready form: the kind, the assignment rule and each polyhedron's ``H`` and ``g`` (eq. 9)."""
        return {
            "kind": self.kind,
            "rule": "first region i with H_i x + g_i <= 0; else the least violated",
            "polyhedra": [{"H": h.tolist(), "g": gi.tolist()} for h, gi in zip(self.H, self.g)],
        }

    @classmethod
    def from_dict(cls, d: dict, n_features: int) -> RegionPartition:
        """The partition from :meth:`to_dict`'s form over ``n_features`` regressors."""
        H = [np.asarray(p["H"], dtype=float).reshape(-1, n_features) for p in d["polyhedra"]]
        g = [np.asarray(p["g"], dtype=float) for p in d["polyhedra"]]
        return cls(H, g, kind=str(d.get("kind", "polyhedra")))

    def __repr__(self) -> str:
        rows = [h.shape[0] for h in self.H]
        return f"RegionPartition(kind={self.kind!r}, n_regions={self.n_regions}, rows={rows})"


def scores_to_partition(W: np.ndarray, b: np.ndarray, kind: str = "linear-classifier") -> RegionPartition:
    """Region i = {x : s_i(x) >= s_j(x) for all j} of linear scores s = W x + b, as polyhedra (eq. 9)."""
    s = W.shape[0]
    H, g = [], []
    for i in range(s):
        others = [j for j in range(s) if j != i]
        H.append(W[others] - W[i])
        g.append(b[others] - b[i])
    return RegionPartition(H, g, kind=kind)


def varying_columns(X: np.ndarray, sd: np.ndarray) -> np.ndarray:
    """Which columns of ``X`` (standard deviations ``sd``) vary: a spread above 1e-12 of the column's
    largest value. A constant column's rounding (a std of 5e-16 for a column of 0.1) is no signal to
    scale up; relative to the column's own size, signals of 1e-12 (a current in A) still vary."""
    return sd > 1e-12 * np.abs(X).max(axis=0, initial=0.0)


def fit_linear_partition(X: np.ndarray, labels: np.ndarray, n_regions: int, C: float = 1e4,
                         max_iter: int = 500, columns=None, init=None) -> RegionPartition:
    """Multicategory linear classifier of regressors into regions, returned as polyhedra (eq. 9).

    Multinomial logistic regression (scikit-learn's objective, solved by Newton's method in
    :mod:`.logistic`, scikit-learn as the fallback) on standardised regressors; the scores
    are mapped back to the raw coordinates so the polyhedra apply to ``x_k`` directly. Labels must
    be ``0 .. n_regions-1``; a label without samples gets an empty region (never chosen).
    ``columns`` (indices) restricts the classifier to some regressors (the others get zero weight).
    ``init``: a partition (or its scores ``(W, b)``) over the same regions whose classifier starts
    the Newton iterations (a warm start: the boundary refinement refits a classifier that moves
    little, and from the previous one Newton needs a third of the iterations; the optimum is the
    same, to the solver's tolerance). Ignored when a present label had no region in it.
    """
    X = np.asarray(X, dtype=float)
    labels = np.asarray(labels, dtype=np.int64)
    present = np.unique(labels)
    nf = X.shape[1]
    if n_regions == 1:
        return RegionPartition.single(nf)
    if isinstance(init, RegionPartition):
        init = init.scores
    if columns is not None:
        cols = np.asarray(columns, dtype=np.int64)
        sub_init = None if init is None else (np.asarray(init[0])[:, cols], init[1])
        sub = fit_linear_partition(X[:, cols], labels, n_regions, C, max_iter, init=sub_init)
        W = np.zeros((n_regions, nf))
        W[:, cols] = sub.scores[0]
        partition = scores_to_partition(W, sub.scores[1])
        partition.scores = (W, sub.scores[1])
        return partition
    mean = X.mean(axis=0)
    sd = X.std(axis=0)
    sd[~varying_columns(X, sd)] = 1.0  # a constant column is not scaled up
    Z = (X - mean) / sd
    W = np.zeros((n_regions, nf))
    b = np.full(n_regions, -1e6)  # absent labels: a score that never wins
    if present.size == 1:
        b[present[0]] = 0.0
    else:
        start = _start(init, present, mean, sd)
        # Newton with the Hessian in one product (partition.logistic); scikit-learn where it cannot step
        coef0, icpt0 = (None, None) if start is None else start
        fitted = newton_logistic(Z, np.searchsorted(present, labels), present.size, C, tol=1e-8,
                                 max_iter=100, coef=coef0, intercept=icpt0)
        if fitted is None:
            fitted = _sklearn_logistic(Z, labels, C, max_iter, start)
        coef, icpt = fitted[0], fitted[1]
        if coef.shape[0] == 1:  # binary: score 0 for the first class, w'z + b for the second
            coef = np.vstack([np.zeros_like(coef), coef])
            icpt = np.concatenate([[0.0], icpt])
        for row, cls_label in enumerate(present):
            W[cls_label] = coef[row] / sd
            b[cls_label] = icpt[row] - np.dot(coef[row], mean / sd)
    partition = scores_to_partition(W, b)
    partition.scores = (W, b)
    return partition


def _sklearn_logistic(Z, labels, C, max_iter, start):
    """(coef, intercept) of scikit-learn's LogisticRegression on the standardised rows ``Z``,
    started from ``start`` (see :func:`_start`) where given."""
    from sklearn.linear_model import LogisticRegression

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ConvergenceWarning on separable data is harmless here
        try:  # Newton-Cholesky: multinomial since scikit-learn 1.6, fast for few features
            clf = LogisticRegression(C=C, solver="newton-cholesky", max_iter=100, tol=1e-8)
            if start is not None:
                clf.set_params(warm_start=True)
                clf.coef_, clf.intercept_ = start
            clf.fit(Z, labels)
        except ValueError:  # older scikit-learn: L-BFGS
            clf = LogisticRegression(C=C, max_iter=max_iter, tol=1e-8).fit(Z, labels)
    return clf.coef_, clf.intercept_


def _start(init, present, mean, sd):
    """The raw-coordinate scores ``init = (W, b)`` of a previous classifier over the same regions
    as a start on rows standardised by ``mean``, ``sd`` (scikit-learn's shapes: one score for two
    classes), or None where they do not cover ``present``."""
    if init is None:
        return None
    W, b = (np.asarray(a, dtype=float) for a in init)
    if W.ndim != 2 or W.shape[1] != mean.size or present.max() >= W.shape[0] or np.any(b[present] < -1e5):
        return None  # another shape, or a present label that had no region: no useful start
    coef = W[present] * sd  # scores in the standardised coordinates of these rows
    icpt = b[present] + W[present] @ mean
    if present.size == 2:  # binary: one score, the second class's minus the first's
        coef, icpt = coef[1:] - coef[:1], icpt[1:] - icpt[:1]
    return coef, icpt


class Hyperplane:
    """A half-space ``sum_j a_j * x[col_j] + c >= 0`` on named regressor (or input) columns."""

    def __init__(self, coefficients: Sequence[float], offset: float, columns: Sequence[str] | None = None):
        self.coefficients = tuple(float(a) for a in coefficients)
        self.offset = float(offset)
        self.columns = None if columns is None else tuple(str(c) for c in columns)
        if not self.coefficients:
            raise ParameterError("a hyperplane needs at least one coefficient")
        if not all(np.isfinite(self.coefficients)) or not np.isfinite(self.offset) \
                or max(map(abs, (*self.coefficients, self.offset))) > 1e100:  # the model file's bound
            raise ParameterError(f"hyperplane coefficients must be finite and within +-1e100, got {self}")
        for c in self.columns or ():
            if "," in c or "@" in c or c != c.strip():  # the model file writes "a,b,c@col1,col2"
                raise ParameterError(f"a hyperplane's column name cannot hold ',' or '@' or surrounding spaces "
                                     f"(written as 'a,b,c@col1,col2'), got {c!r}; rename the column")
        if self.columns is not None and len(self.columns) != len(self.coefficients):
            raise ParameterError(
                f"hyperplane {self}: {len(self.coefficients)} coefficients for {len(self.columns)} columns"
            )

    @classmethod
    def parse(cls, text: str) -> Hyperplane:
        """Parse ``"a,b,c"`` (a*x1 + b*x2 + c >= 0) or ``"a,b,c@col1,col2"`` (named columns).

        Without ``@``, the columns are the first inputs in order (``"a,c"`` uses the first input).
        """
        body, at, cols = str(text).partition("@")
        fields = [v.strip() for v in body.split(",")]
        try:
            if any(not v for v in fields):  # an empty field would shift the others
                raise ValueError
            numbers = [plain_float(v) for v in fields]
        except ValueError:
            raise ParameterError(
                f"hyperplane {text!r}: expected numbers 'a,b,c' meaning a*x1 + b*x2 + c >= 0"
            ) from None
        if len(numbers) < 2:
            raise ParameterError(f"hyperplane {text!r}: expected at least 'a,c' (a*x1 + c >= 0)")
        columns = [c.strip() for c in cols.split(",")] if at else None
        if columns is not None:
            if any(not c for c in columns):
                raise ParameterError(f"hyperplane {text!r}: an empty column name after '@' (expected 'a,b,c@col1,col2')")
            if len(set(columns)) != len(columns):
                raise ParameterError(f"hyperplane {text!r}: a column is named twice after '@'")
        return cls(numbers[:-1], numbers[-1], columns)

    def resolve(self, structure) -> tuple[np.ndarray, float]:
        """Coefficient vector over x_k (zeros on other columns) and the offset."""
        if self.columns is None:
            if len(self.coefficients) > structure.n_inputs:
                raise ParameterError(
                    f"hyperplane {self} has {len(self.coefficients)} coefficients but the model has "
                    f"{structure.n_inputs} input(s); name the columns with '@col1,col2'"
                )
            index = [structure.input_column(j) for j in range(len(self.coefficients))]  # by position
        else:
            index = [structure.column_index(col) for col in self.columns]
        a = np.zeros(structure.n_features)
        for coef, i in zip(self.coefficients, index):
            a[i] += coef
        return a, self.offset

    def to_dict(self) -> dict:
        """JSON-ready form: coefficients, offset and the columns they apply to."""
        return {"coefficients": list(self.coefficients), "offset": self.offset,
                "columns": None if self.columns is None else list(self.columns)}

    def __repr__(self) -> str:
        terms = " + ".join(
            f"{a:g}*{c}" for a, c in zip(self.coefficients, self.columns or [f"x{i + 1}" for i in range(len(self.coefficients))])
        )
        return f"{terms} + {self.offset:g} >= 0"


def hyperplane_partition(hyperplanes: Sequence[Hyperplane], structure) -> RegionPartition:
    """Partition from an ordered list of hyperplanes h_1..h_m, as a decision list (m + 1 regions).

    Region ``j`` (``j = 1..m``) is where ``h_j(x) >= 0`` and no earlier hyperplane holds; region
    ``m + 1`` is where none holds. Every region is an intersection of half-spaces, hence a convex
    polyhedron of eq. 9. The paper's partition (eq. 16 and ``h_i >= 3.5 V``) is
    ``[Hyperplane([1], -3.5, ["h"]), Hyperplane([486.41, 1], -1755.2, ["h", "wp"])]``: region 1 the
    zero mode, region 2 above the fracture line, region 3 below it.
    """
    if not hyperplanes:
        raise ParameterError("hyperplane segmentation needs at least one hyperplane")
    resolved = [hp.resolve(structure) for hp in hyperplanes]
    H, g = [], []
    for j in range(len(resolved) + 1):
        rows, offs = [], []
        for i in range(min(j, len(resolved))):  # earlier hyperplanes do not hold: h_i(x) <= 0
            rows.append(resolved[i][0])
            offs.append(resolved[i][1])
        if j < len(resolved):  # this one holds: -h_j(x) <= 0
            rows.append(-resolved[j][0])
            offs.append(-resolved[j][1])
        H.append(np.array(rows).reshape(-1, structure.n_features))
        g.append(np.array(offs, dtype=float))
    return RegionPartition(H, g, kind="hyperplanes")
