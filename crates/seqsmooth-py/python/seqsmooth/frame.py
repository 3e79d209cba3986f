"""``filter_frame``: many series in one data frame (pandas, Polars, a pyarrow Table, or a
dict of arrays), each filtered on its own with the same settings, the result the rows of
``seqsmooth filter --id-col`` as a frame of the same kind, in input order.

The columns are read as numpy arrays (no copy for numeric columns in pandas, Polars and
Arrow); the ``by`` column is factorised into series numbers; the library's ``StreamBank``
(``filter_series``, without the GIL) groups the rows by series, runs each series through one
filter as ``seqsmooth filter --id-col`` does (the series on the rayon pool) and puts the
estimates back in the input's row order.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np

from ._seqsmooth import KalmanBank, filter_series, seconds
from .errors import InvalidInputError, SeqsmoothError


def _column(frame: Any, name: str) -> np.ndarray:
    """Column ``name`` of a pandas or Polars DataFrame, a pyarrow Table or a mapping."""
    try:
        if hasattr(frame, "column_names") and hasattr(frame, "column"):  # pyarrow
            if name not in frame.column_names:
                raise KeyError(name)
            return frame.column(name).to_numpy()
        return np.asarray(frame[name])
    except (KeyError, IndexError, ValueError, TypeError) as e:
        if isinstance(e, SeqsmoothError):
            raise
        if isinstance(frame, Mapping):
            columns = list(frame.keys())
        else:
            columns = list(getattr(frame, "columns", getattr(frame, "column_names", [])))
        raise InvalidInputError(f"no column {name!r} in the frame (columns: {columns})") from None


def _raw_column(frame: Any, name: str) -> Any:
    """Column ``name`` as the frame holds it (a pandas or Polars Series keeps its dtype, a
    tz-aware one too), for :func:`seconds`."""
    if hasattr(frame, "column_names") and hasattr(frame, "column"):  # pyarrow
        return _column(frame, name)
    try:
        return frame[name]
    except (KeyError, IndexError, ValueError, TypeError):
        return _column(frame, name)  # raises the error naming the columns


def _codes(keys: np.ndarray, by: str) -> tuple[np.ndarray, Any]:
    """Each row's series as a number from 0 (pandas' hash factorisation when pandas is
    there, else numpy's sort), and the series' names by number."""
    try:
        import pandas
    except ImportError:
        names, codes = np.unique(keys, return_inverse=True)
        return codes.astype(np.int64), names
    codes, names = pandas.factorize(keys)
    missing = np.flatnonzero(codes < 0)
    if missing.size:
        i = int(missing[0])
        raise InvalidInputError(f"row {i}: the {by!r} cell is empty (no series)", i)
    return codes.astype(np.int64, copy=False), np.asarray(names)


def _times(frame: Any, name: str) -> np.ndarray:
    """Column ``name`` as seconds (:func:`seconds`); a ``float64`` column as it is (the
    numbers :func:`seconds` would copy, not copied: contiguous and aligned, else converted)."""
    raw = _raw_column(frame, name)
    dtype = getattr(raw, "dtype", None)
    if isinstance(dtype, np.dtype) and dtype == np.float64 and np.ndim(raw) == 1:
        return np.require(np.asarray(raw), np.float64, ["C", "A"])
    return seconds(raw, name)


def _same_data(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether ``a`` and ``b`` are the same numbers in the same memory (shape, dtype, strides
    and address), in constant time."""
    return (
        a.shape == b.shape
        and a.dtype == b.dtype
        and a.strides == b.strides
        and a.__array_interface__["data"][0] == b.__array_interface__["data"][0]
    )


