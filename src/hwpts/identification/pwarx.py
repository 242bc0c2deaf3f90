"""The PWARX estimator (paper section IV): segmentation, region estimation, local least squares.

A PWARX model (paper eqs. 5-11) is ``y_k = phi_k' theta_sigma(k) + e_k`` with ``sigma(k) = i`` when
the regressor ``x_k`` (eq. 7) lies in the polyhedron ``chi_i = {x : H_i x + g_i <= 0}`` (eq. 9).
:class:`PWARX` estimates it in three steps:

1. **segmentation**: a method from the registry assigns the training samples to regions;
2. **region estimation**: a multicategory linear classifier turns the labels into polyhedra
   (eq. 9), then a few rounds of *boundary refinement* move samples to the mode that fits them
   best (weighted by the classifier's confidence) and refit the classifier;
3. **regression**: least squares per region (eq. 17), with optional ridge, or constant / zero modes.

It follows the scikit-learn estimator contract (``__init__`` stores, ``fit`` returns ``self``,
learned attributes end in ``_``). ``predict`` is one step ahead from measured outputs, ``simulate``
is the free run with the switching rule, ``score`` is the free-run fit %.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from hwpts.dataset import IODataset
from hwpts.errors import DataError, ParameterError
from hwpts.identification.local_models import MODEL_KINDS, fit_local_models
from hwpts.identification.local_models import RegionWarning  # noqa: F401 - the docstrings name it
from hwpts.identification.partition import (
    TRIM,
    PartitionLearner,
    RegionPartition,
    drop_empty_regions,
    fit_linear_partition,
)
from hwpts.identification.regressors import (
    RegressorStructure,
    default_input_names,
    dense_real,
    power_scaling,
    MAX_ABS_VALUE,
    validate_inputs,
    validate_signals,
)
from hwpts.identification.segmentation import make_segmenter
from hwpts.identification.simulation import SimulationResult, k_step_pwarx, one_step_pwarx, simulate_pwarx
from hwpts.identification.statespace import mode_state_space

__all__ = ["PWARX", "FreeRunDivergedWarning"]

MIN_SAMPLE_TIME = 1e-12  # seconds: the least sample time a model (and its file) holds
MAX_RIDGE = 1e12  # ridge 1e308 overflowed the normal equations (a LinAlgError in every candidate)

DIVERGENCE_FACTOR = 50.0


class FreeRunDivergedWarning(UserWarning):
    """A free-run simulation left the plausible output band: the model is unstable there."""


class PWARX(BaseEstimator):
    """Piecewise affine ARX model, MISO (paper eqs. 5-11).

    Parameters
    ----------
    output_order : int or None
        ``na``, number of past outputs in the regressor (eq. 7).
    input_order : int, list of int or None
        ``nb`` per input (samples of each input in the regressor).
    input_delay : int, list of int or None
        ``nk`` per input; ``0`` uses ``u(k)`` as the paper's eq. 18.

        An order left ``None`` (the default) is not given: the model fitted on its own takes 1,
        and :class:`~hwpts.identification.PWARXSearch` chooses it on the data, as ``hwpts
        identify`` does without ``--na``/``--nb``/``--nk`` (:meth:`given_orders`).
    n_regions : int
        Number of regions ``s`` (ignored by ``average``, ``zscore``, ``hyperplane``). A PWARX is
        one model: to choose the number of regions, the method or the orders from the data, wrap
        it in :class:`hwpts.identification.PWARXSearch` (what ``hwpts identify`` does by default).
    segmentation : str or Segmenter
        A name from :data:`hwpts.identification.segmentation.SEGMENTATION_METHODS`, or a segmenter
        instance (a scikit-learn estimator: cloned with the model).
    hyperplanes : sequence of str or Hyperplane, optional
        For ``segmentation="hyperplane"``: ``"a,b,c"`` = ``a*x1 + b*x2 + c >= 0`` on the first
        two inputs, or ``"a,b,c@col1,col2"`` on named regressor/input columns.
    region_models : sequence of str, optional
        ``"affine"`` (default), ``"constant"`` or ``"zero"`` per region (the paper's zero mode).
    constant : bool
        Constant term in each mode (eq. 6); ``False`` gives a piecewise linear model.
    ridge : float
        Ridge penalty of the local least squares (0 = plain eq. 17).
    refinement_rounds : int
        Boundary refinement rounds for learned partitions.
    classifier_C : float
        Inverse regularisation of the multinomial logistic region classifier (a learned partition
        whose classifier misclassifies some of its separable training rows is refitted with a
        vanishing one: :meth:`~hwpts.identification.partition.PartitionLearner.sharpen`).
    segmentation_params : dict, optional
        Keyword parameters of the segmentation method.
    partition_columns : sequence of str, optional
        Regressor columns (names like ``"y(k-1)"`` or input names) the region classifier may use;
        default all. Fewer columns: fewer boundary parameters, better generalisation when the
        switching is known to depend on a few signals (e.g. the output level).
    sparse_partition : bool
        After a learned partition is found, drop the regressor columns its boundaries hardly use
        (standardised weight below 5 % of the largest in every boundary normal) and refit the
        classifier on the rest, if it then classifies its training samples as well. Boundaries
        that depend on a few signals (the paper's fracture line: valve voltage and pump speed) are
        then estimated in that subspace, where the data are dense, instead of carrying noise in
        every other direction.
    max_rows : int or None
        Learned segmentations (clustering, alternating, k-means) label at most this many regressor
        rows drawn at random (seeded); a linear classifier extends their labels to every row, and
        the boundary refinement and the local least squares use every row. The segmentation's cost
        grows with the rows (default ``None``: all rows; :class:`PWARXSearch` uses 5,000 for its
        cross-validation fits, then refits the winner as given).
    classifier_rows : int or None
        Most rows each region classifier of a learned partition is fitted on (the boundary
        refinement's rounds: half nearest the boundaries, half at random; default ``None``: 6,000,
        :class:`~hwpts.identification.partition.PartitionLearner`'s). A multinomial Newton step costs
        in proportion.
    polish : bool
        Refine the local parameters by minimising the free-run simulation error on the training
        data (partition fixed; see :mod:`hwpts.identification.polish`), kept only if better.
    output_powers : sequence of int
        Powers ``p`` (2-9) of the standardised last output, ``((y(k-1) - c) / s)^p`` with the
        training output's mean ``c`` and standard deviation ``s``, appended to every mode's
        regressor: a polynomial term for a nonlinearity that is a smooth function of the output
        (a cubic spring), which affine pieces only approximate and cannot extrapolate. Default
        ``()``: the paper's affine modes. The state-space forms are then the modes' linear parts
        (:mod:`hwpts.identification.regressors`); :class:`PWARXSearch` tries ``(2, 3)`` by default.
    random_state : int, optional
        Seed of the numpy ``Generator`` used by randomised methods.

    Attributes
    ----------
    structure_ : RegressorStructure
    partition_ : RegionPartition
    theta_ : ndarray, shape (n_regions, n_features + 1)
        Parameters per mode, offset last.
    n_regions_ : int
    region_models_ : tuple of str
    region_counts_ : ndarray of int
        Training samples per region.
    training_labels_ : ndarray of int
    input_names_, output_name_ : names
    output_range_ : (float, float)
    input_ranges_ : ndarray, shape (n_inputs, 2)
    segmentation_info_ : dict
    parameter_cov_ : ndarray, shape (n_regions, n_features + 1, n_features + 1)
        Covariance of each mode's parameters from its local least squares (eq. 17),
        ``sigma_i^2 (Phi_i' Phi_i)^-1`` with the region's residual variance; ``nan`` where unknown
        (a region with no more samples than parameters). With ``polish`` or ``ridge`` it is the
        least-squares covariance, an approximation.
    sample_time_ : float or None
        Sample period [s] of the training data, when known (data at another rate are refused by
        the command line).
    units_ : dict
        Units of the signals by name, when known.
    condition_ : ndarray, shape (n_regions,)
        Condition number of each region's (column-scaled) least-squares matrix (``nan`` where not
        fitted); a :class:`RegionWarning` names a region beyond 1e10.
    n_features_in_ : int
        Number of inputs (scikit-learn's name).

    Examples
    --------
    A system that switches where its input changes sign, identified with a threshold:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> u = rng.uniform(-1, 1, 300)
    >>> y = np.zeros(300)
    >>> for k in range(1, 300):
    ...     y[k] = (0.5 * y[k-1] + u[k-1] + 0.2) if u[k-1] >= 0 else (-0.4 * y[k-1] + 2 * u[k-1] - 0.1)
    >>> model = PWARX(1, 1, 1, n_regions=2, segmentation="threshold").fit(u[:, None], y)
    >>> np.round(model.theta_, 3)
    array([[-0.4,  2. , -0.1],
           [ 0.5,  1. ,  0.2]])
    >>> round(model.score(u[:, None], y), 3)
    100.0
    """

    def __init__(self, output_order=None, input_order=None, input_delay=None, n_regions=2,
                 segmentation="clustering", hyperplanes=None, region_models=None, constant=True,
                 ridge=0.0, refinement_rounds=3, classifier_C=1e4, segmentation_params=None,
                 polish=False, partition_columns=None, sparse_partition=True, max_rows=None,
                 classifier_rows=None, output_powers=(), random_state=None):
        self.output_order = output_order
        self.input_order = input_order
        self.input_delay = input_delay
        self.n_regions = n_regions
        self.segmentation = segmentation
        self.hyperplanes = hyperplanes
        self.region_models = region_models
        self.constant = constant
        self.ridge = ridge
        self.refinement_rounds = refinement_rounds
        self.classifier_C = classifier_C
        self.segmentation_params = segmentation_params
        self.polish = polish
        self.partition_columns = partition_columns
        self.sparse_partition = sparse_partition
        self.max_rows = max_rows
        self.classifier_rows = classifier_rows
        self.output_powers = output_powers
        self.random_state = random_state

    # ------------------------------------------------------------------ fitting
    def _signals(self, X, y, names=None, output_name=None):
        if isinstance(X, IODataset):
            if y is not None:
                raise ParameterError("pass either an IODataset or (inputs, output), not both")
            if names is not None or output_name is not None:  # the dataset names its own signals
                raise ParameterError(f"input_names and output_name are the IODataset's own "
                                     f"({list(X.input_names)}, {X.output_name!r}); build the dataset with "
                                     f"the names instead of passing them to fit")
            return X.inputs, X.output, X.input_names, X.output_name
        if y is None:
            raise ParameterError("fit needs the measured output y (or an IODataset)")
        _check_index(X, y)
        frame_names = _column_names(X)
        if frame_names is not None and getattr(X, "columns", None) is None and names is not None:
            frame_names = None  # a named Series: the names given win over its name
        if frame_names is not None:
            if names is not None and tuple(names) != frame_names:
                raise ParameterError(f"input_names {list(names)} differ from the DataFrame's columns "
                                     f"{list(frame_names)}; select the columns instead")
            names = frame_names
        if output_name is None:  # a named Series, or a one-column DataFrame
            y_columns = _column_names(y)
            if isinstance(getattr(y, "name", None), str):
                output_name = y.name
            elif y_columns is not None and len(y_columns) == 1:
                output_name = y_columns[0]
        u, yy = validate_signals(_as_array(X), _output_vector(y))
        return u, yy, names, output_name

    def partition_column_names(self) -> tuple[str, ...] | None:
        """``partition_columns`` as a tuple of names (one name is one column, not its letters)."""
        wanted = self.partition_columns
        return None if wanted is None else (wanted,) if isinstance(wanted, str) else tuple(wanted)

    def given_orders(self) -> tuple:
        """``(na, nb, nk)`` this model is fitted with: its orders, 1 for each left ``None``."""
        return tuple(1 if v is None else v for v in (self.output_order, self.input_order, self.input_delay))

    def _check_settings(self, segmenter: bool = True):
        """One line naming the setting, what it takes and what it got, before any fit (the orders,
        regions and rows are checked where they are used); ``segmenter``: the method's own settings
        too (not for a model search's base, whose method the candidates replace)."""
        from hwpts.identification.settings import check_bool, check_count, check_number, check_random_state, is_count

        for name in ("constant", "polish", "sparse_partition"):
            check_bool(getattr(self, name), name)
        check_number(self.ridge, "ridge")
        if self.ridge > MAX_RIDGE:  # relative to the regressors' scale: beyond it every parameter is 0
            raise ParameterError(f"ridge must be at most {MAX_RIDGE:g} (relative to the regressors' scale), "
                                 f"got {self.ridge!r}")
        check_number(self.classifier_C, "classifier_C", strict=True)
        check_count(self.refinement_rounds, "refinement_rounds", 0)
        for name in ("max_rows", "classifier_rows"):
            value = getattr(self, name)
            if value is not None and not is_count(value, 100):
                raise ParameterError(f"{name} must be None or an int >= 100, got {value!r}")
        if self.segmentation_params is not None and not isinstance(self.segmentation_params, Mapping):
            raise ParameterError(f"segmentation_params must be a dict of the method's settings or None, "
                                 f"got {self.segmentation_params!r}")
        for name in ("hyperplanes", "region_models", "partition_columns"):
            value = getattr(self, name)
            if value is None or (name == "partition_columns" and isinstance(value, str)):
                continue  # one column name is one column
            if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__len__") or not len(value):
                what = {"hyperplanes": "a list of hyperplanes ('a,b,c' texts or Hyperplane objects)",
                        "region_models": "a list of region model kinds (one per region)",
                        "partition_columns": "a column name or a non-empty list of them"}[name]
                raise ParameterError(f"{name} must be {what} or None, got {value!r}")
        for kind in self.region_models or ():  # (inside a model search: every candidate failed in its folds)
            if kind not in MODEL_KINDS:
                raise ParameterError(f"unknown region model {kind!r}; valid are {list(MODEL_KINDS)}")
        check_random_state(self.random_state)
        if segmenter:
            self._segmenter().check_params()  # the method's own settings (segmentation_params)

    def _segmenter(self):
        from sklearn.base import clone

        from hwpts.identification.segmentation.base import Segmenter

        if isinstance(self.segmentation, Segmenter):
            if self.segmentation_params:
                try:
                    return clone(self.segmentation).set_params(**self.segmentation_params)
                except ValueError as error:  # scikit-learn's "Invalid parameter 'x' for estimator ..."
                    raise ParameterError(f"segmentation_params: {error}") from None
            return clone(self.segmentation)
        if self.segmentation == "auto":
            raise ParameterError("segmentation 'auto' is a model search, not a model: use "
                                 "PWARXSearch(PWARX(...)) (what `hwpts identify` does by default)")
        params = dict(self.segmentation_params or {})
        if any(not isinstance(key, str) for key in params):  # (TypeError: keywords must be strings)
            raise ParameterError(f"segmentation_params must map parameter names (str) to values, got keys "
                                 f"{[key for key in params if not isinstance(key, str)]!r}")
        if self.segmentation == "hyperplane":
            params.setdefault("hyperplanes", tuple(self.hyperplanes or ()))
        elif self.hyperplanes:
            raise ParameterError(
                f"hyperplanes were given but segmentation is {self.segmentation!r}; "
                f"use segmentation='hyperplane'"
            )
        return make_segmenter(self.segmentation, **params)

    def fit(self, X, y=None, input_names=None, output_name=None, breaks=None, sample_time=None, units=None):
        """Identify the model from inputs ``X`` (n, n_inputs) and output ``y`` (n,), or an IODataset.

        ``X`` may be a pandas DataFrame: its column names become the input names, and later
        predictions select the columns by name (in any order); indexed by time stamps or
        durations, its step is the sample time (a time index at another rate is refused later; one
        with a gap, jitter or a repeated stamp is refused, unless ``breaks`` say where the record
        restarts).
        ``y`` may have shape (n, 1).
        ``input_names`` (one per input) and ``output_name`` name plain arrays' signals (default
        ``u1, u2, ...`` and ``y``, or a named Series' name); an IODataset names its own.
        ``breaks``: sample positions where the record restarts (several experiments joined, or the
        two sides of a held-out block); regressor rows whose lags span a break are dropped.
        ``sample_time``: the sample period [s] of the data (taken from an IODataset's time when not
        given); kept in the model so that data at another rate are refused. ``units``: optional
        ``{signal name: unit}`` kept for plots and exports. Returns ``self``.
        """
        check_fit_arguments(sample_time, units, output_name)
        self._check_settings()
        u, yy, names, oname = self._signals(X, y, input_names, output_name)
        breaks = _check_breaks(breaks, yy.shape[0])
        sample_time = data_sample_time(X, sample_time, breaks)  # an IODataset's or a time-indexed DataFrame's
        n_inputs = u.shape[1]
        names, oname = signal_names(names, oname, n_inputs)
        check_units(units, names, oname)
        structure = RegressorStructure.create(*self.given_orders(), n_inputs, self.constant, names, oname,
                                              self.output_powers, *power_scaling(yy))
        structure.check_length(yy.shape[0])
        _check_signals_fit(structure, u, yy)
        segmenter = self._segmenter()
        rng = np.random.default_rng(self.random_state)
        X_reg, target = structure.build(u, yy)
        if breaks:
            keep = np.ones(target.shape[0], dtype=bool)
            m = structure.max_lag
            for b in breaks:  # rows k in [b, b + m) use samples from both sides of the break
                keep[max(int(b) - m, 0):max(int(b), 0)] = False
            X_reg, target = X_reg[keep], target[keep]
            if target.shape[0] <= structure.n_features + 1:
                raise DataError(f"{target.shape[0]} regressor rows are left after the breaks {list(breaks)}: "
                                f"too few to fit")
        pcols = None
        if self.partition_columns is not None and segmenter.takes_partition_columns():
            # (a given partition or a single model has no boundary to restrict: the model search's
            # ARX candidates of orders without the column ranked the orders, not failed; zscore's
            # labels are classified, on these columns)
            pcols = sorted({structure.column_index(c) for c in self.partition_column_names()})
        if segmenter.uses_n_regions and isinstance(self.n_regions, (int, np.integer)) \
                and not isinstance(self.n_regions, bool) and self.n_regions > X_reg.shape[0] // (structure.n_features + 2):
            if X_reg.shape[0] < structure.n_features + 2:  # not one region's worth ("at most 1" for 1)
                raise DataError(f"{X_reg.shape[0]} regressor rows are too few for a model of {structure.n_features + 1} "
                                f"parameters a region: at least {structure.n_features + 2} rows")
            raise ParameterError(
                f"n_regions={self.n_regions} is too many for {X_reg.shape[0]} regressor rows of "
                f"{structure.n_features + 1} parameters each: at most {max(X_reg.shape[0] // (structure.n_features + 2), 1)}"
            )
        n_regions = self.n_regions
        if segmenter.uses_n_regions:
            if not isinstance(n_regions, (int, np.integer)) or isinstance(n_regions, bool) or n_regions < 1:
                raise ParameterError(f"n_regions must be an int >= 1 for {self.segmentation!r}, got {n_regions!r}")
        X_seg, y_seg = X_reg, target
        limit = self.max_rows
        if segmenter.learns_partition and limit is not None and X_reg.shape[0] > limit:
            rows = np.sort(rng.choice(X_reg.shape[0], int(limit), replace=False))
            X_seg, y_seg = X_reg[rows], target[rows]
        seg = (segmenter.segment(X_seg, y_seg, n_regions, structure, rng, columns=pcols)
               if segmenter.restricts_columns else segmenter.segment(X_seg, y_seg, n_regions, structure, rng))
        s = seg.n_regions
        kinds = self._kinds(s)
        sparse_columns = None
        if seg.partition is not None:
            partition = seg.partition
            labels = partition.predict(X_reg)
        else:
            rows_kw = {} if self.classifier_rows is None else {"classifier_rows": self.classifier_rows}
            learner = PartitionLearner(refinement_rounds=self.refinement_rounds if seg.refine else 0,
                                       C=self.classifier_C, ridge=self.ridge, sparse=self.sparse_partition,
                                       random_state=self.random_state, **rows_kw)
            seg_labels, extension = seg.labels, None
            if X_seg is not X_reg:  # the segmentation saw a subsample: extend its labels to every row
                extension = fit_linear_partition(X_seg, seg.labels, s, C=self.classifier_C, columns=pcols)
                seg_labels = extension.predict(X_reg)
            _, partition, sparse_columns = learner.learn(X_reg, target, seg_labels, s, structure.constant, pcols,
                                                         init=extension)
            labels = partition.predict(X_reg)
            labels, s = drop_empty_regions(labels, partition.n_regions)
            if s != partition.n_regions:
                partition = fit_linear_partition(X_reg, labels, s, C=self.classifier_C,
                                                 columns=pcols if sparse_columns is None else sparse_columns)
                labels = partition.predict(X_reg)
            kinds = self._kinds(s)
        learned = seg.partition is None and s > 1
        local = fit_local_models(X_reg, target, labels, s, structure.constant, kinds, self.ridge,
                                 trim=TRIM if learned else None)
        self.structure_ = structure
        self.partition_ = partition
        self.theta_ = local.theta
        self.n_regions_ = s
        self.region_models_ = tuple(kinds)
        self.region_counts_ = local.n_samples
        self.training_labels_ = labels
        self.condition_ = local.condition
        self.parameter_cov_ = local.covariance
        self.input_names_ = names
        self.output_name_ = structure.output_name
        self.n_features_in_ = n_inputs
        if not isinstance(X, IODataset) and getattr(X, "columns", None) is not None:  # scikit-learn's: a DataFrame
            self.feature_names_in_ = np.asarray(names, dtype=object)
        else:
            self.__dict__.pop("feature_names_in_", None)
        self.output_range_ = (float(yy.min()), float(yy.max()))
        self.input_ranges_ = np.column_stack([u.min(axis=0), u.max(axis=0)])
        self.segmentation_info_ = {"method": segmenter.name, **seg.info}
        self.sample_time_ = None if sample_time is None else float(sample_time)
        self.units_ = {str(k): str(v) for k, v in dict(units or {}).items()}
        if sparse_columns is not None:
            self.segmentation_info_["partition_columns"] = [structure.feature_names[c] for c in sparse_columns]
        if self.polish:
            from hwpts.identification.polish import polish_free_run

            center, half = self.divergence_band()
            self.theta_, info = polish_free_run(structure, partition, self.theta_, kinds, u, yy, center, half,
                                                breaks=breaks)
            self.segmentation_info_["polish"] = info
        return self

    def _kinds(self, s):
        if self.region_models is None:
            return ("affine",) * s
        kinds = tuple(self.region_models)  # (each kind checked by _check_settings)
        if len(kinds) != s:
            raise ParameterError(f"region_models has {len(kinds)} entries but the partition has {s} regions")
        return kinds

    # ------------------------------------------------------------------ prediction
    def _check_inputs(self, X, y=None, need_y=True):
        check_is_fitted(self, "theta_")
        if isinstance(X, IODataset):
            if y is not None:
                raise ParameterError("pass either an IODataset or (inputs, output), not both")
            known = getattr(self, "sample_time_", None)
            dt = X.uniform_sample_time("the dataset's time", "resample the data")
            if known is not None and dt is not None and abs(dt - known) > 0.01 * known:
                raise DataError(f"the data's sample time {dt:.6g} s differs from the model's {known:.6g} s: "
                                f"its lags would mean other delays; resample the data or refit")
            X, y = _select_columns(X.inputs, X.input_names, self.input_names_), X.output
        else:
            _check_index(X, y)
            known = getattr(self, "sample_time_", None)
            dt = frame_sample_time(X, remedy="resample it (X.resample(...)), or give each stretch on its own "
                                             "(X.loc[start:end])")
            if known is not None and dt is not None and abs(dt - known) > 0.01 * known:
                raise DataError(f"the DataFrame's time index is sampled every {dt:.6g} s, the model every "
                                f"{known:.6g} s: its lags would mean other delays; resample the data or refit")
            frame_names = _column_names(X)
            if frame_names is None and hasattr(self, "feature_names_in_") and getattr(X, "ndim", 2) != 1:
                # as scikit-learn: columns by position where the fit took them by name
                warnings.warn(f"X has no column names, but the model was fitted on a DataFrame with columns "
                              f"{list(self.feature_names_in_)}: its columns are taken by position", UserWarning,
                              stacklevel=4)
            X = _as_array(X)
            if frame_names is not None:
                X = _select_columns(X, frame_names, self.input_names_)
        if y is None and need_y:
            raise ParameterError(
                f"the measured output is needed (the first {self.structure_.max_lag} samples are "
                f"the initial conditions)"
            )
        yy = None if y is None else _output_vector(y)
        if yy is not None:
            return validate_signals(X, yy, self.n_features_in_)
        return validate_inputs(X, self.n_features_in_), None

    def _prediction_inputs(self, X, y):
        """Inputs and outputs for a prediction: the measured output only where the regressor has
        lags (a static map predicts from its inputs), and at least one sample beyond the initial
        conditions (not as many as a fit needs)."""
        check_is_fitted(self, "theta_")
        m = self.structure_.max_lag
        u, yy = self._check_inputs(X, y, need_y=m > 0)
        if yy is None:
            yy = np.zeros(u.shape[0])
        if u.shape[0] <= m:
            raise DataError(f"a prediction needs more than the {m} initial samples, got {u.shape[0]}")
        return u, yy

    def predict(self, X, y=None, horizon: int = 1) -> np.ndarray:
        """``horizon``-step-ahead prediction from measured past outputs (eq. 5).

        ``horizon=1`` (default): one step ahead, eq. 5 with the measured regressor ``x_k``.
        ``horizon=k``: ``yhat(t | t-k)``, the free run over ``k`` steps from the measured outputs
        up to ``t-k`` (see :func:`hwpts.identification.simulation.k_step_pwarx`); a horizon of
        ``n - max_lag`` or more is the free run :meth:`simulate`. Returns an array of length n;
        its first ``max_lag`` entries are the measured outputs (``nan`` where a run diverged).
        """
        u, yy = self._prediction_inputs(X, y)
        if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
            raise ParameterError(f"horizon must be an int >= 1 (samples), got {horizon!r}")
        if horizon == 1:
            yhat, _ = one_step_pwarx(self.structure_, self.partition_, self.theta_, u, yy)
            with np.errstate(invalid="ignore"):
                bad = ~(np.abs(yhat) <= MAX_ABS_VALUE)  # inf, nan, or squares that would overflow
            if bad.any():
                lo, hi = self.output_range_
                raise DataError(f"the one-step prediction overflows (beyond +-{MAX_ABS_VALUE:.0e}) at sample "
                                f"{int(np.argmax(bad))}: the data lie far "
                                f"beyond the range the model was identified on (output {lo:.4g} to {hi:.4g}"
                                f"{', and its regressor holds powers of it' if self.structure_.output_powers else ''})")
            return yhat
        center, half = self.divergence_band()
        yhat, _ = k_step_pwarx(self.structure_, self.partition_, self.theta_, u, yy, int(horizon), center, half)
        return yhat

    def predict_regions(self, X, y=None) -> np.ndarray:
        """Region (0-based) of each sample's measured regressor (eq. 8); ``-1`` for the first max_lag."""
        u, yy = self._prediction_inputs(X, y)
        _, regions = one_step_pwarx(self.structure_, self.partition_, self.theta_, u, yy)
        return regions

    def divergence_band(self) -> tuple[float, float]:
        """(center, half-width) of the output band beyond which a free run counts as diverged."""
        check_is_fitted(self, "theta_")
        lo, hi = self.output_range_
        center = 0.5 * (lo + hi)
        half = max(0.5 * (hi - lo), 1e-9 * max(abs(center), 1.0))
        if self.theta_.shape[0] == 1 and not self.structure_.output_powers and self.state_space()[0].stable:
            # one stable linear mode cannot diverge: its output far beyond the training range is
            # the input's doing (validated at 100x the amplitude, an exact model read as diverged)
            return center, np.inf
        return center, DIVERGENCE_FACTOR * half

    def simulate(self, X, y=None, initial_output=None) -> SimulationResult:
        """Free-run simulation with the switching rule (eqs. 5, 8, 10), a :class:`SimulationResult`.

        The first ``max_lag`` outputs are the initial conditions, taken from ``initial_output`` or
        from the measured ``y``. Numba-compiled: about 10^7 samples per second.
        """
        check_is_fitted(self, "theta_")
        m = self.structure_.max_lag
        if initial_output is not None:
            if y is not None or (isinstance(X, IODataset)):
                raise ParameterError("simulate takes the initial outputs from initial_output or from the measured "
                                     "output (y, or an IODataset's), not both")
            u, _ = self._check_inputs(X, None, need_y=False)
            y0 = dense_real(initial_output, "initial_output")
            if y0.ndim > 1 and sum(d > 1 for d in y0.shape) > 1:
                raise DataError(f"initial_output must be a vector of the first outputs, got shape {y0.shape}")
            y0 = y0.ravel()
            if not np.all(np.isfinite(y0)):
                raise DataError("initial_output has a non-finite value")
        else:
            u, yy = self._check_inputs(X, y, need_y=m > 0)
            y0 = np.zeros(m) if yy is None else yy
        return self._simulate_checked(u, y0, strict=initial_output is not None)

    def _simulate_checked(self, u, y0, strict=False) -> SimulationResult:
        """The free run of checked inputs ``u`` from the outputs ``y0`` (``strict``: all ``max_lag``
        initial outputs needed, even for fewer samples)."""
        m = self.structure_.max_lag
        if u.shape[0] == 0:
            raise DataError("simulate needs at least one sample of the inputs, got none")
        if y0.shape[0] < min(m, u.shape[0]) or (strict and y0.shape[0] < m):
            raise DataError(f"need {m} initial outputs, got {y0.shape[0]}")
        center, half = self.divergence_band()
        return simulate_pwarx(self.structure_, self.partition_, self.theta_, u, y0, center, half)

    def score(self, X, y=None) -> float:
        """Free-run fit % (NRMSE) after the initial conditions; ``nan`` (with a warning) if diverged."""
        u, yy = self._check_inputs(X, y)
        sim = self._simulate_checked(u, yy)  # (the data checked once: not again as arrays)
        if sim.diverged:
            warnings.warn(sim.reason, FreeRunDivergedWarning, stacklevel=2)
        return sim.score(yy)

    @property
    def parameter_std_(self) -> np.ndarray:
        """Standard errors of ``theta_`` (square roots of the diagonal of ``parameter_cov_``)."""
        check_is_fitted(self, "theta_")
        cov = getattr(self, "parameter_cov_", None)
        if cov is None:
            return np.full(self.theta_.shape, np.nan)
        return np.sqrt(np.clip(np.diagonal(cov, axis1=1, axis2=2), 0.0, None))

    # ------------------------------------------------------------------ analysis
    def state_space(self) -> list:
        """State-space form (eq. 7) of every mode, with its poles (:class:`ModeStateSpace`); with
        ``output_powers``, of each mode's linear part (the linearisation at ``y(k-1) = c``)."""
        check_is_fitted(self, "theta_")
        return [mode_state_space(self.structure_, th) for th in self.theta_]

    def to_control(self, dt=None) -> list:
        """One python-control ``StateSpace`` per mode (the offset as the last input, held at 1);
        see :func:`hwpts.identification.analysis.to_control` (needs ``hwpts[control]``).
        ``dt`` defaults to the model's sample time when it is known."""
        from hwpts.identification.analysis import to_control

        check_is_fitted(self, "theta_")
        return to_control(self, dt if dt is not None else getattr(self, "sample_time_", None))

    def summary(self) -> dict:
        """JSON-ready description: orders, regions, per-mode sample counts and pole moduli."""
        check_is_fitted(self, "theta_")
        regions = []
        std = self.parameter_std_
        for i, ss in enumerate(self.state_space()):
            regions.append({
                "region": i + 1, "model": self.region_models_[i],
                "theta": [float(f"{v:.8g}") for v in self.theta_[i]],
                "theta_std": [float(f"{v:.4g}") if np.isfinite(v) else None for v in std[i]],
                "n_train_samples": int(self.region_counts_[i]),
                "max_pole_modulus": round(ss.max_pole_modulus, 6), "stable": ss.stable,
            })
        st = self.structure_
        return {
            "na": st.na, "nb": list(st.nb), "nk": list(st.nk), "constant": st.constant,
            **({"output_powers": list(st.output_powers)} if st.output_powers else {}),
            "inputs": list(st.input_names), "output": st.output_name,
            "segmentation": self.segmentation_info_.get("method", str(self.segmentation)),
            "n_regions": int(self.n_regions_), "regions": regions,
            **({"partition_columns": self.segmentation_info_["partition_columns"]}
               if "partition_columns" in self.segmentation_info_ else {}),
            "polished": bool(self.segmentation_info_.get("polish", {}).get("accepted", False)),
        }

    @classmethod
    def from_parts(cls, structure: RegressorStructure, partition: RegionPartition, theta, region_models=None,
                   output_range=None, input_ranges=None, params: dict | None = None,
                   segmentation_info: dict | None = None) -> PWARX:
        """A fitted estimator from its parts (a known model, or one read from a model file)."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if theta.shape != (partition.n_regions, structure.n_features + 1):
            raise ParameterError(
                f"theta must have shape ({partition.n_regions}, {structure.n_features + 1}); got {theta.shape}"
            )
        if partition.n_features != structure.n_features:
            raise ParameterError(
                f"partition is over {partition.n_features} regressors, the structure has {structure.n_features}"
            )
        est = cls(output_order=structure.na, input_order=list(structure.nb), input_delay=list(structure.nk),
                  n_regions=partition.n_regions, constant=structure.constant,
                  output_powers=tuple(structure.output_powers), **(params or {}))
        est.structure_ = structure
        est.partition_ = partition
        est.theta_ = theta
        est.n_regions_ = partition.n_regions
        est.region_models_ = tuple(region_models or ("affine",) * partition.n_regions)
        est.region_counts_ = np.zeros(partition.n_regions, dtype=np.int64)
        est.training_labels_ = np.zeros(0, dtype=np.int64)
        est.condition_ = np.full(partition.n_regions, np.nan)
        est.parameter_cov_ = np.full((partition.n_regions, theta.shape[1], theta.shape[1]), np.nan)
        est.input_names_ = structure.input_names
        est.output_name_ = structure.output_name
        est.n_features_in_ = structure.n_inputs
        est.output_range_ = tuple(output_range) if output_range is not None else (-1e300, 1e300)
        est.input_ranges_ = (np.asarray(input_ranges, dtype=float) if input_ranges is not None
                             else np.full((structure.n_inputs, 2), np.nan))
        est.segmentation_info_ = dict(segmentation_info or {})
        est.sample_time_ = None
        est.units_ = {}
        return est


MIN_ABS_SCALE = 1e-100  # a signal whose values are all smaller is refused (the mirror of MAX_ABS_VALUE)
MAX_OFFSET_RATIO = 1e10  # a signal whose magnitude is more times its variation is refused (digits lost)

LIBRARY_REMEDY = "resample it, or give fit(data, breaks=[...]) the rows where each stretch starts"


def frame_time(X) -> np.ndarray | None:
    """The time [s] of a pandas object indexed by time stamps, periods or durations (a
    DatetimeIndex, PeriodIndex or TimedeltaIndex), else None (a numeric index may count samples as
    well as seconds)."""
    index = getattr(X, "index", None)
    if type(index).__name__ == "PeriodIndex":  # periods (a 1 s PeriodIndex): their start times
        index = index.to_timestamp()
    if index is None or not hasattr(index, "dtype") or getattr(index.dtype, "kind", None) not in ("M", "m"):
        return None
    values = np.asarray(index.values)
    if values.dtype.kind == "M":
        values = values - values[0] if values.size else values
    return values.astype("timedelta64[ns]").astype(np.int64) / 1e9


FRAME_REMEDY = "resample it (X.resample(...)), or give fit(..., breaks=[...]) the rows where each stretch starts"


def frame_sample_time(X, breaks=(), remedy: str = FRAME_REMEDY) -> float | None:
    """The sample period [s] of a pandas object indexed by time stamps, periods or durations
    (:func:`frame_time`), else None (no time index, or fewer than two rows). An index that repeats
    a time stamp, or is not uniform (a gap: rows dropped, records joined; or jitter) is refused as
    an IODataset's time is: read by position, the lags would span the gap. With ``breaks`` (the
    rows where the record restarts) only the steps within each stretch must be uniform, and agree.
    An unsorted index is refused before (:func:`_check_index`)."""
    time = frame_time(X)
    if time is None or time.size < 2:
        return None
    repeated = np.flatnonzero(np.diff(time) == 0)
    if repeated.size:
        raise DataError(f"the DataFrame's time index repeats a time stamp at row {int(repeated[0]) + 1} (two "
                        f"samples of one instant): drop or average the duplicates (X[~X.index.duplicated()])")
    return stretch_sample_time(time, breaks, "the DataFrame's time index", remedy)


def stretch_sample_time(time, breaks, what: str, remedy: str) -> float | None:
    """The sample period [s] of the times ``time`` (:func:`hwpts.dataset.uniform_sample_time`),
    each stretch between the ``breaks`` (rows where the record restarts) on its own: uniform within
    each, and the same in all; ``None`` when no stretch has two samples."""
    from hwpts.dataset import uniform_sample_time

    edges = [0, *sorted(int(b) for b in breaks or ()), len(time)]
    found = []
    for a, b in zip(edges[:-1], edges[1:]):
        try:
            dt = uniform_sample_time(time[a:b], what, remedy)
        except DataError as error:
            if a == 0:
                raise
            raise DataError(f"{error} (in the stretch from row {a})") from None
        if dt is not None:
            found.append((dt, a))
    if not found:
        return None
    dt, _ = found[0]
    other = next(((d, a) for d, a in found if abs(d - dt) > 0.01 * dt), None)
    if other is not None:
        raise DataError(f"{what} steps {dt:.6g} s, but {other[0]:.6g} s from row {other[1]}: PWARX models need one "
                        f"sample time; resample the stretches to one rate")
    return dt


def data_sample_time(X, sample_time, breaks=(), remedy: str | None = None):
    """The sample time [s] to keep for a fit on ``X``: the step of an IODataset's time or of a
    time-indexed DataFrame's (:func:`frame_sample_time`, with the fit's ``breaks``), or
    ``sample_time`` when given and equal to it within 1 % (another one is refused: it replaced the
    data's, and then the model refused its own training data as sampled at another rate).
    ``remedy``: what a message on a non-uniform time says to do (default: resample or give breaks)."""
    from hwpts.identification.settings import is_number

    if isinstance(X, IODataset):  # (a gap where the fit's breaks say the record restarts is no gap)
        uniform = stretch_sample_time(X.time, breaks, "the dataset's time", remedy or LIBRARY_REMEDY)
        what = "the dataset's time"
    else:
        uniform, what = frame_sample_time(X, breaks, remedy or FRAME_REMEDY), "the DataFrame's time index"
    if uniform is None or sample_time is None:
        return uniform if sample_time is None else sample_time
    if is_number(sample_time, strict=True) and abs(sample_time - uniform) > 0.01 * uniform:
        raise ParameterError(f"sample_time {sample_time!r} s differs from {what}, sampled every "
                             f"{uniform:g} s; expected that or sample_time left out")
    return sample_time


def check_fit_arguments(sample_time, units, output_name) -> None:
    """The arguments of ``fit`` beside the data (PWARX's and PWARXSearch's), checked before any
    state changes: a bad one raised a TypeError from numpy, or after the fit had replaced the model."""
    from hwpts.identification.settings import is_number

    if sample_time is not None and not (is_number(sample_time, strict=True) and sample_time >= MIN_SAMPLE_TIME):
        raise ParameterError(f"sample_time must be a number of seconds >= {MIN_SAMPLE_TIME:g} (as a model file holds it) or "
                             f"None, got {sample_time!r}")
    if units is not None and not isinstance(units, Mapping):
        raise ParameterError(f"units must be a dict {{signal name: unit}} or None, got {units!r}")
    if output_name is not None and (not isinstance(output_name, str) or not output_name):
        raise ParameterError(f"output_name must be a non-empty string, got {output_name!r}")


def _check_signals_fit(structure, u, yy) -> None:
    """The signals the regressor holds (an input of order 0 is not used, so not checked) can be
    fitted: none constant, none whose values all lie below :data:`MIN_ABS_SCALE` (its least squares
    gave zero gains, with a warning only), none whose offset is more than :data:`MAX_OFFSET_RATIO`
    times its variation (the model works on the raw values: pick_and_place's output + 1e12, 25 units
    around 1e12, fitted a free run of 45.9 % for 79.2 %; + 1e15 a one-step fit of 53 % for 99.9 %)."""
    used = [(name, values) for name, values, nb in zip(structure.input_names, u.T, structure.nb) if nb > 0]
    for j, (name, values) in enumerate([*used, (structure.output_name, yy)]):
        spread = float(np.ptp(values))
        if spread == 0 and j < len(used):
            raise DataError(f"input {name!r} is constant ({values[0]:.6g}) in the training data: it carries no "
                            f"information and makes the least squares singular; drop it or use richer data")
        if spread == 0:
            raise DataError(f"output {name!r} is constant in the training data; there is nothing to identify")
        largest = float(np.max(np.abs(values)))
        if largest < MIN_ABS_SCALE:
            raise DataError(f"signal {name!r} holds no value larger than {largest:.3g} in magnitude, below "
                            f"{MIN_ABS_SCALE:.0e}: too small to fit; rescale it")
        if largest > MAX_OFFSET_RATIO * spread:
            level = float(np.median(values))
            raise DataError(f"signal {name!r} varies by {spread:.3g} around {level:.6g}: an offset "
                            f"{largest / spread:.1e} times its variation leaves the model too few digits; "
                            f"subtract it first ({name} - {level:.6g})")


def signal_names(names, output_name, n_inputs) -> tuple[tuple[str, ...], str]:
    """The inputs' and the output's names a fit gives its model: those given, else ``u1, u2, ...``
    and ``y`` (``y_out`` where an input is named ``y``); checked (:func:`_check_names`)."""
    if names is not None and (isinstance(names, (str, bytes)) or not hasattr(names, "__iter__")):
        # (a string was split into its letters, an int failed: 'int' object is not iterable)
        raise ParameterError(f"input_names must be a sequence of {n_inputs} name(s), got {names!r}")
    names = tuple(names) if names is not None else default_input_names(n_inputs)
    if output_name is None:  # the output unnamed: "y", unless an input has that name
        output_name = "y" if "y" not in names else "y_out"
    _check_names(names, output_name, n_inputs)
    return names, output_name


def check_units(units, names, output_name) -> None:
    """``units`` (``{signal: unit}``) names signals of the model, with printable units: another
    name was kept and written, and the model file was then refused by every command."""
    for name, unit in dict(units or {}).items():
        if name not in (*names, output_name):
            raise ParameterError(f"units names {name!r}, which is no signal of the model "
                                 f"({[*names, output_name]})")
        if not isinstance(unit, str) or not unit.isprintable():
            raise ParameterError(f"units[{name!r}] must be printable text, got {unit!r}")


def _check_names(names, output_name, n_inputs):
    """The inputs' names: one per input column, distinct, none the output's (a regressor column is
    chosen by name: ``partition_columns``, ``--partition-column``, the model file)."""
    if len(names) != n_inputs:
        raise ParameterError(f"input_names has {len(names)} names for {n_inputs} input columns: {list(names)}")
    seen = set()
    for name in names:
        if not isinstance(name, str) or not name:
            raise ParameterError(f"input names must be non-empty strings, got {name!r}")
        if name in seen or name == output_name:
            clash = "the output's name" if name == output_name else "two inputs' name"
            raise ParameterError(f"input name {name!r} is {clash}; the names must be distinct (rename the columns)")
        seen.add(name)


def _check_breaks(breaks, n):
    """``breaks`` as a sorted tuple of sample positions inside ``(0, n)`` (None or empty: none)."""
    if breaks is None:
        return ()
    if isinstance(breaks, (str, bytes)) or not hasattr(breaks, "__iter__"):
        raise ParameterError(f"breaks must be a list of sample positions, got {breaks!r}")
    out = []
    for b in breaks:
        if isinstance(b, bool) or not isinstance(b, (int, np.integer)) or not 0 < b < n:
            shown = b.item() if isinstance(b, np.generic) else b
            raise ParameterError(f"breaks must be sample positions between 1 and {n - 1}, got {shown!r}")
        out.append(int(b))
    return tuple(sorted(set(out)))


def _column_names(X) -> tuple[str, ...] | None:
    """The column names of a DataFrame-like ``X`` (pandas, polars: a ``columns`` attribute), else None."""
    if isinstance(X, np.ndarray):
        return None
    columns = getattr(X, "columns", None)
    if columns is None:
        name = getattr(X, "name", None)  # a named Series: one input of that name
        if isinstance(name, str) and name and getattr(X, "ndim", None) == 1:
            return (name,)
        return None
    return tuple(str(c) for c in columns)


def _check_index(X, y) -> None:
    """pandas inputs are read by position, as scikit-learn reads them: refuse what position would
    read wrong without a word, an output indexed otherwise than the inputs and an index (time,
    or numeric: ``df.sample`` shuffles it) that is not increasing (unsorted records: every lag
    would be another sample; a shuffled DataFrame fitted at -0.5 % without a message)."""
    x_index, y_index = getattr(X, "index", None), getattr(y, "index", None)
    if x_index is not None and y_index is not None and hasattr(x_index, "equals") and not x_index.equals(y_index):
        raise DataError("X and y have different indexes and are read by position: align them first "
                        "(y.reindex(X.index)) or pass arrays")
    for label, index in (("X", x_index), ("y", y_index)):
        kind = getattr(getattr(index, "dtype", None), "kind", None)
        if kind is None or kind not in "mMiuf" or index.is_monotonic_increasing:
            continue
        if kind in "mM":
            raise DataError(f"{label}'s time index is not increasing: sort the records by time ({label}.sort_index())")
        # a numeric index that goes back: rows shuffled (df.sample) or records joined end to end;
        # read by position every lag would be another record's sample
        raise DataError(f"{label}'s index is not increasing (rows are read in order, as lags): sort shuffled "
                        f"rows ({label}.sort_index()), or for records joined end to end reset the index and give "
                        f"fit(..., breaks=[...]) where each starts")


def _as_array(X):
    """A DataFrame-like as a numpy array (its ``to_numpy``); anything else unchanged."""
    to_numpy = getattr(X, "to_numpy", None)
    return to_numpy() if callable(to_numpy) and not isinstance(X, np.ndarray) else X


def _output_vector(y) -> np.ndarray:
    """The output as a 1-D array: shape (n,) or (n, 1) (a one-column DataFrame or Series too)."""
    arr = _as_array(y)
    if hasattr(arr, "tocsr") or np.iscomplexobj(arr):
        return dense_real(arr, "y")
    arr = np.asarray(arr)
    if arr.ndim == 2 and arr.shape[1] == 1:
        arr = arr[:, 0]
    return arr


def _select_columns(u, names, wanted) -> np.ndarray:
    """The columns of ``u`` (named ``names``) in the order ``wanted``: data are matched by name."""
    names = tuple(names)
    if names == tuple(wanted):
        return u
    unnamed = default_input_names(len(wanted))
    if tuple(wanted) == unnamed and len(names) == len(wanted) and not set(names) & set(unnamed):
        # a model fitted on arrays (its inputs unnamed) given a DataFrame: its columns in order,
        # as scikit-learn takes them, with a warning
        warnings.warn(f"the model's inputs were fitted without names; the data's columns {list(names)} are "
                      f"taken in that order", UserWarning, stacklevel=4)
        return u
    missing = [w for w in wanted if w not in names]
    if missing:
        raise DataError(f"the data have no input column(s) {missing} (the model's inputs are {list(wanted)}; "
                        f"the data's columns are {list(names)})")
    u = np.asarray(u)
    return u[:, [names.index(w) for w in wanted]]
