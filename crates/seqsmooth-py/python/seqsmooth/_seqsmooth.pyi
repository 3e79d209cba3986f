"""Type stubs of the native module (the classes and functions re-exported by seqsmooth)."""

from collections.abc import Callable
from fractions import Fraction
from typing import Literal, overload

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Matrix = npt.NDArray[np.float64]
Vector = npt.NDArray[np.float64]
Cube = npt.NDArray[np.float64]

MAX_DEGREE: int
__version__: str

class State:
    """The estimate of a polynomial filter at one time."""

    @property
    def time(self) -> float: ...
    @property
    def derivatives(self) -> Vector: ...
    @property
    def covariance(self) -> Matrix | None: ...
    @property
    def std_devs(self) -> Vector | None: ...
    @property
    def sigma(self) -> Vector | None:
        """``std_devs`` by its old name."""

class PolynomialFilter:
    @property
    def degree(self) -> int: ...
    @property
    def samples(self) -> int: ...
    @property
    def last_time(self) -> float | None: ...
    @property
    def is_determined(self) -> bool: ...
    def update(self, t: float, y: float) -> None: ...
    @overload
    def update_many(
        self,
        t: ArrayLike,
        y: ArrayLike,
        return_sigma: Literal[False] = ...,
        *,
        out: Matrix | None = None,
    ) -> Matrix: ...
    @overload
    def update_many(
        self,
        t: ArrayLike,
        y: ArrayLike,
        return_sigma: Literal[True],
        *,
        out: Matrix | None = None,
    ) -> tuple[Matrix, Matrix]: ...
    def estimate(self) -> State: ...
    def estimate_at(self, t: float) -> State: ...

class ExpandingMemory(PolynomialFilter):
    def __init__(
        self,
        degree: int,
        engine: Literal["exact", "gain"] = "exact",
        sigma: float | None = None,
        *,
        x0: ArrayLike | None = None,
        P0: ArrayLike | float | None = None,
        t0: float = 0.0,
    ) -> None: ...

class FadingMemory(PolynomialFilter):
    def __init__(
        self,
        degree: int,
        theta: float | None = None,
        tau: float | None = None,
        engine: Literal["exact", "gain"] = "exact",
        sigma: float | None = None,
        theta_per_update: float | None = None,
        *,
        x0: ArrayLike | None = None,
        P0: ArrayLike | float | None = None,
        t0: float = 0.0,
    ) -> None: ...

class FixedMemory(PolynomialFilter):
    def __init__(
        self,
        degree: int,
        window: int,
        engine: Literal["adaptive", "sliding", "direct", "irregular"] = "adaptive",
        sigma: float | None = None,
    ) -> None: ...

@overload
def smooth(
    y: ArrayLike,
    window_length: int,
    polyorder: int,
    deriv: int = 0,
    delta: float = 1.0,
    t: ArrayLike | None = None,
    sigma: float | None = None,
    return_sigma: Literal[False] = ...,
) -> Vector: ...
@overload
def smooth(
    y: ArrayLike,
    window_length: int,
    polyorder: int,
    deriv: int = 0,
    delta: float = 1.0,
    t: ArrayLike | None = None,
    sigma: float | None = None,
    *,
    return_sigma: Literal[True],
) -> tuple[Vector, Vector]: ...
def filter_series(
    codes: npt.NDArray[np.int64],
    t: ArrayLike,
    y: ArrayLike,
    kind: Literal["expanding", "fading", "fixed", "auto"],
    degree: int,
    theta: float | None = None,
    tau: float | None = None,
    window: int | None = None,
    engine: str | None = None,
    sigma: float | None = None,
    review_window: int | None = None,
) -> tuple[Matrix, list[str]]:
    """The engine of ``filter_frame``: row ``i`` of series ``codes[i]`` through its series'
    filter; the columns of ``seqsmooth filter``'s rows as an array ``(columns, rows)`` and
    their names (``d0..dM``, ``s0..sM``, the kind's cells: ``window``; ``noise``,
    ``outlier`` (final), ``misfit``, ``bias``)."""
    ...

