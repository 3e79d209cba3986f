"""seqsmooth.polars: the expressions equal filter_frame (and smooth, KalmanFilter per series)
bit for bit on 25 interleaved series with string ids, with .over(id), in eager, lazy and
streaming execution."""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest
from test_frame import interleaved

import seqsmooth as ss
import seqsmooth.polars as ssp

KINDS = {
    "expanding": dict(kind="expanding", degree=2, sigma=0.3),
    "fading": dict(kind="fading", degree=2, theta=0.9, tau=1.0, sigma=0.3),
    "fixed": dict(kind="fixed", degree=1, window=15, sigma=0.3),
    "auto": dict(kind="auto", degree=2, theta=0.95, tau=1.0),
}
MODES = ["eager", "lazy", "streaming"]


@pytest.fixture(scope="module")
def frame() -> pl.DataFrame:
    names, t, y = interleaved(np.random.default_rng(34))
    return pl.DataFrame({"id": names.astype(str), "t": t, "y": y})


def run(df: pl.DataFrame, expr: pl.Expr, mode: str) -> pl.DataFrame:
    """``df`` with the struct ``expr`` unnested, in the execution mode."""
    if mode == "eager":
        out = df.with_columns(f=expr)
    else:
        engine = "streaming" if mode == "streaming" else "in-memory"
        out = df.lazy().with_columns(f=expr).collect(engine=engine)
    return out.unnest("f")


def assert_bits(a: np.ndarray, b: np.ndarray, name: str):
    a, b = np.ascontiguousarray(a, np.float64), np.ascontiguousarray(b, np.float64)
    assert a.shape == b.shape, name
    assert np.array_equal(a.view(np.uint64), b.view(np.uint64)), name


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("kind", KINDS)
def test_filter_equals_filter_frame(frame, kind, mode):
    settings = KINDS[kind]
    expected = ss.filter_frame(frame, by="id", **settings)
    out = run(frame, ssp.filter("y", time="t", **settings).over("id"), mode)
    columns = expected.columns[3:]
    assert out.columns[3:] == columns
    assert out["id"].to_list() == frame["id"].to_list()  # rows in input order
    for name in columns:
        assert_bits(out[name].to_numpy(), expected[name].to_numpy(), name)
    # Without .over the frame is one series, whose interleaved times go back: refused.
    with pytest.raises(ss.InvalidInputError, match="strictly increasing"):
        run(frame, ssp.filter("y", time="t", **settings), mode)


def per_series(frame: pl.DataFrame, compute) -> dict[str, np.ndarray]:
    """``compute(t, y) -> {name: column}`` on each series, put back in the frame's rows."""
    ids = frame["id"].to_numpy()
    t, y = frame["t"].to_numpy(), frame["y"].to_numpy()
    out: dict[str, np.ndarray] = {}
    for key in np.unique(ids):
        rows = np.flatnonzero(ids == key)
        for name, column in compute(t[rows], y[rows]).items():
            out.setdefault(name, np.full(len(ids), np.nan))[rows] = column
    return out


@pytest.mark.parametrize("mode", MODES)
def test_smooth_equals_smooth_per_series(frame, mode):
    def compute(t, y):
        fits = [ss.smooth(y, 11, 2, deriv=k, t=t, return_sigma=True) for k in range(3)]
        return {f"d{k}": v for k, (v, _) in enumerate(fits)} | {
            f"s{k}": s for k, (_, s) in enumerate(fits)
        }

    expected = per_series(frame, compute)
    out = run(frame, ssp.smooth("y", time="t", window_length=11, polyorder=2).over("id"), mode)
    for name, column in expected.items():
        assert_bits(out[name].to_numpy(), column, name)


@pytest.mark.parametrize("mode", MODES)
def test_kalman_equals_kalman_filter_per_series(frame, mode):
    x0, P0, R, q = [0.0, 0.0], 1e4, 0.09, 0.01

    def compute(t, y):
        states, covariances, nis = ss.KalmanFilter(1, x0, P0, t[0], q=q).update_many(t, y, R)
        sd = np.sqrt(np.diagonal(covariances, axis1=1, axis2=2))
        return {"d0": states[:, 0], "d1": states[:, 1], "s0": sd[:, 0], "s1": sd[:, 1]} | {
            "nis": nis
        }

    expected = per_series(frame, compute)
    expr = ssp.kalman("y", time="t", degree=1, x0=x0, P0=P0, R=R, q=q).over("id")
    out = run(frame, expr, mode)
    assert out.columns[3:] == ["d0", "d1", "s0", "s1", "nis"]
    for name, column in expected.items():
        assert_bits(out[name].to_numpy(), column, name)


def test_dates_are_seconds(frame):
    """A Datetime time column gives the numbers of its seconds since the epoch, as
    seqsmooth.seconds reads them."""
    settings = KINDS["fading"]
    dated = frame.with_columns(when=(pl.col("t") * 1e6).round().cast(pl.Int64).cast(pl.Datetime))
    dated = dated.with_columns(t=pl.Series(ss.seconds(dated["when"])))
    a = dated.with_columns(f=ssp.filter("y", time="when", **settings).over("id")).unnest("f")
    b = dated.with_columns(f=ssp.filter("y", time="t", **settings).over("id")).unnest("f")
    for name in ["d0", "d1", "d2", "s0"]:
        assert_bits(a[name].to_numpy(), b[name].to_numpy(), name)


def test_settings_refused_at_once():
    with pytest.raises(ss.ParameterError, match="tau"):
        ssp.filter("y", time="t", kind="fading", degree=1, theta=0.9)
    with pytest.raises(ss.ParameterError):
        ssp.filter("y", time="t", kind="fading", degree=1, theta=1.5, tau=1.0)
    with pytest.raises(ss.SeqsmoothError):
        ssp.kalman("y", time="t", degree=1, x0=[0.0], P0=1.0, R=1.0)


def test_bad_rows_raise_with_their_index(frame):
    bad = frame.with_columns(y=pl.when(pl.int_range(pl.len()) == 7).then(np.nan).otherwise("y"))
    with pytest.raises(ss.InvalidInputError):
        bad.with_columns(f=ssp.filter("y", time="t", **KINDS["expanding"]).over("id"))


@pytest.mark.parametrize("kind", KINDS)
def test_one_series_streams_from_parquet_in_one_call(tmp_path, kind):
    """Without .over, a Parquet file of many row groups through the streaming engine (scan
    to sink) is one series: the filter sees the whole column at once, not batch by batch."""
    rng = np.random.default_rng(7)
    t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, 200_000))
    y = np.sin(t / 50.0) + 0.3 * rng.standard_normal(t.size)
    source, sink = tmp_path / "in.parquet", tmp_path / "out.parquet"
    pl.DataFrame({"t": t, "y": y}).write_parquet(source, row_group_size=10_000)
    settings = KINDS[kind]
    expected = ss.filter_frame(pl.read_parquet(source), **settings)
    query = pl.scan_parquet(source).with_columns(f=ssp.filter("y", time="t", **settings))
    query.unnest("f").sink_parquet(sink)
    out = pl.read_parquet(sink)
    for name in expected.columns[2:]:
        assert_bits(out[name].to_numpy(), expected[name].to_numpy(), name)
