"""Regression vectors of a MISO ARX / PWARX model (paper eqs. 6-7).

The standard regression vector at sample ``k`` is (paper eq. 7, generalised to an input delay
``nk_j`` per input, with ``nk_j = 0`` allowed as in the paper's eq. 18 which uses ``h_i(k)``)::

    x_k = [y(k-1) ... y(k-na),
           u_1(k-nk_1) ... u_1(k-nk_1-nb_1+1),
           ...,
           u_p(k-nk_p) ... u_p(k-nk_p-nb_p+1)]'

and the extended regression vector is ``phi_k = [x_k' 1]'`` (eq. 6) when the model has a constant
term, ``phi_k = x_k`` otherwise (a piecewise *linear* model).

Optionally (``output_powers``, beyond the paper) ``x_k`` ends with powers of the standardised last
output, ``((y(k-1) - c) / s)^p`` for each ``p`` (``c``, ``s``: the training output's mean and
standard deviation, kept in the structure): a polynomial NARX term in every mode, for a system
whose nonlinearity is a smooth function of the output (a cubic spring) that affine pieces only
approximate and cannot extrapolate. The terms and ``y(k-1)`` span the polynomials in ``y(k-1)``
up to the highest power when every lower power is there (``(2, 3)`` for a cubic: the cube of the
centred output alone holds ``-3 c y^2``). The model stays linear in its parameters (least squares per
region, the polish) but is no longer affine in its state: the modes' state-space form
(:func:`~hwpts.identification.statespace.mode_state_space`) is then the linear part, the
linearisation at ``y(k-1) = c``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from hwpts.dataset import dense_real  # noqa: F401 - the package imports it from here too
from hwpts.errors import DataError, ParameterError

__all__ = ["RegressorStructure", "as_order_tuple"]


def as_order_tuple(value, n_inputs: int, name: str, minimum: int) -> tuple[int, ...]:
    """An order given as an int (same for every input) or one int per input, as a tuple."""
    if isinstance(value, np.ndarray) and value.ndim == 0:  # np.array(2): its number
        value = value.item()
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        values = (int(value),) * n_inputs
    else:
        # one int per input, in order: a list, tuple or integer array (not a set, whose order is
        # none; nor True or 1.0, which the scalar forms refuse as well)
        if isinstance(value, (str, bytes, set, frozenset, dict)) or not hasattr(value, "__iter__") \
                or not all(isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)) for v in value):
            raise ParameterError(f"{name} must be an int or a list of ints (one per input), got {value!r}")
        values = tuple(int(v) for v in value)
        if len(values) != n_inputs:
            raise ParameterError(
                f"{name} has {len(values)} entries but there are {n_inputs} inputs; "
                f"give one int or one per input"
            )
    if any(v < minimum for v in values):
        raise ParameterError(f"{name} must be >= {minimum} for every input, got {list(values)}")
    return values


MAX_POWER = 9  # highest power term: (y - c) / s reaches tens on an output far outside its training range


def check_output_powers(value) -> tuple[int, ...]:
    """``output_powers`` as a sorted tuple of distinct ints in 2..MAX_POWER (``None``: empty)."""
    if value is None:
        return ()
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        value = (value,)
    try:
        items = list(value)
    except TypeError:
        raise ParameterError(f"output_powers must be a list of ints in 2..{MAX_POWER}, got {value!r}") from None
    if any(isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 2 <= v <= MAX_POWER for v in items) \
            or len(set(int(v) for v in items)) != len(items):
        raise ParameterError(f"output_powers must be distinct ints in 2..{MAX_POWER}, got {value!r}")
    return tuple(sorted(int(v) for v in items))


def default_input_names(n_inputs: int) -> tuple[str, ...]:
    """The inputs' names when none are given: ``u1``, ``u2``, ..."""
    return tuple(f"u{j + 1}" for j in range(n_inputs))


def power_scaling(output) -> tuple[float, float]:
    """``(c, s)`` of the power terms for a training ``output``: its mean and standard deviation
    (1 for a constant output)."""
    y = np.asarray(output, dtype=float)
    return float(np.mean(y)), float(np.std(y)) or 1.0


