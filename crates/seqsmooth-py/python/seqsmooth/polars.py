"""Polars expressions: the polynomial filters, ``smooth`` and the polynomial Kalman filter over
a value column with a time column (``time=``), each returning a struct of the estimates, their
1σ and the kind's flags, for ``select``/``with_columns``, ``.over(id)``, lazy queries and the
streaming engine::

    import polars as pl
    import seqsmooth.polars as ssp

    df = pl.DataFrame({"id": ["a", "b"] * 50, "t": [float(i) for i in range(100)],
                       "y": [0.1 * i for i in range(100)]})
    out = df.with_columns(
        f=ssp.filter("y", time="t", kind="fading", degree=1, theta=0.9, tau=2.0, sigma=0.5)
        .over("id")
    ).unnest("f")
    assert out.columns[-4:] == ["d0", "d1", "s0", "s1"]

Each expression is a ``map_batches`` of the package's compiled functions (the numbers of
:func:`seqsmooth.filter_frame`, :func:`seqsmooth.smooth` and
:class:`seqsmooth.KalmanFilter`, bit for bit), not a compiled Polars plugin: a compiled plugin
links pyo3-polars, whose pyo3 differs from the binding's, into a second extension that compiles
the Polars crates (docs/python.md, "Polars expressions"). The filter is sequential: each
call receives a whole series (with ``.over(id)``, one series; without, the whole column), so
Polars holds the series' columns in memory even in the streaming engine: memory is bounded by
the longest series' columns, not by the filter's window (BENCHMARKS.md, "Polars expressions").
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
import polars as pl

from ._seqsmooth import KalmanFilter, filter_series, seconds
from ._seqsmooth import smooth as _smooth
from .errors import ParameterError

__all__ = ["filter", "smooth", "kalman"]


def _expr(column: str | pl.Expr) -> pl.Expr:
    return pl.col(column) if isinstance(column, str) else column


def _map(value: Any, time: Any, names: list[str], run: Any) -> pl.Expr:
    """``run(t, y) -> list of float64 columns`` over the struct of the time and value
    columns, as a Polars struct of ``names`` (all Float64)."""
    dtype = pl.Struct({name: pl.Float64 for name in names})

    def batch(s: pl.Series) -> pl.Series:
        if len(s) == 0:
            return pl.Series(s.name, [], dtype=dtype)
        t = seconds(s.struct.field("t"), "t")
        columns = run(t, s.struct.field("y").to_numpy())
        return pl.DataFrame(dict(zip(names, columns)), schema=dtype.to_schema()).to_struct(s.name)

    return pl.struct(_expr(time).alias("t"), _expr(value).cast(pl.Float64).alias("y")).map_batches(
        batch, return_dtype=dtype
    )


def filter(
    value: str | pl.Expr,
    *,
    time: str | pl.Expr = "t",
    kind: Literal["expanding", "fading", "fixed", "auto"] = "fading",
    degree: int = 1,
    theta: float | None = None,
    tau: float | None = None,
    window: int | None = None,
    engine: str | None = None,
    sigma: float | None = None,
    review_window: int | None = None,
) -> pl.Expr:
    """The polynomial filter of ``kind`` over ``value`` at the times ``time`` (numbers, or
    Polars ``Datetime``/``Date`` read as seconds since the Unix epoch): a struct of
    :func:`seqsmooth.filter_frame`'s columns ``d0..dM``, ``s0..sM`` (with ``sigma``; always
    for ``auto``), then ``window`` (``fixed``) or ``noise``, ``outlier``, ``misfit``, ``bias``
    (``auto``); NaN where ``filter_frame`` has NaN. The settings are ``filter_frame``'s, but
    ``fading`` and ``auto`` need ``tau``: ``filter_frame``'s default is the median step over
    the whole frame, which an expression, seeing one series at a time, cannot know.

    Raises
    ------
    ParameterError
        At once, for settings the filter refuses (and ``tau`` missing where needed).
    """
    if kind in ("fading", "auto") and tau is None:
        raise ParameterError(
            f"tau is needed for kind {kind!r} in an expression "
            "(filter_frame's default is the median step over the whole frame)"
        )
    settings = dict(
        theta=theta,
        tau=tau,
        window=window,
        engine=engine,
        sigma=sigma,
        review_window=review_window,
    )
    # One row through the filter: the settings checked now, and the columns' names.
    _, names = filter_series(np.zeros(1, np.int64), [0.0], [0.0], kind, degree, **settings)

    def run(t: np.ndarray, y: np.ndarray) -> list[np.ndarray]:
        values, _ = filter_series(np.zeros(len(t), np.int64), t, y, kind, degree, **settings)
        return list(values)

    return _map(value, time, list(names), run)


def smooth(
    value: str | pl.Expr,
    *,
    time: str | pl.Expr = "t",
    window_length: int,
    polyorder: int,
    sigma: float | None = None,
) -> pl.Expr:
    """:func:`seqsmooth.smooth` (the centred least-squares window, ``savgol_filter``'s
    names) over ``value`` at the times ``time``: a struct of ``d0..dM`` (``M = polyorder``) and
    their 1σ ``s0..sM``, each the numbers of ``smooth(y, window_length, polyorder, deriv=k,
    t=t, sigma=sigma, return_sigma=True)``."""
    names = [f"d{k}" for k in range(polyorder + 1)] + [f"s{k}" for k in range(polyorder + 1)]

    def run(t: np.ndarray, y: np.ndarray) -> list[np.ndarray]:
        fits = [
            _smooth(y, window_length, polyorder, deriv=k, t=t, sigma=sigma, return_sigma=True)
            for k in range(polyorder + 1)
        ]
        return [v for v, _ in fits] + [s for _, s in fits]

    return _map(value, time, names, run)


def kalman(
    value: str | pl.Expr,
    *,
    time: str | pl.Expr = "t",
    degree: int,
    x0: Any,
    P0: Any,
    R: float,
    q: float = 0.0,
    t0: float | None = None,
    theta: float | None = None,
    tau: float | None = None,
) -> pl.Expr:
    """The polynomial Kalman filter (:class:`seqsmooth.KalmanFilter` of ``degree``, one axis,
    from ``x0``, ``P0`` at ``t0`` — default each series' first time — with white-noise
    intensity ``q`` and fading ``theta`` per ``tau``) updated with every ``value`` of noise
    variance ``R`` at the times ``time``: a struct of the state ``d0..dM`` (the derivatives,
    named as ``filter``'s), its 1σ ``s0..sM`` and ``nis`` (the normalised innovation squared,
    the misfit flag's statistic), the numbers of ``KalmanFilter.update_many``."""
    width = degree + 1
    names = [f"d{k}" for k in range(width)] + [f"s{k}" for k in range(width)] + ["nis"]
    settings = dict(q=q, theta=theta, tau=tau)
    KalmanFilter(degree, x0, P0, 0.0 if t0 is None else t0, **settings)  # settings checked now

    def run(t: np.ndarray, y: np.ndarray) -> list[np.ndarray]:
        start = t[0] if t0 is None else t0
        states, covariances, nis = KalmanFilter(degree, x0, P0, start, **settings).update_many(
            t, y, R
        )
        sd = np.sqrt(np.diagonal(covariances, axis1=1, axis2=2))
        return [states[:, k] for k in range(width)] + [sd[:, k] for k in range(width)] + [nis]

    return _map(value, time, names, run)
