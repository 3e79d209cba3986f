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

Which to use: the expressions for frames that fit in memory (any query, any columns kept,
``.over(id)``); :func:`filter_batches` for data larger than memory, such as a long Parquet
log of many interleaved sensors: it takes a lazy query's ordered batches from the streaming
engine through one filter per series, carried from batch to batch (the library's stream
bank, as ``seqsmooth filter --id-col``), and is itself a lazy query, in memory bounded by the
number of series and the batch size, not by the rows; :func:`sink_parquet` writes such a
query to a Parquet file without ever leaving a half-written one::

    lf = pl.scan_parquet("log.parquet")  # columns id, t, y; series interleaved
    out = ssp.filter_batches(lf, by="id", kind="fading", degree=2, theta=0.9, tau=1.0)
    ssp.sink_parquet(out, "estimates.parquet")
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from typing import Any, Literal

import numpy as np
import polars as pl
from polars.io.plugins import register_io_source

from ._seqsmooth import TAU_SCAN_ROWS, FilterStream, KalmanFilter, filter_series, seconds
from ._seqsmooth import smooth as _smooth
from .errors import InvalidInputError, ParameterError, SeqsmoothError

__all__ = ["filter", "smooth", "kalman", "filter_batches", "kalman_batches", "sink_parquet"]


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


class _Series:
    """Each key's series number, from 0 in order of first appearance in the stream."""

    def __init__(self, by: str) -> None:
        self.by = by
        self.numbers: dict[Any, int] = {}
        self.names: list[Any] = []

    def codes(self, keys: pl.Series, first: int) -> np.ndarray:
        """The series numbers of ``keys`` (rows ``first``.. of the stream)."""
        empty = keys.is_null()
        if keys.dtype.is_float():
            empty = empty | keys.is_nan()  # NaN names no series (filter_frame: empty)
        if empty.any():
            i = first + int(empty.arg_true()[0])
            raise InvalidInputError(f"row {i}: the {self.by!r} cell is empty (no series)", i)
        # The keys of the batch in order of first appearance, then each one's number in the
        # stream (a new key: the count of keys before it).
        firsts = keys.unique(maintain_order=True)
        known = []
        for k in firsts.to_list():
            if k not in self.numbers:
                self.numbers[k] = len(self.names)
                self.names.append(k)
            known.append(self.numbers[k])
        table = pl.DataFrame({"k": firsts, "c": np.asarray(known, dtype=np.int64)})
        joined = keys.to_frame("k").join(table, on="k", how="left", maintain_order="left")
        return joined["c"].to_numpy().astype(np.int64, copy=False)


def _ahead(batches: Iterator[pl.DataFrame]) -> Iterator[tuple[pl.DataFrame, bool]]:
    """Each non-empty batch with whether it is the last."""
    held = None
    for batch in batches:
        if batch.height == 0:
            continue
        if held is not None:
            yield held, False
        held = batch
    if held is not None:
        yield held, True