class FilterStream:
    """``filter_series`` kept open: rows of many series that come in chunks, one filter per
    series carried from chunk to chunk (the library's ``StreamBank``, as ``seqsmooth filter
    --id-col``); the numbers of ``filter_series`` on all the rows at once, bit for bit."""

    def __init__(
        self,
        kind: Literal["expanding", "fading", "fixed", "auto"],
        degree: int,
        theta: float | None = None,
        tau: float | None = None,
        window: int | None = None,
        engine: str | None = None,
        sigma: float | None = None,
        review_window: int | None = None,
    ) -> None: ...
    @property
    def names(self) -> list[str]:
        """The columns ``update`` gives back (``filter_series``' names)."""
    @property
    def rows(self) -> int:
        """Rows taken so far."""
    @property
    def waiting(self) -> int:
        """Rows taken, not given back yet (``auto``: their outlier decision to come)."""
    def update(
        self, codes: npt.NDArray[np.int64], t: ArrayLike, y: ArrayLike, last: bool = False
    ) -> tuple[Matrix, int]:
        """A chunk of rows (``codes``: each series numbered from 0 in order of first
        appearance in the stream); the columns ``(columns, rows)`` of the next ``rows`` rows of
        the stream (``auto``: up to the first whose outlier decision is still to come; with
        ``last``, all). Without ``tau`` the first chunk holds ``TAU_SCAN_ROWS`` rows or all."""
        ...

TAU_SCAN_ROWS: int
"""Rows the default ``tau`` (the median time step within series) is taken from."""

def seconds(t: ArrayLike, name: str = "t") -> Vector:
    """Times as every entry point reads them: numbers as they are; dates (numpy datetime64 of
    any unit, pandas datetime columns, tz-aware too, Polars Datetime/Date, Arrow timestamps and
    dates) as seconds since the Unix epoch (naive dates are UTC); timedelta64 as seconds."""

class Innovation:
    """What one Kalman update saw."""

    @property
    def components(self) -> list[int]: ...
    @property
    def innovation(self) -> Vector: ...
    @property
    def covariance(self) -> Matrix: ...
    @property
    def gain(self) -> Matrix: ...
    @property
    def nis(self) -> float: ...
    @property
    def log_likelihood(self) -> float: ...

class KalmanBank:
    """One Kalman filter's model over many series (the library's ``kalman::bank``).

    Parameters
    ----------
    degree : int
        The polynomial model's degree.
    x0 : array_like
        The prior state every series starts from at its first time, ``n = (degree + 1) * axes``.
    P0 : float or array_like
        The prior covariance (a number times the identity, the variances, or ``n x n``).
    R : float or array_like
        The measurement noise (a variance for every component, the variances, or ``p x p``).
    axes : int
        The axes of the model.
    q : float
        The white-noise driving's spectral density (0: none).
    observation : array_like, optional
        ``M``, ``p x n`` (default: the positions of the axes).

    Notes
    -----
    ``filter``, ``smooth`` and ``fixed_lag_smoother`` take ``series`` (int64 labels, any values,
    any order, series may interleave), ``t`` and ``z`` (``rows x p``, NaN missing), each
    series' times not decreasing, and return ``(state, sigma, nis)`` by input row (``nis``
    NaN where every component was missing). ``state`` and ``sigma`` are ``rows x n``
    arrays and ``nis`` a contiguous array of ``rows``: the bank's own buffers when each
    series' rows are already together (no copy), else one copy putting them back in input
    order. An error's ``.index`` is the input row.
    """

    def __init__(
        self,
        degree: int,
        x0: ArrayLike,
        P0: ArrayLike | float,
        R: ArrayLike | float,
        axes: int = 1,
        q: float = 0.0,
        observation: ArrayLike | None = None,
    ) -> None: ...
    @property
    def states(self) -> int: ...
    @property
    def components(self) -> int: ...
    def filter(
        self, series: npt.NDArray[np.int64], t: ArrayLike, z: ArrayLike
    ) -> tuple[Matrix, Matrix, Vector]: ...
    def smooth(
        self, series: npt.NDArray[np.int64], t: ArrayLike, z: ArrayLike
    ) -> tuple[Matrix, Matrix, Vector]: ...
    def fixed_lag_smoother(
        self, series: npt.NDArray[np.int64], t: ArrayLike, z: ArrayLike, lag: int
    ) -> tuple[Matrix, Matrix, Vector]: ...

