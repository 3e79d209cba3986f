"""seqsmooth: sequential smoothing and prediction (Morrison, *Introduction to Sequential
Smoothing and Prediction*, 1969), a binding of the Rust library of the same name.

Filters
-------
ExpandingMemory, FadingMemory, FixedMemory
    The polynomial filters of any degree on any (irregular, Unix-epoch) timestamps:
    ``update(t, y)``, ``update_many(t, y) -> ndarray``, ``estimate()``, ``estimate_at(t)``.

AutomaticFilter
    Expanding start, fading memory, outlier rejection, noise estimation, misfit restarts and
    degree settling, with each sample's flags.
FadingBank, ExpandingBank
    Many channels on one even time grid, a time step of all channels at a time.
KalmanFilter
    The Kalman filter over the polynomial model (Morrison chs. 12, 14, 15): driving noise,
    fading memory, missing components, ``update_many`` and the RTS ``smooth``.
KalmanBank
    One Kalman filter's model (the polynomial model, driving noise, missing components) over
    many series, each with its own times: the filter, the RTS and fixed-lag smoothers, the
    series on the rayon pool.
LinearKalmanFilter
    The Kalman filter on your own matrices ``F``, ``H``, ``Q``, ``R``, ``B u`` (filterpy's
    ``KalmanFilter``), constant or one per step: ``update_many`` (``batch_filter``), the RTS
    smoother over that pass with its gains, and the fixed-lag smoother (streamed:
    ``LinearFixedLagSmoother``).
ContinuousModel, ContinuousKalmanFilter
    A continuous linear model ``dX/dt = A X + w`` (your ``A`` and spectral density ``Qc``, or
    nearly constant velocity/acceleration, Singer, the polynomial model) discretised exactly
    over each actual step, and the Kalman filter on it with each measurement at its own time.
BayesFilter
    The Bayes filter (Morrison ch. 10) in square-root information form over the same model:
    starts from no information, fading memory with the true covariance.
RadarTracker
    A radar's range, azimuth and elevation to a track of a built-in motion model (constant
    velocity, constant acceleration, Singer, coordinated turn): the sliding Gauss–Newton fit,
    the extended Kalman filter (driving noise or fading memory) or its smoother; the numbers
    of ``seqsmooth track``.
CoordinatedTurn
    The library's coordinated-turn model (known or estimated turn rate) as the ``f``,
    ``F_jacobian`` and ``Q`` callables of ``ExtendedKalmanFilter`` and
    ``UnscentedKalmanFilter``.
SlidingFit
    Gauss–Newton differential correction of each row's window of the last W rows (Morrison
    §8.5-8.7), radar or scalar polynomial model: ``update_many`` gives the states,
    covariances, iterations, chi-squared and epochs of ``seqsmooth fit``.
Information
    One long series cut into partitions (on Dask, Spark, or anywhere): each partition's
    least-squares information, merged exactly, gives the single pass's expanding-memory,
    least-squares or Bayes fit (``reduce``, ``merge`` or ``+``, ``add_prior``, ``estimate``).

Functions
---------
smooth
    ``scipy.signal.savgol_filter``'s names and meaning, on irregular times too.
fit_model
    The Gauss–Newton fit (Morrison §8.5-8.7) of your own model's state at one epoch (``f`` or
    ``dxdt``, ``h``) to a window of measurements: the state, its covariance, chi-squared.
filter_frame
    Many series of a pandas or Polars DataFrame or a pyarrow Table, one filter each: the rows
    of ``seqsmooth filter --id-col``, as a frame of the same kind.
kalman_frame
    Many series of a frame through a ``KalmanBank``: the estimates, their σ and the NIS, as a
    frame of the same kind.
gains, vrf
    The gains and variance-reduction matrices of Morrison's tables, in floats or exactly as
    ``fractions.Fraction``.

seconds
    Times as the entry points read them: numbers as they are, dates (numpy ``datetime64``,
    pandas, Polars, Arrow) as seconds since the Unix epoch (naive dates are UTC).

Conventions: every argument ``t`` takes numbers or dates (read as by ``seconds``);
derivatives are unscaled, in the caller's time units (``[x, x', x'', ...]``);
every error is a :class:`SeqsmoothError` (a ``ValueError``) naming the bad value and, in a
batch, its ``index``.
"""

from . import errors
from ._seqsmooth import (
    MAX_DEGREE,
    AutomaticFilter,
    BayesFilter,
    ContinuousKalmanFilter,
    ContinuousModel,
    CoordinatedTurn,
    CurveFit,
    ExpandingBank,
    ExpandingMemory,
    ExtendedKalmanFilter,
    FadingBank,
    FadingMemory,
    FixedMemory,
    Information,
    Innovation,
    KalmanBank,
    KalmanFilter,
    LinearFixedLagSmoother,
    LinearKalmanFilter,
    OnlineSmoother,
    PolynomialFilter,
    RadarTracker,
    SlidingFit,
    State,
    UnscentedKalmanFilter,
    __version__,
    cramer_rao_bound,
    fit_curve,
    fit_model,
    gains,
    gauss_rule,
    luenberger_gains,
    polynomial_samples,
    seconds,
    smooth,
    vrf,
)
from .errors import (
    DamagedStateError,
    InvalidInputError,
    InvalidTypeError,
    NotDeterminedError,
    NumericalError,
    ParameterError,
    SeqsmoothError,
    TooFewSamplesError,
)
from .frame import filter_frame, kalman_frame

__all__ = [
    "__version__",
    "MAX_DEGREE",
    "AutomaticFilter",
    "BayesFilter",
    "ExpandingBank",
    "ExpandingMemory",
    "FadingBank",
    "FadingMemory",
    "FixedMemory",
    "KalmanFilter",
    "KalmanBank",
    "UnscentedKalmanFilter",
    "LinearKalmanFilter",
    "LinearFixedLagSmoother",
    "ContinuousModel",
    "ContinuousKalmanFilter",
    "ExtendedKalmanFilter",
    "RadarTracker",
    "CoordinatedTurn",
    "SlidingFit",
    "Information",
    "Innovation",
    "PolynomialFilter",
    "State",
    "smooth",
    "seconds",
    "filter_frame",
    "kalman_frame",
    "gains",
    "vrf",
    "gauss_rule",
    "polynomial_samples",
    "OnlineSmoother",
    "fit_curve",
    "fit_model",
    "cramer_rao_bound",
    "CurveFit",
    "luenberger_gains",
    "errors",
    "SeqsmoothError",
    "InvalidInputError",
    "InvalidTypeError",
    "ParameterError",
    "TooFewSamplesError",
    "NotDeterminedError",
    "NumericalError",
    "DamagedStateError",
]