@dataclass(frozen=True)
class RegressorStructure:
    """Orders of a MISO ARX structure and the names of its signals.

    Attributes
    ----------
    na : int
        Output order (number of past outputs), ``>= 0``.
    nb : tuple of int
        Input order per input (number of samples of each input), ``>= 0``.
    nk : tuple of int
        Input delay per input, ``>= 0`` (``0`` uses ``u(k)``, as the paper's eq. 18).
    constant : bool
        Whether the extended regressor ends with a constant 1 (eq. 6: an affine model).
    input_names, output_name : names used for the regressor column names.
    output_powers : tuple of int
        Powers ``p >= 2`` of the standardised last output ``((y(k-1) - c) / s)^p`` appended to
        ``x_k`` (module doc); empty (the default): the paper's affine regressor.
    power_center, power_scale : float
        ``c`` and ``s`` of those terms (the training output's mean and standard deviation,
        :func:`power_scaling`); 0 and 1 without power terms.
    """

    na: int
    nb: tuple[int, ...]
    nk: tuple[int, ...]
    constant: bool = True
    input_names: tuple[str, ...] = ()
    output_name: str = "y"
    output_powers: tuple[int, ...] = ()
    power_center: float = 0.0
    power_scale: float = 1.0

    @classmethod
    def create(cls, na, nb, nk, n_inputs: int, constant: bool = True, input_names=None,
               output_name: str | None = None, output_powers=(), power_center: float = 0.0,
               power_scale: float = 1.0) -> RegressorStructure:
        """Validate orders (int or one per input) and build the structure."""
        if not isinstance(na, (int, np.integer)) or isinstance(na, bool) or na < 0:
            raise ParameterError(f"na (output order) must be an int >= 0, got {na!r}")
        if n_inputs < 1:
            raise ParameterError(f"need at least one input, got {n_inputs}")
        nb_t = as_order_tuple(nb, n_inputs, "nb (input order)", 0)
        nk_t = as_order_tuple(nk, n_inputs, "nk (input delay)", 0)
        if na == 0 and sum(nb_t) == 0:
            raise ParameterError("na=0 and nb=0 for every input leave an empty regressor")
        names = tuple(input_names) if input_names is not None else default_input_names(n_inputs)
        if len(names) != n_inputs:
            raise ParameterError(f"{len(names)} input names for {n_inputs} inputs")
        powers = check_output_powers(output_powers)
        if powers and na < 1:
            raise ParameterError(f"output_powers {list(powers)} need y(k-1) in the regressor: na (output order) "
                                 f"must be >= 1, got {na}")
        center, scale = (float(power_center), float(power_scale)) if powers else (0.0, 1.0)
        if not (np.isfinite(center) and np.isfinite(scale) and scale > 0):
            raise ParameterError(f"power_center must be finite and power_scale finite and > 0, got "
                                 f"{power_center!r} and {power_scale!r}")
        return cls(int(na), nb_t, nk_t, bool(constant), names, output_name or "y", powers, center, scale)

    @property
    def n_inputs(self) -> int:
        """Number of inputs."""
        return len(self.nb)

    @property
    def max_lag(self) -> int:
        """Number of initial samples needed before the first regressor (initial conditions)."""
        lags = [self.na] + [nk + nb - 1 for nb, nk in zip(self.nb, self.nk) if nb > 0]
        return max(0, *lags)

    @property
    def n_linear(self) -> int:
        """Columns of x_k that are lagged signals (eq. 7): the power terms follow them."""
        return self.na + sum(self.nb)

    @property
    def n_features(self) -> int:
        """Length of the regression vector x_k (eq. 7, then the power terms, if any)."""
        return self.na + sum(self.nb) + len(self.output_powers)

    @property
    def n_parameters(self) -> int:
        """Length of the extended regression vector phi_k (eq. 6) = parameters per mode."""
        return self.n_features + int(self.constant)

    @property
    def min_samples(self) -> int:
        """Fewest samples giving as many equations as one mode has parameters."""
        return self.max_lag + self.n_parameters

    def describe_orders(self) -> str:
        """The orders as text, such as ``na=5, nb=4, nk=0``."""
        nb = self.nb[0] if len(set(self.nb)) == 1 else list(self.nb)
        nk = self.nk[0] if len(set(self.nk)) == 1 else list(self.nk)
        powers = f", output powers {list(self.output_powers)}" if self.output_powers else ""
        return f"na={self.na}, nb={nb}, nk={nk}{powers}"

    def check_length(self, n_samples: int, what: str = "the data") -> None:
        """Raise :class:`DataError` when ``n_samples`` is too short for these orders."""
        if n_samples < self.min_samples:
            raise DataError(
                f"{self.describe_orders()} needs at least {self.min_samples} samples "
                f"({self.max_lag} initial conditions + {self.n_parameters} parameters); "
                f"{what} has {n_samples} rows"
            )

    @property
    def feature_names(self) -> list[str]:
        """Names of the columns of x_k, e.g. ``y(k-1)``, ``u1(k)``, ``u1(k-1)``."""
        names = [f"{self.output_name}(k-{i})" for i in range(1, self.na + 1)]
        for name, nb, nk in zip(self.input_names, self.nb, self.nk):
            for lag in range(nk, nk + nb):
                names.append(f"{name}(k)" if lag == 0 else f"{name}(k-{lag})")
        names += [f"(({self.output_name}(k-1)-c)/s)^{p}" for p in self.output_powers]
        return names

    @property
    def lags(self) -> tuple[np.ndarray, np.ndarray]:
        """For each column of x_k: the signal index (-1 = output, j = input j) and the lag."""
        sig, lag = [], []
        for i in range(1, self.na + 1):
            sig.append(-1)
            lag.append(i)
        for j, (nb, nk) in enumerate(zip(self.nb, self.nk)):
            for lg in range(nk, nk + nb):
                sig.append(j)
                lag.append(lg)
        sig += [-1] * len(self.output_powers)
        lag += [1] * len(self.output_powers)
        return np.asarray(sig, dtype=np.int64), np.asarray(lag, dtype=np.int64)

    @property
    def powers(self) -> np.ndarray:
        """For each column of x_k: 1 for a lagged signal, ``p`` for a power term (module doc)."""
        return np.asarray([1] * self.n_linear + list(self.output_powers), dtype=np.int64)

    def with_powers(self, X: np.ndarray) -> np.ndarray:
        """Fill the power-term columns of ``X`` (rows x_k) from its ``y(k-1)`` column, in place;
        ``X`` is returned (nothing to do without power terms)."""
        if self.output_powers:
            z = (X[:, 0] - self.power_center) / self.power_scale
            for q, p in enumerate(self.output_powers):
                X[:, self.n_linear + q] = z ** p
        return X

    def column_index(self, name: str) -> int:
        """Index in x_k of a regressor column, by regressor name (``u1(k-1)``) or input name.

        An input name refers to that input's most recent sample in the regressor (``u(k-nk)``);
        the output name refers to ``y(k-1)``. A name that means two columns (an input named
        ``y(k-1)`` beside the output ``y``) is refused rather than guessed.
        """
        names = self.feature_names
        meanings = {}
        if name in names:
            meanings[names.index(name)] = f"the regressor column {name!r}"
        if name in self.input_names:
            j = self.input_names.index(name)
            if self.nb[j] > 0:
                meanings.setdefault(self.input_column(j), f"the input {name!r}")
            elif not meanings:
                raise ParameterError(f"input {name!r} has nb=0: it is not in the regressor")
        if name == self.output_name and self.na > 0:
            meanings.setdefault(0, f"the output {name!r}")
        if len(meanings) > 1:
            raise ParameterError(f"column name {name!r} is ambiguous: it names {' and '.join(meanings.values())}, "
                                 f"different regressor columns; rename the data's column")
        if meanings:
            return next(iter(meanings))
        raise ParameterError(
            f"unknown regressor column {name!r}; valid names are {names} or the inputs "
            f"{list(self.input_names)}"
        )

    def input_column(self, j: int) -> int:
        """Index in x_k of input ``j``'s most recent sample (``u_j(k-nk_j)``)."""
        if self.nb[j] == 0:
            raise ParameterError(f"input {self.input_names[j]!r} has nb=0: it is not in the regressor")
        return self.na + sum(self.nb[:j])

    def build(self, inputs: np.ndarray, output: np.ndarray, fit: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Regressor matrix X (rows x_k', eq. 7) and targets y(k), for k = max_lag .. n-1.

        ``fit``: the record must hold enough rows to fit the parameters (:meth:`check_length`);
        ``False`` (a prediction): one row beyond the initial conditions is enough."""
        u = np.asarray(inputs, dtype=float)
        if u.ndim == 1:
            u = u[:, None]
        y = np.asarray(output, dtype=float)
        if u.ndim != 2 or u.shape[1] != self.n_inputs:
            raise DataError(f"inputs must have shape (n_samples, {self.n_inputs}); got {u.shape}")
        if y.ndim != 1 or y.shape[0] != u.shape[0]:
            raise DataError(f"output must have shape ({u.shape[0]},); got {y.shape}")
        n = y.shape[0]
        if fit:
            self.check_length(n)
        elif n <= self.max_lag:
            raise DataError(f"a prediction needs more than the {self.max_lag} initial samples, got {n}")
        m = self.max_lag
        rows = n - m
        X = np.empty((rows, self.n_features))
        col = 0
        for i in range(1, self.na + 1):
            X[:, col] = y[m - i : n - i]
            col += 1
        for j, (nb, nk) in enumerate(zip(self.nb, self.nk)):
            for lg in range(nk, nk + nb):
                X[:, col] = u[m - lg : n - lg, j]
                col += 1
        return self.with_powers(X), y[m:].copy()

    def extend(self, X: np.ndarray) -> np.ndarray:
        """Extended regressors phi_k = [x_k' 1]' (eq. 6), or x_k without a constant term."""
        if not self.constant:
            return X
        return np.hstack([X, np.ones((X.shape[0], 1))])

    def to_dict(self) -> dict:
        """JSON-ready form (orders, names, regressor names) as stored in model files."""
        doc = {
            "na": self.na, "nb": list(self.nb), "nk": list(self.nk), "constant": self.constant,
            "input_names": list(self.input_names), "output_name": self.output_name,
            "regressor_names": self.feature_names,
        }
        if self.output_powers:  # written only when present: affine models' files are as before
            doc.update({"output_powers": list(self.output_powers), "power_center": self.power_center,
                        "power_scale": self.power_scale})
        return doc

    @classmethod
    def from_dict(cls, d: dict) -> RegressorStructure:
        """The structure from :meth:`to_dict`'s form (validated)."""
        return cls.create(d["na"], d["nb"], d["nk"], len(d["input_names"]), d["constant"],
                          d["input_names"], d["output_name"], d.get("output_powers") or (),
                          d.get("power_center", 0.0), d.get("power_scale", 1.0))


MAX_ABS_VALUE = 1e100  # largest magnitude of a signal value: its square (and sums of them) stay finite


def validate_inputs(inputs, n_inputs: int | None = None) -> np.ndarray:
    """Inputs as a finite (n, p) float array (a 1-D array is one input)."""
    u = dense_real(inputs, "inputs")
    if u.ndim == 1:
        u = u[:, None]
    if u.ndim != 2:
        raise DataError(f"inputs must be 2-D (n_samples, n_inputs); got shape {u.shape}")
    if n_inputs is not None and u.shape[1] != n_inputs:
        raise DataError(f"expected {n_inputs} input columns, got {u.shape[1]}")
    check_values("inputs", u)
    return u


def validate_signals(inputs, output, n_inputs: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Inputs as (n, p) float array and output as (n,) float array, finite, same length."""
    u = validate_inputs(inputs, n_inputs)
    y = dense_real(output, "output")
    if y.ndim != 1:
        raise DataError(f"output must be 1-D; got shape {y.shape}")
    if u.shape[0] != y.shape[0]:
        raise DataError(f"inputs have {u.shape[0]} rows but output has {y.shape[0]}")
    check_values("output", y)
    return u, y


def check_values(label: str, arr: np.ndarray) -> None:
    """Every value finite and within +-MAX_ABS_VALUE (else a DataError naming the first row): the
    signals of a fit, and the rows a segmenter or the partition learner is given."""
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.argwhere(bad.reshape(arr.shape[0], -1))[0, 0])
        raise DataError(f"{label} has a non-finite value (NaN or inf) at row {row}")
    huge = np.abs(arr) > MAX_ABS_VALUE
    if huge.any():
        row = int(np.argwhere(huge.reshape(arr.shape[0], -1))[0, 0])
        raise DataError(f"{label} has the value {np.abs(arr.reshape(arr.shape[0], -1)[row]).max():.3g} at row {row}, "
                        f"beyond +-{MAX_ABS_VALUE:.0e}: its squares overflow the least squares; rescale the signal")


def names_or_default(names: Sequence[str] | None, n: int, prefix: str) -> tuple[str, ...]:
    """``names`` as a tuple of strings, or ``prefix1``, ``prefix2``, and so on when ``names`` is None."""
    if names is None:
        return tuple(f"{prefix}{j + 1}" for j in range(n))
    return tuple(str(x) for x in names)