def _batches(
    lf: pl.LazyFrame,
    time: str,
    value: str,
    by: str | None,
    names: list[str],
    start: Any,
    hold: int,
    chunk_size: int | None,
    explain: str,
) -> pl.LazyFrame:
    """The LazyFrame of ``[by,] time, value`` and the columns ``names`` of a stream made by
    ``start()`` (``.rows`` taken so far; ``.update(codes, t, y, last) -> (values, ready)``:
    the columns of its next ``ready`` rows), fed ``lf``'s batches in order from the streaming
    engine, the first ``hold`` rows at once."""
    lf = lf.lazy()
    source = lf.collect_schema()
    for column in [c for c in (by, time, value) if c is not None]:
        if column not in source:
            raise InvalidInputError(
                f"no column {column!r} in the frame (columns: {source.names()})"
            )
    schema: dict[str, Any] = {} if by is None else {by: source[by]}
    schema |= {time: pl.Float64, value: pl.Float64} | {n: pl.Float64 for n in names}
    inputs = lf.select([c for c in (by, time, value) if c is not None])

    def rows() -> Iterator[pl.DataFrame]:
        stream = start()
        series = None if by is None else _Series(by)
        pending: pl.DataFrame | None = None  # rows taken, not given back yet
        batches = inputs.collect_batches(chunk_size=chunk_size, engine="streaming")
        first: list[pl.DataFrame] = []
        for batch, last in _ahead(iter(batches)):
            if stream.rows == 0 and hold:
                first.append(batch)
                if not last and sum(b.height for b in first) < hold:
                    continue
                batch, first = pl.concat(first, rechunk=True), []
            start_row = stream.rows
            codes = (
                np.zeros(batch.height, np.int64)
                if series is None
                else series.codes(batch[by], start_row)
            )
            try:
                t = seconds(batch[time], time)
            except SeqsmoothError as e:
                if e.index is None:
                    raise
                # A time that is no time (a null date): its row among all rows, as filter_frame.
                row = start_row + e.index
                named = "" if series is None else f" (series {series.names[codes[e.index]]!r})"
                raise type(e)(f"row {row}{named}: {e}", row) from e
            y = np.ascontiguousarray(np.asarray(batch[value]), dtype=np.float64)
            try:
                values, ready = stream.update(codes, t, y, last)
            except SeqsmoothError as e:
                if e.index is None or series is None:
                    raise
                # filter_frame's words: the row among all rows and its series.
                name = series.names[codes[e.index - start_row]]
                message = str(e)
                if message.startswith("sample ") and ": " in message:
                    message = message.split(": ", 1)[1]
                raise type(e)(
                    f"row {e.index} (series {name!r} of column {by!r}): {message}", e.index
                ) from e
            taken = ({} if by is None else {by: batch[by]}) | {time: t, value: y}
            taken = pl.DataFrame(taken, schema={c: schema[c] for c in taken})
            pending = taken if pending is None else pl.concat([pending, taken])
            if ready:
                out = pending.head(ready).hstack([pl.Series(n, v) for n, v in zip(names, values)])
                # The rows still waiting in buffers of their own (a slice would keep the
                # batches' buffers alive).
                pending = pending.slice(ready).rechunk() if ready < pending.height else None
                yield out

    def io_source(
        with_columns: list[str] | None,
        predicate: pl.Expr | None,
        n_rows: int | None,
        batch_size: int | None,
    ) -> Iterator[pl.DataFrame]:
        left = n_rows
        for out in rows():
            if with_columns is not None:
                out = out.select(with_columns)
            if predicate is not None:
                out = out.filter(predicate)
            if left is not None:
                out = out.head(left)
                left -= out.height
            yield out
            if left is not None and left <= 0:
                return

    return register_io_source(io_source, schema=schema, explain_name=explain)


def filter_batches(
    lf: pl.LazyFrame | pl.DataFrame,
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
    chunk_size: int | None = 1 << 15,
) -> pl.LazyFrame:
    """:func:`seqsmooth.filter_frame` over a lazy query, batch by batch: a LazyFrame of
    ``filter_frame``'s rows (``[by,] time, value, d0..dM``, ``s0..sM``, the kind's cells; the
    time in seconds, the rows in input order), bit for bit, for data larger than memory.

    Collecting the result (``collect``, ``sink_parquet``, :func:`sink_parquet`,
    ``collect_batches``) runs ``lf`` in Polars' streaming engine and takes its batches in
    order (``collect_batches``, ``maintain_order``), each through one filter per series,
    carried from batch to batch (``FilterStream``: the library's stream bank, ``seqsmooth
    filter --id-col``'s engine): memory holds one filter per series, a few batches
    (``chunk_size`` rows each; ``None``: Polars' default, about 10⁵ rows here) and, for
    ``auto``, the rows from the oldest one whose outlier decision is still to come (rows go
    out in input order, and a sample is decided ``review_window`` samples of its series
    later: a series that falls silent holds every row after its last ones until it speaks
    again or the stream ends, as ``seqsmooth filter --id-col --kind auto`` does). Each
    collection runs the whole stream again from its start.

    Which to use: the expressions (:func:`filter`) for frames in memory and for queries that
    keep other columns; this for a stream longer than memory, in one pass. The settings are
    ``filter_frame``'s; without ``tau``, ``fading`` and ``auto`` take ``filter_frame``'s
    default from the first ``TAU_SCAN_ROWS`` rows, which are held before the first estimate.

    Raises
    ------
    SeqsmoothError
        At once for settings the filter refuses; while collecting, for a bad row, with its
        index among all rows and its series (the batches before it already given out: write
        with :func:`sink_parquet`, which then leaves no file).
    """
    settings = dict(
        theta=theta,
        tau=tau,
        window=window,
        engine=engine,
        sigma=sigma,
        review_window=review_window,
    )
    names = FilterStream(kind, degree, **settings).names  # the settings checked now
    hold = TAU_SCAN_ROWS if tau is None and kind in ("fading", "auto") else 0
    return _batches(
        lf,
        time,
        value,
        by,
        names,
        lambda: FilterStream(kind, degree, **settings),
        hold,
        chunk_size,
        "seqsmooth.filter_batches",
    )


