"""``switched``: the modes first (switched linear regression), then the regions each mode covers.

Some systems use the same local model on disjoint regions of the regressor space (a valve that
behaves alike at both ends of its stroke, a mode reached from two sides). A segmentation that
looks for ``s`` compact regions with ``s`` distinct models (``alternating``) then prefers ``s``
distinct hyperplanes that fit the noise: on the generator's 6 regions sharing 3 parameter sets
(``python -m benchmarks zoo --variants``, ``rand_6m_shared3``) its objective is lower at 50 %
agreement with the true regions than at the truth, and the search keeps a single ARX model.

This method separates the two questions:

1. **modes**: ``n_regions`` is the number ``K`` of distinct local models. Switched linear
   regression (the alternation of :mod:`.alternating` without its separability term: each row goes
   to the model that predicts it best, least squares per model, repeat; several starts) labels every row with its mode; on ``rand_6m_shared3`` it finds the 3 modes at 97 %
   from every start. Rows that two modes predict about equally well (the cost gap
   ``(r_2^2 - r_1^2) / sigma^2`` under ``confidence_margin``) carry no information about where a
   mode lives and are left out of the next step.
2. **regions**: a multicategory linear classifier (eq. 9) must put each row in *some* region of
   its mode. It starts from one region per connected piece of each mode's rows
   (:func:`mode_pieces`: a mode used on regions apart, ``A | B | A | B`` along one direction, is
   several pieces; from one region per mode the classifier cannot separate them, and no single
   split gains: a 4-slab, 2-mode instance stayed at 47 % one-step fit against the 96 % of least
   squares told the modes). Then the region whose rows the classifier most often
   puts into another mode's region is split in two while that raises the share of rows classified into their own mode by
   ``min_gain``. A split is a hard-EM over the region labels (classifier fitted, each row moved to
   the most probable region of its own mode, repeat), started from a cut of the region at the
   median of each principal direction, from k-means, and from the rows the classifier misplaces;
   the starts are screened on ``screen_rows`` rows and the best one is run on all of them. On
   ``rand_6m_shared3`` this recovers the 6 regions (own-mode share 0.99; k-means alone cannot
   split two adjacent cells of one mode, whose union is not convex).

3. **or merges**: where the splits leave the own-mode share under :data:`FULL_SHARE`, the other
   way round is tried too, and kept where its share is ``min_gain`` higher: every piece cut by
   k-means into a few convex parts, hard EM over all of them, then the two adjacent regions of a
   mode (the most rows with one as their most probable region and the other as the second)
   merged whose union the classifier still separates best, while a merge costs under half of
   ``min_gain`` (``info["regions_by"]``: ``"splits"`` or ``"merges"``). Adjacent cells of one
   mode make a region that is connected, so one piece, but not convex; a split of it must find
   the face between the cells, where a merge only has to keep two parts apart: on a 2-D map of 5
   Voronoi cells and 2 modes, validation fit 80.9 % (splits, share 0.988) against 100 % (merges).

The result has ``K`` modes over as many regions as the split made (``info["mode_of_region"]``);
the estimator then learns the partition from these labels and fits one local model per region
(regions of one mode get nearly equal parameters). On large data everything runs on a random
subset of ``SUBSET`` rows, and the final classifier labels the rest.
"""

from __future__ import annotations

import numpy as np

from hwpts.errors import ParameterError
from hwpts.identification.partition.learner import confident_rows, noise_variance
from hwpts.identification.segmentation.alternating import SUBSET, _fit_thetas, alternate
from hwpts.identification.segmentation.base import SegmentationResult, Segmenter, kmeans_labels, standardize