class KalmanFilter:
    def __init__(
        self,
        degree: int,
        x0: ArrayLike,
        P0: ArrayLike | float,
        t0: float = 0.0,
        axes: int = 1,
        q: float = 0.0,
        observation: ArrayLike | None = None,
        theta: float | None = None,
        tau: float | None = None,
        theta_per_update: float | None = None,
    ) -> None: ...
    @property
    def state(self) -> Vector: ...
    @state.setter
    def state(self, value: ArrayLike) -> None: ...
    @property
    def covariance(self) -> Matrix: ...
    @covariance.setter
    def covariance(self, value: ArrayLike | float) -> None: ...
    @property
    def std_devs(self) -> Vector: ...
    @property
    def time(self) -> float: ...
    def predict(self, t: float) -> None: ...
    def update(self, t: float, z: ArrayLike | float, R: ArrayLike | float) -> Innovation | None: ...
    def update_many(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float
    ) -> tuple[Matrix, npt.NDArray[np.float64], Vector]: ...
    @overload
    def smooth(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float, return_gains: Literal[False] = ...
    ) -> tuple[Matrix, npt.NDArray[np.float64]]: ...
    @overload
    def smooth(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float, return_gains: Literal[True]
    ) -> tuple[Matrix, Cube, Cube, Cube]: ...
    def fixed_lag_smoother(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float, lag: int
    ) -> tuple[Matrix, npt.NDArray[np.float64]]:
        """The fixed-lag smoother from this filter's estimate (the filter is not changed).

        Parameters
        ----------
        t, z, R
            The measurements, as ``smooth`` takes them (NaN: a missing component).
        lag : int
            The lag, in measurements: each estimate is from the ``lag`` measurements after
            it (the last ``lag`` from all of them); ``lag`` at least ``len(t)`` gives
            ``smooth``'s, 0 the filter's.

        Returns
        -------
        states, covariances : ndarray
            ``(N, dim)`` and ``(N, dim, dim)``: measurement ``k``'s estimate, the
            whole-interval smoother's over measurements ``0..k+lag`` read at ``k``, computed
            holding ``lag + 1`` measurements however many there are. An error's ``.index``
            names the measurement.
        """

Transition = Callable[[Vector, float, float], ArrayLike]
Observe = Callable[[Vector, float], ArrayLike]
StepNoise = ArrayLike | float | Callable[[float, float], ArrayLike]
Derivative = Callable[[Vector, float], ArrayLike]

class UnscentedKalmanFilter:
    def __init__(
        self,
        degree: int | None = None,
        x0: ArrayLike | None = None,
        P0: ArrayLike | float | None = None,
        t0: float = 0.0,
        axes: int = 1,
        q: float = 0.0,
        observation: ArrayLike | Literal["radar"] | None = None,
        site: tuple[float, float, float] | None = None,
        sigma_points: tuple[float, float, float] = (1.0, 2.0, 0.0),
        *,
        f: Transition | None = None,
        h: Observe | None = None,
        Q: StepNoise | None = None,
        angles: list[int] | None = None,
        dxdt: Derivative | None = None,
    ) -> None: ...
    @property
    def state(self) -> Vector: ...
    @state.setter
    def state(self, value: ArrayLike) -> None: ...
    @property
    def covariance(self) -> Matrix: ...
    @covariance.setter
    def covariance(self, value: ArrayLike | float) -> None: ...
    @property
    def std_devs(self) -> Vector: ...
    @property
    def time(self) -> float: ...
    @property
    def sigma_points(self) -> tuple[float, float, float]: ...
    def predict(self, t: float) -> None: ...
    def update(self, t: float, z: ArrayLike | float, R: ArrayLike | float) -> Innovation | None: ...
    def update_many(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float
    ) -> tuple[Matrix, npt.NDArray[np.float64], Vector]: ...
    def smooth(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float
    ) -> tuple[Matrix, npt.NDArray[np.float64]]: ...
    def fixed_lag_smoother(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float, lag: int
    ) -> tuple[Matrix, npt.NDArray[np.float64]]:
        """The fixed-lag smoother from this filter's estimate (the filter is not changed).

        Parameters
        ----------
        t, z, R
            The measurements, as ``smooth`` takes them (NaN: a missing component).
        lag : int
            The lag, in measurements: each estimate is from the ``lag`` measurements after
            it (the last ``lag`` from all of them); ``lag`` at least ``len(t)`` gives
            ``smooth``'s, 0 the filter's.

        Returns
        -------
        states, covariances : ndarray
            ``(N, dim)`` and ``(N, dim, dim)``: measurement ``k``'s estimate, the
            whole-interval smoother's over measurements ``0..k+lag`` read at ``k``, computed
            holding ``lag + 1`` measurements however many there are. An error's ``.index``
            names the measurement.
        """

class LinearKalmanFilter:
    """The Kalman filter on a discrete-time linear model given by its matrices (filterpy's
    ``KalmanFilter``): ``x_k = F x_{k-1} + B u_k + w``, ``z_k = H x_k + v``."""

    def __init__(
        self,
        x0: ArrayLike,
        P0: ArrayLike | float,
        F: ArrayLike,
        H: ArrayLike,
        Q: ArrayLike | float,
        R: ArrayLike | float,
        B: ArrayLike | None = None,
    ) -> None: ...
    @property
    def x(self) -> Vector: ...
    @x.setter
    def x(self, value: ArrayLike) -> None: ...
    @property
    def P(self) -> Matrix: ...
    @P.setter
    def P(self, value: ArrayLike | float) -> None: ...
    @property
    def state(self) -> Vector: ...
    @state.setter
    def state(self, value: ArrayLike) -> None: ...
    @property
    def covariance(self) -> Matrix: ...
    @covariance.setter
    def covariance(self, value: ArrayLike | float) -> None: ...
    @property
    def std_devs(self) -> Vector: ...
    @property
    def steps(self) -> int: ...
    @property
    def F(self) -> Matrix: ...
    @F.setter
    def F(self, value: ArrayLike) -> None: ...
    @property
    def H(self) -> Matrix: ...
    @H.setter
    def H(self, value: ArrayLike) -> None: ...
    @property
    def Q(self) -> Matrix: ...
    @Q.setter
    def Q(self, value: ArrayLike | float) -> None: ...
    @property
    def R(self) -> Matrix: ...
    @R.setter
    def R(self, value: ArrayLike | float) -> None: ...
    def predict(
        self,
        u: ArrayLike | None = None,
        B: ArrayLike | None = None,
        F: ArrayLike | None = None,
        Q: ArrayLike | float | None = None,
    ) -> None:
        """One step: ``x = F x + B u``, ``P = F P Fᵀ + Q`` (this step's matrices where given)."""
    def update(
        self,
        z: ArrayLike | float | None,
        R: ArrayLike | float | None = None,
        H: ArrayLike | None = None,
    ) -> Innovation | None:
        """The update with ``z`` (NaN a missing component), Joseph's form."""
    def update_many(
        self,
        zs: ArrayLike,
        Fs: ArrayLike | None = None,
        Qs: ArrayLike | None = None,
        Hs: ArrayLike | None = None,
        Rs: ArrayLike | None = None,
        Bs: ArrayLike | None = None,
        us: ArrayLike | None = None,
    ) -> tuple[Matrix, npt.NDArray[np.float64], Matrix, npt.NDArray[np.float64]]:
        """filterpy's ``batch_filter``: ``(means, covariances, means_p, covariances_p)``."""
    def rts_smoother(
        self,
        Xs: ArrayLike,
        Ps: ArrayLike,
        Fs: ArrayLike | None = None,
        Qs: ArrayLike | None = None,
        Bs: ArrayLike | None = None,
        us: ArrayLike | None = None,
    ) -> tuple[Matrix, npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """filterpy's ``rts_smoother`` over a pass: ``(x, P, K, Pp)``."""
    def fixed_lag_smoother(
        self,
        zs: ArrayLike,
        lag: int,
        Fs: ArrayLike | None = None,
        Qs: ArrayLike | None = None,
        Hs: ArrayLike | None = None,
        Rs: ArrayLike | None = None,
        Bs: ArrayLike | None = None,
        us: ArrayLike | None = None,
    ) -> tuple[Matrix, npt.NDArray[np.float64]]:
        """Each measurement's estimate from the ``lag`` after it: ``(states, covariances)``."""

class LinearFixedLagSmoother:
    """The fixed-lag smoother on a LinearKalmanFilter's model, a measurement at a time, in
    memory bounded by the lag."""

    def __init__(self, filter: LinearKalmanFilter, lag: int) -> None: ...
    @property
    def pushed(self) -> int: ...
    @property
    def lag(self) -> int: ...
    def update(
        self,
        z: ArrayLike | float,
        u: ArrayLike | None = None,
        B: ArrayLike | None = None,
        F: ArrayLike | None = None,
        Q: ArrayLike | float | None = None,
        H: ArrayLike | None = None,
        R: ArrayLike | float | None = None,
    ) -> tuple[int, Vector, Matrix] | None:
        """One step; ``(index, state, covariance)`` of the step ``lag`` before, or ``None``."""
    def finish(self) -> tuple[npt.NDArray[np.int64], Matrix, npt.NDArray[np.float64]]:
        """The last ``lag`` steps: ``(indices, states, covariances)``."""

class ExtendedKalmanFilter:
    def __init__(
        self,
        x0: ArrayLike,
        P0: ArrayLike | float,
        f: Transition | None = None,
        h: Observe | None = None,
        Q: StepNoise | None = None,
        t0: float = 0.0,
        F_jacobian: Transition | None = None,
        H_jacobian: Observe | None = None,
        angles: list[int] | None = None,
        iterations: int = 1,
        tolerance: float = 1e-9,
        *,
        dxdt: Derivative | None = None,
        dxdt_jacobian: Derivative | None = None,
    ) -> None: ...
    @property
    def state(self) -> Vector: ...
    @state.setter
    def state(self, value: ArrayLike) -> None: ...
    @property
    def covariance(self) -> Matrix: ...
    @covariance.setter
    def covariance(self, value: ArrayLike | float) -> None: ...
    @property
    def std_devs(self) -> Vector: ...
    @property
    def time(self) -> float: ...
    def predict(self, t: float) -> None: ...
    def update(self, t: float, z: ArrayLike | float, R: ArrayLike | float) -> Innovation | None: ...
    def update_many(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float
    ) -> tuple[Matrix, npt.NDArray[np.float64], Vector]: ...
    def smooth(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float
    ) -> tuple[Matrix, npt.NDArray[np.float64]]: ...
    def fixed_lag_smoother(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float, lag: int
    ) -> tuple[Matrix, npt.NDArray[np.float64]]:
        """The fixed-lag smoother from this filter's estimate (the filter is not changed).

        Parameters
        ----------
        t, z, R
            The measurements, as ``smooth`` takes them (NaN: a missing component).
        lag : int
            The lag, in measurements: each estimate is from the ``lag`` measurements after
            it (the last ``lag`` from all of them); ``lag`` at least ``len(t)`` gives
            ``smooth``'s, 0 the filter's.

        Returns
        -------
        states, covariances : ndarray
            ``(N, dim)`` and ``(N, dim, dim)``: measurement ``k``'s estimate, the
            whole-interval smoother's over measurements ``0..k+lag`` read at ``k``, computed
            holding ``lag + 1`` measurements however many there are. An error's ``.index``
            names the measurement.
        """

def fit_model(
    x0: ArrayLike,
    t: ArrayLike,
    z: ArrayLike,
    R: ArrayLike | float,
    *,
    h: Observe,
    f: Transition | None = None,
    dxdt: Derivative | None = None,
    F_jacobian: Transition | None = None,
    H_jacobian: Observe | None = None,
    dxdt_jacobian: Derivative | None = None,
    angles: list[int] | None = None,
    epoch: str | float | None = None,
    max_iterations: int = 20,
) -> dict[str, object]: ...

class ContinuousModel:
    def __init__(self, A: ArrayLike, Qc: ArrayLike) -> None: ...
    @staticmethod
    def polynomial(
        degree: int, q: ArrayLike | float, axes: int | None = None
    ) -> ContinuousModel: ...
    @staticmethod
    def nearly_constant_velocity(
        q: ArrayLike | float, axes: int | None = None
    ) -> ContinuousModel: ...
    @staticmethod
    def nearly_constant_acceleration(
        q: ArrayLike | float, axes: int | None = None
    ) -> ContinuousModel: ...
    @staticmethod
    def singer(
        manoeuvre_alpha: float, manoeuvre_variance: float, axes: int = 1
    ) -> ContinuousModel: ...
    def discretise(self, dt: float) -> tuple[Matrix, Matrix]: ...
    @property
    def A(self) -> Matrix: ...
    @property
    def Qc(self) -> Matrix: ...
    @property
    def dimension(self) -> int: ...

class ContinuousKalmanFilter:
    def __init__(
        self,
        model: ContinuousModel,
        H: ArrayLike,
        R: ArrayLike | float,
        x0: ArrayLike,
        P0: ArrayLike | float,
        t0: float = 0.0,
    ) -> None: ...
    @property
    def state(self) -> Vector: ...
    @property
    def covariance(self) -> Matrix: ...
    @property
    def std_devs(self) -> Vector: ...
    @property
    def time(self) -> float: ...
    @property
    def H(self) -> Matrix: ...
    @property
    def R(self) -> Matrix: ...
    def predict(self, t: float) -> None: ...
    def update(
        self, t: float, z: ArrayLike | float, R: ArrayLike | float | None = None
    ) -> Innovation | None: ...
    def update_many(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float | None = None
    ) -> tuple[Matrix, npt.NDArray[np.float64], Vector]: ...
    @overload
    def smooth(
        self,
        t: ArrayLike,
        z: ArrayLike,
        R: ArrayLike | float | None = None,
        return_gains: Literal[False] = ...,
    ) -> tuple[Matrix, npt.NDArray[np.float64]]: ...
    @overload
    def smooth(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float | None, return_gains: Literal[True]
    ) -> tuple[Matrix, Cube, Cube, Cube]: ...
    def fixed_lag_smoother(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float | None, lag: int
    ) -> tuple[Matrix, npt.NDArray[np.float64]]:
        """The fixed-lag smoother from this filter's estimate (the filter is not changed).

        Parameters
        ----------
        t, z, R
            The measurements, as ``smooth`` takes them (NaN: a missing component);
            ``R`` ``None`` for the filter's own.
        lag : int
            The lag, in measurements: each estimate is from the ``lag`` measurements after
            it (the last ``lag`` from all of them); ``lag`` at least ``len(t)`` gives
            ``smooth``'s, 0 the filter's.

        Returns
        -------
        states, covariances : ndarray
            ``(N, dim)`` and ``(N, dim, dim)``: measurement ``k``'s estimate, the
            whole-interval smoother's over measurements ``0..k+lag`` read at ``k``, computed
            holding ``lag + 1`` measurements however many there are. An error's ``.index``
            names the measurement.
        """

class BayesFilter:
    def __init__(
        self,
        degree: int,
        t0: float = 0.0,
        axes: int = 1,
        observation: ArrayLike | None = None,
        x0: ArrayLike | None = None,
        P0: ArrayLike | float | None = None,
        theta: float | None = None,
        tau: float | None = None,
        theta_per_update: float | None = None,
        q: float = 0.0,
    ) -> None: ...
    @property
    def is_determined(self) -> bool: ...
    @property
    def state(self) -> Vector | None: ...
    @state.setter
    def state(self, value: ArrayLike) -> None: ...
    @property
    def covariance(self) -> Matrix | None: ...
    @covariance.setter
    def covariance(self, value: ArrayLike | float) -> None: ...
    def set_estimate(self, x: ArrayLike, P: ArrayLike | float) -> None: ...
    @property
    def std_devs(self) -> Vector | None: ...
    @property
    def information_covariance(self) -> Matrix | None: ...
    @property
    def time(self) -> float: ...
    def predict(self, t: float) -> None: ...
    def update(self, t: float, z: ArrayLike | float, R: ArrayLike | float) -> None: ...
    def update_many(
        self, t: ArrayLike, z: ArrayLike, R: ArrayLike | float
    ) -> tuple[Matrix, npt.NDArray[np.float64]]: ...

class RadarTracker:
    def __init__(
        self,
        method: Literal["kalman", "fading", "smooth", "window"] = "kalman",
        *,
        sigma_range: float | None = None,
        sigma_angle: float | None = None,
        site: tuple[float, float, float] = (0.0, 0.0, 0.0),
        q: float | None = None,
        theta: float | None = None,
        tau: float | None = None,
        theta_per_update: float | None = None,
        window: int | None = None,
        lag: int | None = None,
        azimuth: Literal["from-x", "bearing"] = "from-x",
        max_iterations: int = 20,
        model: Literal[
            "constant-velocity", "constant-acceleration", "singer", "coordinated-turn"
        ] = "constant-velocity",
        manoeuvre_alpha: float | None = None,
        manoeuvre_variance: float | None = None,
        turn_rate_noise: float | None = None,
    ) -> None: ...
    @property
    def rows_taken(self) -> int: ...
    def update_many(
        self,
        t: ArrayLike,
        range: ArrayLike,
        azimuth: ArrayLike,
        elevation: ArrayLike,
        sigma_range: ArrayLike | None = None,
        sigma_angle: ArrayLike | None = None,
    ) -> tuple[Matrix, npt.NDArray[np.float64], Vector, npt.NDArray[np.str_]]: ...
    def smoothed(
        self,
    ) -> tuple[
        npt.NDArray[np.int64], Matrix, npt.NDArray[np.float64], Vector, npt.NDArray[np.str_]
    ]: ...
    def finish(
        self,
    ) -> tuple[
        npt.NDArray[np.int64], Matrix, npt.NDArray[np.float64], Vector, npt.NDArray[np.str_]
    ]: ...

class CoordinatedTurn:
    def __init__(
        self, q: float, *, turn_rate: float | None = None, turn_rate_noise: float = 0.0
    ) -> None: ...
    @property
    def dim(self) -> int: ...
    @property
    def turn_rate(self) -> float | None: ...
    def f(self, x: ArrayLike, t0: float, t1: float) -> Vector: ...
    def F_jacobian(self, x: ArrayLike, t0: float, t1: float) -> Matrix: ...
    def Q(self, t0: float, t1: float) -> Matrix: ...

class SlidingFit:
    def __init__(
        self,
        model: Literal["radar", "polynomial"] = "radar",
        *,
        window: int | None = None,
        epoch: Literal["end", "centre", "center"] | float | None = "end",
        degree: int | None = None,
        site: tuple[float, float, float] | None = None,
        sigma_range: float | None = None,
        sigma_angle: float | None = None,
        sigma: float | None = None,
        azimuth: Literal["from-x", "bearing"] = "from-x",
        max_iterations: int = 20,
    ) -> None: ...
    @property
    def rows_taken(self) -> int: ...
    @overload
    def update_many(
        self, t: ArrayLike, y: ArrayLike, /
    ) -> tuple[Matrix, npt.NDArray[np.float64], dict[str, Vector]]: ...
    @overload
    def update_many(
        self, t: ArrayLike, range: ArrayLike, azimuth: ArrayLike, elevation: ArrayLike, /
    ) -> tuple[Matrix, npt.NDArray[np.float64], dict[str, Vector]]: ...

class Information:
    """One part of a long series' least-squares information: reduce each partition, merge
    (in any order), estimate the whole series' fit."""

    def __init__(
        self, degree: int, start: float, end: float, sigma: float | None = None
    ) -> None: ...
    @property
    def degree(self) -> int: ...
    @property
    def span(self) -> tuple[float, float]: ...
    @property
    def sigma(self) -> float | None: ...
    @property
    def samples(self) -> int: ...
    @property
    def has_prior(self) -> bool: ...
    def reduce(self, t: ArrayLike, y: ArrayLike) -> None: ...
    def merge(self, other: Information) -> None: ...
    def __add__(self, other: Information) -> Information: ...
    def add_prior(self, x0: ArrayLike, P0: ArrayLike | float, t0: float = 0.0) -> None: ...
    def estimate(self, t: float) -> State: ...
    def residual_sq(self) -> float: ...

Exact = Fraction | int | float | str

@overload
def gains(
    kind: Literal["expanding", "fading"],
    degree: int,
    n: int | None = None,
    theta: Exact | None = None,
    form: Literal["current", "predictor"] = "current",
    exact: Literal[False] = False,
) -> Vector: ...
@overload
def gains(
    kind: Literal["expanding", "fading"],
    degree: int,
    n: int | None = None,
    theta: Exact | None = None,
    form: Literal["current", "predictor"] = "current",
    *,
    exact: Literal[True],
) -> list[Fraction]: ...
@overload
def vrf(
    kind: Literal["expanding", "fading", "fixed"],
    degree: int,
    n: int | None = None,
    theta: Exact | None = None,
    window: int | None = None,
    lead: Exact | None = None,
    form: Literal["current", "predictor"] | None = None,
    exact: Literal[False] = False,
) -> Matrix: ...
@overload
def vrf(
    kind: Literal["expanding", "fading", "fixed"],
    degree: int,
    n: int | None = None,
    theta: Exact | None = None,
    window: int | None = None,
    lead: Exact | None = None,
    form: Literal["current", "predictor"] | None = None,
    *,
    exact: Literal[True],
) -> list[list[Fraction]]: ...
def error_kinds() -> list[tuple[str, str]]:
    """The library's error kinds, each with the name of its class in ``seqsmooth.errors``."""
    ...

def parameter_kinds() -> list[tuple[str, str, str]]:
    """Every parameter the library's errors name, with its error kind and its class."""
    ...

def gauss_rule(
    n: int,
    t: ArrayLike | None = None,
    weights: ArrayLike | None = None,
    kind: Literal["legendre", "chebyshev"] = "legendre",
    a: float = -1.0,
    b: float = 1.0,
) -> tuple[Vector, Vector]: ...
def polynomial_samples(
    t: ArrayLike,
    y: ArrayLike,
    sigma: float | ArrayLike,
    degree: int | None = None,
    *,
    n: int | None = None,
) -> tuple[Vector, Vector, Vector]: ...
@overload
def luenberger_gains(n: int, exact: Literal[False] = False) -> Vector: ...
@overload
def luenberger_gains(n: int, *, exact: Literal[True]) -> list[int]: ...
def fit_curve(
    h: Callable[[Vector, Vector], ArrayLike],
    t: ArrayLike,
    y: ArrayLike,
    sigma: float | ArrayLike,
    start: ArrayLike,
    jac: Callable[[Vector, Vector], ArrayLike] | None = None,
) -> CurveFit: ...
def cramer_rao_bound(
    h: Callable[[Vector, Vector], ArrayLike],
    theta: ArrayLike,
    t: ArrayLike,
    sigma: float | ArrayLike,
    jac: Callable[[Vector, Vector], ArrayLike] | None = None,
) -> Matrix: ...

class CurveFit:
    """A converged maximum-likelihood fit (``fit_curve``)."""

    @property
    def parameters(self) -> Vector: ...
    @property
    def covariance(self) -> Matrix: ...
    @property
    def std_devs(self) -> Vector: ...
    @property
    def standard_deviations(self) -> Vector:
        """``std_devs`` by its old name."""
    @property
    def chi_squared(self) -> float: ...
    @property
    def degrees_of_freedom(self) -> int: ...
    @property
    def condition_number(self) -> float: ...
    @property
    def correction(self) -> float: ...
    @property
    def evaluations(self) -> int: ...

class OnlineSmoother:
    """A segment's polynomial samples accumulated a sample at a time."""

    def __init__(
        self,
        t: ArrayLike,
        sigma: float | ArrayLike,
        degree: int | None = None,
        *,
        n: int | None = None,
    ) -> None: ...
    def push(self, y: float) -> None: ...
    def push_all(self, y: ArrayLike) -> None: ...
    @property
    def taken(self) -> int: ...
    @property
    def size(self) -> int: ...
    def polynomial_samples(self) -> tuple[Vector, Vector, Vector]: ...
    def reset(self) -> None: ...

class AutomaticFilter:
    def __init__(
        self,
        degree: int,
        theta: float,
        tau: float = 1.0,
        engine: Literal["exact", "gain"] = "exact",
        sigma: float | None = None,
        review_window: int | None = None,
    ) -> None: ...
    @property
    def degree(self) -> int: ...
    @property
    def samples(self) -> int: ...
    @property
    def decided(self) -> int: ...
    def update_many(self, t: ArrayLike, y: ArrayLike) -> dict[str, np.ndarray]: ...
    def finish(self) -> npt.NDArray[np.bool_]: ...
    def estimate(self) -> State: ...
    def estimate_at(self, t: float) -> State: ...

class Bank:
    @property
    def samples(self) -> int: ...
    def update(self, y: ArrayLike) -> None: ...
    def estimate(self) -> Matrix: ...

class FadingBank(Bank):
    def __init__(self, degree: int, theta: float, channels: int, tau: float = 1.0) -> None: ...

class ExpandingBank(Bank):
    def __init__(self, degree: int, channels: int, tau: float = 1.0) -> None: ...