class _KalmanStream:
    """One :class:`seqsmooth.KalmanFilter` per series, each from ``x0``, ``P0`` at ``t0``
    (default its first time), carried from batch to batch; each batch's rows of a series go
    to its ``update_many`` at once."""

    def __init__(self, degree: int, x0: Any, P0: Any, R: float, t0: Any, settings: Any):
        self.degree, self.x0, self.P0, self.R, self.t0 = degree, x0, P0, R, t0
        self.settings = settings
        self.filters: list[KalmanFilter] = []
        self.rows = 0

    def update(
        self, codes: np.ndarray, t: np.ndarray, y: np.ndarray, last: bool
    ) -> tuple[np.ndarray, int]:
        width = self.degree + 1
        out = np.empty((2 * width + 1, len(t)))
        order = np.argsort(codes, kind="stable")
        for rows in np.split(order, np.flatnonzero(np.diff(codes[order])) + 1):
            c = int(codes[rows[0]])
            if c == len(self.filters):
                start = t[rows[0]] if self.t0 is None else self.t0
                self.filters.append(
                    KalmanFilter(self.degree, self.x0, self.P0, start, **self.settings)
                )
            try:
                states, covariances, nis = self.filters[c].update_many(t[rows], y[rows], self.R)
            except SeqsmoothError as e:
                if e.index is None:
                    raise
                i = self.rows + int(rows[e.index])
                message = str(e)
                if message.startswith("sample ") and ": " in message:
                    message = message.split(": ", 1)[1]
                raise type(e)(f"sample {i} of the batch: {message}", i) from e
            sd = np.sqrt(np.diagonal(covariances, axis1=1, axis2=2))
            out[:width, rows] = states.T
            out[width : 2 * width, rows] = sd.T
            out[2 * width, rows] = nis
        self.rows += len(t)
        return out, len(t)


def kalman_batches(
    lf: pl.LazyFrame | pl.DataFrame,
    time: str = "t",
    value: str = "y",
    by: str | None = None,
    *,
    degree: int,
    x0: Any,
    P0: Any,
    R: float,
    q: float = 0.0,
    t0: float | None = None,
    theta: float | None = None,
    tau: float | None = None,
    chunk_size: int | None = 1 << 15,
) -> pl.LazyFrame:
    """The expression :func:`kalman` with ``.over(by)``, batch by batch, as
    :func:`filter_batches` runs ``filter_frame``: a LazyFrame of ``[by,] time, value``
    (the time in seconds) and ``d0..dM``, ``s0..sM``, ``nis``, the numbers of one
    :class:`seqsmooth.KalmanFilter` per series (from ``x0``, ``P0`` at ``t0``, default the
    series' first time) carried from batch to batch, bit for bit those of the expression;
    memory holds one filter per series and a few batches."""
    settings = dict(q=q, theta=theta, tau=tau)
    KalmanFilter(degree, x0, P0, 0.0 if t0 is None else t0, **settings)  # settings checked now
    width = degree + 1
    names = [f"d{k}" for k in range(width)] + [f"s{k}" for k in range(width)] + ["nis"]
    return _batches(
        lf,
        time,
        value,
        by,
        names,
        lambda: _KalmanStream(degree, x0, P0, R, t0, settings),
        0,
        chunk_size,
        "seqsmooth.kalman_batches",
    )


def _umask() -> int:
    """The process's umask (read from /proc where it can be, without changing it)."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except OSError:
        pass
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


def sink_parquet(query: pl.LazyFrame, path: str | os.PathLike[str], **kwargs: Any) -> None:
    """``query.sink_parquet(path, **kwargs)`` (Polars' streaming engine) that never leaves a
    half-written file: the rows go to a temporary file in ``path``'s directory, renamed to
    ``path`` once complete (an existing file is replaced only then, atomically, and keeps
    its permissions; a new one gets the umask's); on an error the temporary file is removed
    and ``path`` is untouched. ``path`` is a local file: ``lazy``, partitioned or cloud
    targets are Polars' own ``sink_parquet``'s (refused here, with ``ParameterError``);
    ``mkdir=True`` creates the directory first."""
    if not isinstance(path, (str, os.PathLike)) or "://" in os.fspath(path):
        raise ParameterError(
            f"sink_parquet writes a local file path, not {path!r}: use the query's own "
            "sink_parquet for partitioned, cloud or file-object targets"
        )
    if kwargs.get("lazy"):
        raise ParameterError(
            "sink_parquet(lazy=True) would write nothing: use the query's own "
            "sink_parquet(..., lazy=True) and collect it"
        )
    kwargs.pop("lazy", None)
    path = os.fspath(path)
    directory, name = os.path.split(os.path.abspath(path))
    if kwargs.pop("mkdir", False):
        os.makedirs(directory, exist_ok=True)
    fd, temporary = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp", dir=directory)
    os.close(fd)
    try:
        query.sink_parquet(temporary, **kwargs)
        try:
            mode = os.stat(path).st_mode & 0o7777
        except FileNotFoundError:
            mode = 0o666 & ~_umask()
        os.chmod(temporary, mode)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise
