"""``filter_frame``: many series in one data frame (pandas, Polars, a pyarrow Table, or a
dict of arrays), each filtered on its own with the same settings, the result the rows of
``seqsmooth filter --id-col`` as a frame of the same kind, in input order.

The columns are read as numpy arrays (no copy for numeric columns in pandas, Polars and
Arrow); the rows are grouped by the ``by`` column (stable, so each series keeps its input
order) and each series runs through one filter's ``update_many`` (the GIL released, the
series on a thread pool); the estimates are scattered back to the input rows.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from ._seqsmooth import ExpandingMemory, FadingMemory, FixedMemory
from .errors import InvalidInputError, ParameterError, SeqsmoothError


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


def _like(frame: Any, columns: dict[str, np.ndarray]) -> Any:
    """``columns`` as a frame of the kind of ``frame``."""
    module = type(frame).__module__.split(".")[0]
    if module == "pandas":
        import pandas

        return pandas.DataFrame(columns)
    if module == "polars":
        import polars

        return polars.DataFrame(columns)
    if module == "pyarrow":
        import pyarrow

        return pyarrow.table(columns)
    return columns


def filter_frame(
    df: Any,
    time: str = "t",
    value: str = "y",
    by: str | None = None,
    kind: str = "fading",
    degree: int = 1,
    theta: float | None = None,
    tau: float = 1.0,
    window: int | None = None,
    engine: str | None = None,
    sigma: float | None = None,
    threads: int | None = None,
) -> Any:
    """Filters every series of a frame, as ``seqsmooth filter [--id-col BY]`` does.

    Parameters
    ----------
    df : pandas.DataFrame, polars.DataFrame, pyarrow.Table or dict of arrays
        The rows; each series' times strictly increasing (series may interleave).
    time, value : str
        The time and value columns.
    by : str, optional
        The column naming each row's series (any type); without it the frame is one series.
    kind : {"expanding", "fading", "fixed"}
    degree, theta, tau, window, engine, sigma
        As for :class:`ExpandingMemory`, :class:`FadingMemory` and :class:`FixedMemory`
        (``engine`` defaults to ``"exact"``, for ``fixed`` to ``"adaptive"``).
    threads : int, optional
        Series filtered at once (default: the CPU count).

    Returns
    -------
    The kind of ``df`` with the columns of ``seqsmooth filter``'s CSV: ``[by,] time, value,
    d0..dM`` (the estimate at each row's time, from its series up to that row), then
    ``s0..sM`` (their 1σ) with ``sigma``, then ``window`` (rows in the window) for ``fixed``;
    NaN where the series is not yet determined. Rows in input order.

    Raises
    ------
    SeqsmoothError
        As ``update_many``; ``.index`` is the row of the frame, and the message names its
        series.
    """
    if kind == "expanding":
        make = lambda: ExpandingMemory(degree, engine=engine or "exact", sigma=sigma)  # noqa: E731
    elif kind == "fading":
        if theta is None:
            raise ParameterError("kind 'fading' needs theta, the discount per tau (0 < theta < 1)")
        make = lambda: FadingMemory(  # noqa: E731
            degree, theta, tau=tau, engine=engine or "exact", sigma=sigma
        )
    elif kind == "fixed":
        if window is None:
            raise ParameterError("kind 'fixed' needs window, the number of samples in the window")
        make = lambda: FixedMemory(  # noqa: E731
            degree, window, engine=engine or "adaptive", sigma=sigma
        )
    else:
        raise ParameterError(f"kind {kind!r} is not one of 'expanding', 'fading', 'fixed'")
    make()  # the settings checked once, before any row
    t = np.ascontiguousarray(_column(df, time), dtype=np.float64)
    y = np.ascontiguousarray(_column(df, value), dtype=np.float64)
    n = len(t)
    if n == 0:
        raise InvalidInputError("the frame has no rows")
    if by is None:
        keys, codes = None, np.zeros(n, dtype=np.intp)
        groups = [np.arange(n)]
        names = [None]
    else:
        keys = _column(df, by)
        names, codes = np.unique(keys, return_inverse=True)
        order = np.argsort(codes, kind="stable")
        cuts = np.flatnonzero(np.diff(codes[order])) + 1
        groups = np.split(order, cuts)
    width = degree + 1
    d = np.full((n, width), np.nan)
    s = np.full((n, width), np.nan) if sigma is not None else None

    def run(rows: np.ndarray) -> None:
        f = make()
        out = f.update_many(t[rows], y[rows], return_sigma=sigma is not None)
        if s is None:
            d[rows] = out
        else:
            d[rows], s[rows] = out

    errors: list[tuple[int, BaseException]] = []

    def guarded(k: int) -> None:
        try:
            run(groups[k])
        except SeqsmoothError as e:
            errors.append((k, e))

    with ThreadPoolExecutor(max_workers=threads or os.cpu_count() or 1) as pool:
        list(pool.map(guarded, range(len(groups))))
    if errors:
        # The error of the earliest bad row in the frame.
        def row(item):
            k, e = item
            return groups[k][e.index] if e.index is not None else groups[k][0]

        k, e = min(errors, key=row)
        index = int(groups[k][e.index]) if e.index is not None else None
        series = "" if by is None else f" (series {names[k]!r} of column {by!r})"
        message = str(e)
        if index is not None and message.startswith("sample ") and ": " in message:
            message = message.split(": ", 1)[1]  # the index within the series, replaced
        where = f"row {index}{series}: " if index is not None else f"{series.strip()}: "
        raise type(e)(f"{where}{message}", index) from e
    columns: dict[str, np.ndarray] = {}
    if keys is not None:
        columns[by] = keys
    columns[time] = t
    columns[value] = y
    for k in range(width):
        columns[f"d{k}"] = d[:, k]
    if s is not None:
        for k in range(width):
            columns[f"s{k}"] = s[:, k]
    if kind == "fixed":
        cells = np.empty(n)
        for rows in groups:
            cells[rows] = np.minimum(np.arange(1, len(rows) + 1), window)
        columns["window"] = cells
    return _like(df, columns)