SIGHT_POINTS = (0.25, 0.5, 0.75)  # where along a link of mode_pieces the nearest row must be of the link's mode
EM_SETTLED = 0.002  # share of the rows whose move no longer counts: the hard EM has settled
FULL_SHARE = 0.999  # own-mode share past which neither a split nor the merge path is tried
# the merge path (SwitchedSegmenter._merged_regions), tried where the splits leave the own-mode
# share under FULL_SHARE: up to OVERSEGMENT k-means parts per piece, MERGE_START_STEPS hard-EM
# steps over them, the MERGE_PAIRS most adjacent same-mode pairs tried at each merge,
# MERGE_EM_STEPS hard-EM steps each (the classifier's fits are the path's time: on 20,000 rows
# of 6 cells and 3 modes, 3 steps each and 20 at the start took 1.5-3 s a fit, these 0.6-1.0 s,
# with each trial warm-started). A few misplaced rows cost much fit where the modes predict far
# apart: on a 2-D map with 5 Voronoi cells and 2 modes the splits stopped at an own-mode share of
# 0.973 and a validation fit of 49.9 %, the merges reached 0.993 and 80.9 %, so the path is tried
# up to FULL_SHARE, not only where the share is poor
OVERSEGMENT = 3
MERGE_PAIRS = 3
MERGE_START_STEPS = 5
MERGE_EM_STEPS = 1


def switched_regression(Z, ys, K, rng, n_restarts=5, max_iter=20):
    """``(labels, mean squared residual)`` of the best of ``n_restarts`` switched linear
    regressions of ``ys`` on the standardised regressors ``Z`` with ``K`` models (the alternation
    of :mod:`.alternating` without its separability term, at most ``max(50, 5 max_iter)`` steps)."""
    n = Z.shape[0]
    Phi = np.hstack([Z, np.ones((n, 1))])
    best = None
    for r in range(int(n_restarts)):
        # the first start from k-means of [z, y], the others from random labels: k-means starts
        # are alike (on one rand_6m_shared3 subset three of them ended in the same poor
        # minimum, mean squared residual 0.070 against 0.0018; random labels reached 0.0018
        # 11 times in 12)
        init = (kmeans_labels(np.column_stack([Z, ys]), K, rng, n_init=1) if r == 0
                else rng.integers(0, K, n).astype(np.int64))
        labels, objective, _ = alternate(Phi, ys, Z, init, K, 0.0, max(50, 5 * int(max_iter)))
        if best is None or objective < best[1]:
            best = (labels, objective)
    return best[0], float(best[1])


def _hard_em(Z, regions, owner, mode, k, max_iter, init=None):
    """Region labels of the rows ``Z`` (each in a region of its own ``mode``; ``owner[r]`` is
    region ``r``'s mode) by hard EM: fit the classifier, move each row to its own mode's most
    probable region, until nothing moves; ``init`` a classifier or its scores ``(W, b)`` to start
    from (used where it has ``k`` regions). Returns (labels, classifier)."""
    from hwpts.identification.partition import fit_linear_partition

    start = getattr(init, "scores", init)
    for _ in range(max(1, int(max_iter))):
        part = fit_linear_partition(Z, regions, k, init=start if start is not None and len(start[0]) == k else None)
        start = part.scores
        logp = part.log_proba(Z)
        logp = np.where(owner[None, :] == mode[:, None], logp, -np.inf)
        new = np.argmax(logp, axis=1)
        moved = int(np.count_nonzero(new != regions))
        regions = new
        if moved <= EM_SETTLED * regions.size:
            break
    return regions, part