def _like(frame: Any, columns: dict[str, np.ndarray], kept: Sequence[str] = ()) -> Any:
    """``columns`` as a frame of the kind of ``frame``, no column copied; ``kept`` names the
    columns that may be ``frame``'s own columns as they are.

    pandas: such a column is the input's own pandas column (on the result's ``RangeIndex``),
    so the result shares its memory under pandas' copy-on-write (the first write to either
    frame copies that column: the result's columns are all writable, and writing them never
    changes the input); the new columns are the arrays as they are (no copy into a
    consolidated block). Polars and Arrow: their constructors' own rules, as before.
    """
    module = type(frame).__module__.split(".")[0]
    if module == "pandas":
        import pandas

        data: dict[str, Any] = dict(columns)
        for name in kept:
            column = frame[name]
            # Only a column held in a numpy array is compared (``np.asarray`` is then a view);
            # any other (strings, categorical, nullable) was converted, so it is not the same.
            if (
                isinstance(column, pandas.Series)
                and isinstance(column.dtype, np.dtype)
                and _same_data(np.asarray(column), columns[name])
            ):
                data[name] = column.reset_index(drop=True)
        return pandas.DataFrame(data, copy=False)
    if module == "polars":
        import polars

        return polars.DataFrame(columns)
    if module == "pyarrow":
        import pyarrow

        return pyarrow.table(columns)
    return columns


def _in_row(e: SeqsmoothError, by: str | None, names: Any, codes: np.ndarray) -> SeqsmoothError:
    """``e`` naming the frame's row (``.index``) and its series, or ``e`` itself without a row."""
    if e.index is None:
        return e
    message = str(e)
    if message.startswith("sample ") and ": " in message:
        message = message.split(": ", 1)[1]  # the row is named below
    series = "" if by is None else f" (series {names[codes[e.index]]!r} of column {by!r})"
    return type(e)(f"row {e.index}{series}: {message}", e.index)


def filter_frame(
    df: Any,
    time: str = "t",
    value: str = "y",
    by: str | None = None,
    kind: Literal["expanding", "fading", "fixed", "auto"] = "fading",
    degree: int = 1,
    theta: float | None = None,
    tau: float | None = None,
    window: int | None = None,
    engine: str | None = None,
    sigma: float | None = None,
    review_window: int | None = None,
) -> Any:
    """Filters every series of a frame, as ``seqsmooth filter [--id-col BY]`` does.

    Parameters
    ----------
    df : pandas.DataFrame, polars.DataFrame, pyarrow.Table or dict of arrays
        The rows; each series' times strictly increasing (series may interleave).
    time, value : str
        The time and value columns. The times may be numbers or dates (numpy
        ``datetime64``, pandas datetime, tz-aware too, Polars ``Datetime``/``Date``, Arrow
        timestamps), read as seconds since the Unix epoch (naive dates are UTC).
    by : str, optional
        The column naming each row's series (any type); without it the frame is one series.
    kind : {"expanding", "fading", "fixed", "auto"}
        ``"auto"``: the automatic filter (:class:`AutomaticFilter`, ``seqsmooth filter --kind
        auto``).
    degree, theta, window, engine, sigma, review_window
        As for :class:`ExpandingMemory`, :class:`FadingMemory`, :class:`FixedMemory` and
        :class:`AutomaticFilter` (``engine`` defaults to ``"exact"``, for ``fixed`` to
        ``"adaptive"``; ``review_window`` only for ``auto``).
    tau : float, optional
        ``fading`` and ``auto``: the time interval ``theta`` discounts over. Default: the
        median of the first 100 time steps within series among the first 65536 rows, as
        ``seqsmooth filter`` takes it without ``--tau`` (so ``theta`` is the discount per
        typical step); :class:`FadingMemory`'s and :class:`AutomaticFilter`'s own default is
        ``1.0``, a unit of time.

    Returns
    -------
    The kind of ``df`` with the columns of ``seqsmooth filter``'s CSV: ``[by,] time, value,
    d0..dM`` (``time`` in seconds, as the filter read it; ``dk`` the estimate at each row's
    time, from its series up to that row), then
    ``s0..sM`` (their 1σ) with ``sigma`` (always for ``auto``), then ``window`` (rows in the
    window) for ``fixed``; for ``auto`` ``noise`` (the noise σ in use), ``outlier`` (the
    final decision, the whole series being there: 1 rejected), ``misfit`` (0/1) and ``bias``
    (the estimated bias of ``d0``, included in ``s0``); NaN where the command leaves a cell
    empty (the series not yet determined, the automatic filter's estimate withheld). Rows in
    input order.

    Raises
    ------
    SeqsmoothError
        As ``update_many``; ``.index`` is the row of the frame, and the message names its
        series.
    """
    t = seconds(_raw_column(df, time), time)
    y = np.ascontiguousarray(_column(df, value), dtype=np.float64)
    n = len(t)
    if n == 0:
        raise InvalidInputError("the frame has no rows")
    keys = None if by is None else _column(df, by)
    codes, names = (np.zeros(n, dtype=np.int64), [None]) if keys is None else _codes(keys, by)
    try:
        result = filter_series(
            codes,
            t,
            y,
            kind,
            degree,
            theta=theta,
            tau=tau,
            window=window,
            engine=engine,
            sigma=sigma,
            review_window=review_window,
        )
    except SeqsmoothError as e:
        raise _in_row(e, by, names, codes) from e
    values, names_out = result
    columns: dict[str, np.ndarray] = {}
    if keys is not None:
        columns[by] = keys
    columns[time] = t
    columns[value] = y
    for name, column in zip(names_out, values):
        columns[name] = column
    return _like(df, columns, kept=[c for c in (by, value) if c is not None])