def mode_pieces(Z, mode, K, n_neighbors, min_rows):
    """``(owner, piece)``: the connected pieces of each mode's rows, ``piece[i]`` row ``i``'s and
    ``owner[j]`` piece ``j``'s mode. Two rows of one mode are linked when each is among the
    other's ``n_neighbors`` nearest rows (all modes counted), both are core rows (most of their
    nearest rows of their mode) and the row nearest each of :data:`SIGHT_POINTS` along the link
    (its two ends aside) is of their mode too: a mode used on two regions apart (a
    slab of another mode between them) falls into two pieces, which a linear classifier started
    from one region per mode cannot separate (``A | B | A | B`` along one direction: own-mode share
    0.57 from that start). Pieces of fewer than ``min_rows`` rows (stray labels inside another
    mode's region) join the nearest large piece of their mode; a mode without a large piece keeps
    its largest. Adjacent regions of one mode stay one piece: the splits or the merges separate them.
    (Links from either side, not mutual, joined two slabs of A across a slab of B on 2 of 3 data
    sets of a 5-slab instance, through the sparse corners of the regressor space.)"""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = Z.shape[0]
    c = min(int(n_neighbors) + 1, n)
    # scipy's k-d tree, not scikit-learn's NearestNeighbors: the same neighbours without the
    # estimator's validation and joblib dispatch on each of the ~120 queries of a search
    tree = cKDTree(Z)
    idx = tree.query(Z, k=c)[1].reshape(n, c)
    # core rows: most of their nearest rows are of their mode (a stray label inside another
    # mode's region is not one, and would otherwise link two pieces across that region)
    core = np.mean(mode[idx[:, 1:]] == mode[:, None], axis=1) > 0.5 if c > 1 else np.ones(n, bool)
    src = np.repeat(np.arange(n), c)
    dst = idx.ravel()
    same = (mode[src] == mode[dst]) & (src != dst) & core[src] & core[dst]
    src, dst = src[same], dst[same]
    # a link holds only if the rows nearest the SIGHT_POINTS along it are of its mode: where the
    # rows are sparse, a row's nearest rows of its mode may lie across another mode's slab
    sight = np.ones(src.size, dtype=bool)
    for t in (SIGHT_POINTS if src.size else ()):
        near = tree.query((1.0 - t) * Z[src] + t * Z[dst], k=min(3, n))[1].reshape(src.size, -1)
        other = (near != src[:, None]) & (near != dst[:, None])  # the link's own ends do not count
        mid = near[np.arange(near.shape[0]), np.argmax(other, axis=1)]
        sight &= (mode[mid] == mode[src]) | ~other.any(axis=1)
    graph = coo_matrix((np.ones(int(sight.sum())), (src[sight], dst[sight])), shape=(n, n)).tocsr()
    graph = graph.minimum(graph.T)  # mutual neighbours only: a row in a sparse corner reaches far
    _, comp = connected_components(graph, directed=False)
    sizes = np.bincount(comp)
    keep = (sizes[comp] >= min_rows) & core
    for m in range(K):  # every mode keeps at least its largest piece
        own = mode == m
        if own.any() and not np.any(keep & own):
            keep |= comp == comp[own][np.argmax(sizes[comp[own]])]
    piece = np.full(n, -1)
    kept, piece[keep] = np.unique(comp[keep], return_inverse=True)
    _, first_row = np.unique(comp, return_index=True)  # (components are numbered 0, 1, ...)
    owner = mode[first_row[kept]].astype(np.int64)
    for m in range(K):  # the rows of small pieces join the nearest large piece of their mode
        stray = np.flatnonzero((mode == m) & ~keep)
        home = np.flatnonzero((mode == m) & keep)
        if stray.size and home.size:
            near = cKDTree(Z[home]).query(Z[stray], k=1)[1].reshape(-1)
            piece[stray] = piece[home[near]]
    return owner, piece


def _own_mode_share(part, Z, owner, mode) -> float:
    """Share of the rows the classifier puts into a region of their own mode."""
    return float(np.mean(owner[part.predict(Z)] == mode))


def _no_worse(last, screened, screened_share, Z, owner, mode):
    """``(classifier, own-mode share)``: ``last``, the classifier after a last hard EM on all rows
    ``Z``, where its share is at least that of ``screened``, the classifier it started from (found
    on the screened rows, whose share on ``Z`` is ``screened_share``); else ``screened``. The hard EM climbs the classifier's likelihood of the
    region labels, not the share: on one ``rand_vor5_d2`` set (``python -m benchmarks zoo
    --variants``) it lowered the share from 0.9917 to 0.9763 and the one-step validation fit from
    98.1 to 92.3 %. Kept only where it does not lose, the variants' medians rose on
    ``rand_vor4_na1`` (88.5 -> 90.5 %), ``rand_abcabc`` (93.5 -> 94.1), ``rand_abab_i2``
    (94.9 -> 96.5) and ``rand_aba_i4`` (95.3 -> 96.4); none fell."""
    share = _own_mode_share(last, Z, owner, mode)
    return (last, share) if share >= screened_share else (screened, screened_share)