def kalman_frame(
    df: Any,
    time: str = "t",
    value: str | Sequence[str] = "y",
    by: str | None = None,
    *,
    degree: int = 1,
    P0: Any,
    R: Any = 1.0,
    q: float = 0.0,
    x0: Any = None,
    smoother: Literal["filter", "rts", "fixed_lag"] = "filter",
    lag: int | None = None,
) -> Any:
    """Runs one Kalman filter's model over every series of a frame (:class:`KalmanBank`).

    The polynomial model of ``degree`` on as many axes as ``value`` names columns (each
    column the position on its axis), white-noise driving of spectral density ``q``; every
    series starts from ``x0``, ``P0`` at its own first time.

    Parameters
    ----------
    df : pandas.DataFrame, polars.DataFrame, pyarrow.Table or dict of arrays
        The rows; series may interleave, each series' times not decreasing.
    time : str
        The time column (numbers or dates, read as :func:`seconds` reads them).
    value : str or sequence of str
        The observed column(s), one per axis; NaN (or null) marks a missing component.
    by : str, optional
        The column naming each row's series (any type); without it the frame is one series.
    degree : int
        The polynomial model's degree (1: constant velocity).
    P0 : float, sequence or array
        The prior covariance every series starts from (a number times the identity, the
        variances, or ``n x n``), ``n = (degree + 1) * axes``.
    R : float, sequence or array
        The measurement noise: a variance for every component, the variances, or ``p x p``.
    q : float
        The driving noise's spectral density (0: none).
    x0 : array, optional
        The prior state (default zeros), ``[x_axes..., x'_axes..., ...]``.
    smoother : {"filter", "rts", "fixed_lag"}
        The filter's estimates, the Rauch–Tung–Striebel smoother's (from the whole series), or
        the fixed-lag smoother's (from the ``lag`` rows after each row).
    lag : int, optional
        The fixed-lag smoother's lag, in rows (``smoother="fixed_lag"`` only).

    Returns
    -------
    The kind of ``df`` with the columns ``[by,] time, value...``, the estimate's derivatives
    ``d0..dM`` and their 1σ ``s0..sM`` (``M = degree``; named as :func:`filter_frame` names
    them; with several value columns ``<value>_d0..``, ``<value>_s0..`` for each), and
    ``nis`` (the update's normalised innovation squared, NaN where every component was
    missing), one row per input row, in input order. The input's columns that need no
    conversion (``float64`` times and values, numeric numpy ids) are not copied: for pandas
    they are the input's columns under copy-on-write (every column of the result writable;
    writing either frame copies the column written, the other unchanged; pandas before 3
    without copy-on-write may copy them), for a dict the caller's arrays themselves (a
    ``float64`` time column too); other columns (strings, categorical, nullable, integer or
    date times) are converted copies.

    Raises
    ------
    SeqsmoothError
        A bad setting, or a bad row: ``.index`` is the row of the frame, and the message
        names its series.

    Examples
    --------
    >>> import numpy as np, seqsmooth
    >>> rows = {"id": np.array([0, 1, 0, 1]), "t": np.array([0.0, 0.0, 1.0, 2.0]),
    ...         "y": np.array([1.0, 5.0, 2.0, np.nan])}
    >>> out = seqsmooth.kalman_frame(rows, by="id", P0=100.0, R=1.0)
    >>> sorted(out)
    ['d0', 'd1', 'id', 'nis', 's0', 's1', 't', 'y']
    """
    values = [value] if isinstance(value, str) else list(value)
    if not values:
        raise InvalidInputError("value names no column")
    t = _times(df, time)
    rows = len(t)
    if rows == 0:
        raise InvalidInputError("the frame has no rows")
    columns_in = [np.asarray(_column(df, v), dtype=np.float64) for v in values]
    # One value column is z as it is (one component a row); several are stacked by row.
    z = columns_in[0] if len(values) == 1 else np.column_stack(columns_in)
    # Contiguous and aligned (a partition unpickled from a buffer may be neither).
    z = np.require(z, np.float64, ["C", "A"])
    axes = len(values)
    n = (degree + 1) * axes
    bank = KalmanBank(degree, np.zeros(n) if x0 is None else x0, P0, R, axes=axes, q=q)
    keys = None if by is None else _column(df, by)
    names_by_row = False
    if keys is None:
        codes, names = np.zeros(rows, dtype=np.int64), [None]
    elif keys.ndim == 1 and keys.dtype.kind in "iu" and np.can_cast(keys.dtype, np.int64):
        # Integer ids are the bank's series labels as they are (grouped there, no hashing
        # here); a row's series is its own id.
        codes, names, names_by_row = np.require(keys, np.int64, ["C", "A"]), keys, True
    else:
        codes, names = _codes(keys, by)
    if smoother != "fixed_lag" and lag is not None:
        raise InvalidInputError(f"lag is for smoother='fixed_lag', not {smoother!r}")
    try:
        if smoother == "filter":
            state, sigma, nis = bank.filter(codes, t, z)
        elif smoother == "rts":
            state, sigma, nis = bank.smooth(codes, t, z)
        elif smoother == "fixed_lag":
            if lag is None:
                raise InvalidInputError("smoother='fixed_lag' needs lag")
            state, sigma, nis = bank.fixed_lag_smoother(codes, t, z, lag)
        else:
            raise InvalidInputError(
                f"smoother {smoother!r} is not one of 'filter', 'rts', 'fixed_lag'"
            )
    except SeqsmoothError as e:
        if names_by_row and e.index is not None:
            # The row's series is its own id, named as a Python number.
            names, codes = {e.index: keys[e.index].item()}, range(rows)
        raise _in_row(e, by, names, codes) from e
    columns: dict[str, np.ndarray] = {}
    if keys is not None:
        columns[by] = keys
    columns[time] = t
    for name, column in zip(values, columns_in):
        columns[name] = column
    # The state is [positions of the axes, their first derivatives, ...]: component k·axes + a
    # is axis a's k-th derivative, named as filter_frame names derivatives (``d``/``s`` and k),
    # after the axis' value column when there are several.
    prefixes = [""] if axes == 1 else [f"{v}_" for v in values]
    for letter, numbers in (("d", state), ("s", sigma)):
        for a, prefix in enumerate(prefixes):
            for k in range(degree + 1):
                columns[f"{prefix}{letter}{k}"] = numbers[:, k * axes + a]
    columns["nis"] = nis
    return _like(df, columns, kept=[c for c in (by, time, *values) if c is not None])