class SwitchedSegmenter(Segmenter):
    """Modes by switched linear regression, then the regions of each mode (module doc).

    Parameters
    ----------
    n_restarts : int
        Starts of the switched regression (the first from k-means of ``[z, y]``, the others from
        random labels); the lowest mean squared residual is kept.
    max_regions : int or None
        Most regions in all (default ``3 K``).
    confidence_margin : float
        A row trains the classifier only if its best mode wins by this cost (residual variance
        units), as in the partition learner's boundary refinement.
    min_gain : float
        Least rise of the own-mode share (0-1) for a split to be kept.
    screen_rows : int
        Rows on which the starts of a split are compared.
    max_iter : int
        Steps of the switched regression and of each hard EM.
    n_neighbors : int
        Nearest rows that link two rows of one mode into one piece (:func:`mode_pieces`).
    """

    name = "switched"
    learns_partition = True

    def __init__(self, *, n_restarts: int = 5, max_regions: int | None = None, confidence_margin: float = 4.0,
                 min_gain: float = 0.01, screen_rows: int = 1500, max_iter: int = 20, n_neighbors: int = 10):
        self.n_restarts = n_restarts
        self.max_regions = max_regions
        self.confidence_margin = confidence_margin
        self.min_gain = min_gain
        self.screen_rows = screen_rows
        self.max_iter = max_iter
        self.n_neighbors = n_neighbors

    def check_params(self) -> None:
        """The restarts, rows, iterations, margins and ``max_regions`` (see :meth:`Segmenter.check_params`)."""
        for name, low in (("n_restarts", 1), ("screen_rows", 10), ("max_iter", 1), ("n_neighbors", 1)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
                raise ParameterError(f"switched: {name} must be an int >= {low}, got {value!r}")
        if self.max_regions is not None and (isinstance(self.max_regions, bool)
                                             or not isinstance(self.max_regions, (int, np.integer))
                                             or self.max_regions < 1):
            raise ParameterError(f"switched: max_regions must be None or an int >= 1, got {self.max_regions!r}")
        for name in ("confidence_margin", "min_gain"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) or not value >= 0:
                raise ParameterError(f"switched: {name} must be a number >= 0, got {value!r}")

    def _modes(self, Z, ys, K, rng):
        """Mode labels by switched linear regression (:func:`switched_regression`) and the rows
        each mode predicts clearly better than the others."""
        n = Z.shape[0]
        mode, mse = switched_regression(Z, ys, K, rng, int(self.n_restarts), int(self.max_iter))
        Phi = np.hstack([Z, np.ones((n, 1))])
        theta = _fit_thetas(Phi, ys, mode, K, 1e-8)
        R = (ys[:, None] - Phi @ theta.T) ** 2
        sigma2 = noise_variance(R[np.arange(n), mode])  # ys standardised: the scale is 1
        confident = confident_rows(R / sigma2, mode, self.confidence_margin, K, Z.shape[1] + 1)
        return mode, confident, mse

    def _screen(self, n, rng):
        """The sorted random ``screen_rows`` of ``n`` rows (all of them if fewer) on which starts
        and merges are tried."""
        return np.sort(rng.choice(n, min(n, int(self.screen_rows)), replace=False))

    def _split(self, Z, regions, owner, mode, k, j, wrong_rows, rng, screen):
        """The best two-way split of region ``j`` (see the module doc): (labels, classifier, share)."""
        rows = np.flatnonzero(regions == j)
        centred = Z[rows] - Z[rows].mean(axis=0)
        _, _, Vt = np.linalg.svd(centred, full_matrices=False)
        owner2 = np.append(owner, owner[j])
        starts = [kmeans_labels(Z[rows], 2, rng, n_init=3) == 1, wrong_rows[rows]]
        starts += [centred @ v > np.median(centred @ v) for v in Vt]
        best = None
        for side in starts:
            if side.sum() < 1 or side.all():
                continue
            labels = regions.copy()
            labels[rows[side]] = k
            if np.bincount(labels[screen], minlength=k + 1).min() == 0:
                continue
            _, part = _hard_em(Z[screen], labels[screen], owner2, mode[screen], k + 1, self.max_iter)
            share = _own_mode_share(part, Z, owner2, mode)
            if best is None or share > best[1]:
                best = (part, share)
        if best is None:
            return None
        part = best[0]
        start = part.predict(Z)
        labels, last = _hard_em(Z, start, owner2, mode, k + 1, self.max_iter, init=part)
        kept, share = _no_worse(last, part, best[1], Z, owner2, mode)
        return (labels if kept is last else start), kept, share

    def _regions(self, Z, mode, K, rng, pieces):
        """Regions of the modes (labels of ``Z``'s rows), the classifier, each region's mode and the
        own-mode share after each split, started from one region per piece of ``pieces``
        (:func:`mode_pieces`)."""
        owner, start = pieces
        k = owner.size
        cap = max(int(self.max_regions) if self.max_regions is not None else 3 * K, k)
        regions, part = _hard_em(Z, start, owner, mode, k, self.max_iter)
        share = _own_mode_share(part, Z, owner, mode)
        history = [round(share, 4)]
        screen = self._screen(Z.shape[0], rng)
        p = Z.shape[1] + 1
        while k < cap and share < min(FULL_SHARE, 1.0 - self.min_gain):  # no split can gain more than 1 - share
            predicted = owner[part.predict(Z)]
            wrong = predicted != mode
            counts = np.bincount(regions[wrong], minlength=k)  # each region's rows put into another mode
            j = int(np.argmax(counts))
            if counts[j] == 0 or np.sum(regions == j) < 2 * p:
                break
            split = self._split(Z, regions, owner, mode, k, j, wrong, rng, screen)
            if split is None or split[2] < share + self.min_gain:
                break
            regions, part, share = split
            owner = np.append(owner, owner[j])
            k += 1
            history.append(round(share, 4))
        return part, owner, history

    def _merged_regions(self, Z, mode, rng, pieces):
        """The other way to the regions (module doc): each piece cut by k-means into up to
        :data:`OVERSEGMENT` convex parts, hard EM over all of them, then the two adjacent regions
        of one mode whose union the classifier separates best merged, while a merge costs under
        half of ``min_gain`` of own-mode share; the merges run on ``screen_rows`` rows, the last
        hard EM on all. Returns (classifier, owners, share after each merge)."""
        owner0, piece0 = pieces
        p = Z.shape[1] + 1
        labels = np.empty(Z.shape[0], dtype=np.int64)
        owner = []
        for j in range(owner0.size):
            rows = np.flatnonzero(piece0 == j)
            m = int(min(OVERSEGMENT, max(1, rows.size // (4 * p))))
            part_of = kmeans_labels(Z[rows], m, rng, n_init=3) if m > 1 else np.zeros(rows.size, dtype=np.int64)
            for c in np.unique(part_of):
                labels[rows[part_of == c]] = len(owner)
                owner.append(owner0[j])
        owner = np.asarray(owner, dtype=np.int64)
        screen = self._screen(Z.shape[0], rng)
        Zs, ms = Z[screen], mode[screen]
        regions, part = _hard_em(Zs, labels[screen], owner, ms, owner.size, MERGE_START_STEPS)
        history = []
        while True:
            used, renumbered = np.unique(regions, return_inverse=True)
            if used.size < owner.size:  # regions the hard EM emptied are dropped
                owner = owner[used]
                regions, part = _hard_em(Zs, renumbered, owner, ms, owner.size, self.max_iter)
            share = _own_mode_share(part, Z, owner, mode)
            history.append(round(share, 4))
            k = owner.size
            if k < 2:
                break
            # adjacency: rows whose two most probable regions are a and b
            top2 = np.argsort(-part.log_proba(Zs), axis=1)[:, :2]
            adjacent = np.zeros((k, k))
            np.add.at(adjacent, (top2[:, 0], top2[:, 1]), 1.0)
            adjacent += adjacent.T
            pairs = sorted(((adjacent[a, b], a, b) for a in range(k) for b in range(a + 1, k)
                            if owner[a] == owner[b] and adjacent[a, b] > 0), reverse=True)[:MERGE_PAIRS]
            best = None
            for _, a, b in pairs:
                trial = np.where(regions == b, a, regions)
                trial[trial > b] -= 1
                kept = np.delete(owner, b)
                warm = tuple(np.delete(v, b, axis=0) for v in part.scores)  # region b's scores dropped
                trial, trial_part = _hard_em(Zs, trial, kept, ms, k - 1, MERGE_EM_STEPS, init=warm)
                gain = _own_mode_share(trial_part, Z, kept, mode)
                if best is None or gain > best[0]:
                    best = (gain, b, trial, trial_part)
            if best is None or best[0] < share - self.min_gain / 2.0:
                break
            _, b, regions, part = best
            owner = np.delete(owner, b)
        # all rows: each to its own mode's most probable region, then hard EM
        logp = np.where(owner[None, :] == mode[:, None], part.log_proba(Z), -np.inf)
        _, last = _hard_em(Z, np.argmax(logp, axis=1), owner, mode, owner.size, self.max_iter, init=part)
        part, share = _no_worse(last, part, share, Z, owner, mode)
        history.append(round(share, 4))
        return part, owner, history

    def segment(self, X, y, n_regions, structure, rng) -> SegmentationResult:
        """Labels of ``n_regions`` modes over the regions each covers (see the module docstring)."""
        X, y, rng = self._check_rows(X, y, rng)
        self.check_params()
        self._check_regions(n_regions, X.shape[0])
        K = int(n_regions)
        n = X.shape[0]
        if K == 1:
            return SegmentationResult(np.zeros(n, dtype=np.int64), 1, info={"modes": 1, "mode_of_region": [0]})
        Z = standardize(X)
        ys = (y - y.mean()) / (y.std() or 1.0)
        idx = np.arange(n) if n <= SUBSET else np.sort(rng.choice(n, SUBSET, replace=False))
        mode, confident, objective = self._modes(Z[idx], ys[idx], K, rng)
        rows = idx[confident]
        pieces = mode_pieces(Z[rows], mode[confident], K, int(self.n_neighbors),
                             max(2 * (Z.shape[1] + 1), rows.size // 100))
        part, owner, history = self._regions(Z[rows], mode[confident], K, rng, pieces)
        how = "splits"
        if history[-1] < FULL_SHARE:
            merged = self._merged_regions(Z[rows], mode[confident], rng, pieces)
            if merged[2][-1] >= history[-1] + self.min_gain:
                (part, owner, history), how = merged, "merges"
        labels = part.predict(Z)
        used = np.unique(labels)  # regions the final classifier never chooses are dropped
        remap = np.full(owner.size, -1)
        remap[used] = np.arange(used.size)
        return SegmentationResult(remap[labels], int(used.size),
                                  info={"modes": K, "mode_of_region": [int(owner[r]) for r in used],
                                        "own_mode_share": history, "regions_by": how, "objective": objective})


def switched_fit_percent(X, y, n_modes: int, rng, n_restarts: int = 5) -> float:
    """In-sample one-step fit % of the best switched linear regression with ``n_modes`` models on
    the regressors ``X`` and targets ``y`` (each row predicted by the model that predicts it best;
    at most ``SUBSET`` rows): the least misfit any segmentation into ``n_modes`` models can reach
    on these rows, whatever the regions (the model search compares it with its candidates' to see
    whether modes exist that its regions miss)."""
    n = X.shape[0]
    idx = np.arange(n) if n <= SUBSET else np.sort(rng.choice(n, SUBSET, replace=False))
    Z = standardize(X[idx])
    ys = (y[idx] - y[idx].mean()) / (y[idx].std() or 1.0)
    if n_modes == 1:
        Phi = np.hstack([Z, np.ones((idx.size, 1))])
        theta = _fit_thetas(Phi, ys, np.zeros(idx.size, dtype=np.int64), 1, 1e-8)
        mse = float(np.mean((ys - Phi @ theta[0]) ** 2))
    else:
        _, mse = switched_regression(Z, ys, int(n_modes), rng, n_restarts)
    return 100.0 * (1.0 - np.sqrt(max(mse, 0.0)))
