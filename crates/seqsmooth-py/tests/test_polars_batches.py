"""seqsmooth.polars.filter_batches: a lazy query's batches through one filter per series,
carried from batch to batch (FilterStream), equal bit for bit to filter_frame on the whole
frame (the library's filter_series, all rows at once) and to the expression with .over(id),
on 25 interleaved series with string ids, every kind; and sink_parquet's whole-or-nothing
write."""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest
from test_frame import interleaved
from test_polars import KINDS, assert_bits

import seqsmooth as ss
import seqsmooth.polars as ssp
from seqsmooth._seqsmooth import TAU_SCAN_ROWS, FilterStream, filter_series


@pytest.fixture(scope="module")
def frame() -> pl.DataFrame:
    names, t, y = interleaved(np.random.default_rng(34))
    return pl.DataFrame({"id": names.astype(str), "t": t, "y": y})


@pytest.fixture(scope="module")
def parquet(tmp_path_factory, frame) -> str:
    """The frame in a Parquet file of row groups of 100 rows."""
    path = tmp_path_factory.mktemp("batches") / "in.parquet"
    frame.write_parquet(path, row_group_size=100)
    return str(path)


def assert_frames(out: pl.DataFrame, expected: pl.DataFrame):
    assert out.columns == expected.columns
    assert out["id"].to_list() == expected["id"].to_list()  # rows in input order
    for name in expected.columns[1:]:
        assert_bits(out[name].to_numpy(), expected[name].to_numpy(), name)


def codes_of(ids: np.ndarray) -> np.ndarray:
    """Each id's series number in order of first appearance."""
    _, first, inverse = np.unique(ids, return_index=True, return_inverse=True)
    rank = np.empty(len(first), np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    return rank[inverse]


@pytest.mark.parametrize("kind", KINDS)
def test_stream_cut_anywhere_equals_all_rows_at_once(frame, kind):
    """FilterStream fed the rows in pieces cut at random rows gives filter_series' columns on
    all the rows at once, bit for bit (auto: once every row is given back, the last piece
    deciding those still waiting)."""
    settings = dict(KINDS[kind])
    settings.pop("kind")
    degree = settings.pop("degree")
    t, y = frame["t"].to_numpy(), frame["y"].to_numpy()
    codes = codes_of(frame["id"].to_numpy())
    expected, names = filter_series(codes, t, y, kind, degree, **settings)
    rng = np.random.default_rng(5)
    cuts = np.sort(rng.choice(np.arange(1, len(t)), 11, replace=False))
    stream = FilterStream(kind, degree, **settings)
    assert stream.names == list(names)
    pieces, waited = [], 0
    for k, (a, b) in enumerate(zip([0, *cuts], [*cuts, len(t)])):
        values, ready = stream.update(codes[a:b], t[a:b], y[a:b], last=k == len(cuts))
        assert values.shape == (len(names), ready)
        pieces.append(values)
        waited = max(waited, stream.waiting)
    assert stream.rows == len(t) and stream.waiting == 0
    out = np.concatenate(pieces, axis=1)
    for k, name in enumerate(names):
        assert_bits(out[k], expected[k], name)
    # The automatic filter's rows wait for their outlier decision across pieces; the other
    # kinds give every row back at once.
    assert (waited > 0) == (kind == "auto")
    with pytest.raises(ss.InvalidInputError, match="ended"):
        stream.update(codes[:1], t[:1], y[:1])


@pytest.mark.parametrize("mode", ["collect", "sink"])
@pytest.mark.parametrize("kind", KINDS)
def test_batches_equal_filter_frame_and_the_expression(frame, parquet, tmp_path, kind, mode):
    settings = KINDS[kind]
    expected = ss.filter_frame(frame, by="id", **settings)
    query = ssp.filter_batches(pl.scan_parquet(parquet), by="id", chunk_size=97, **settings)
    if mode == "collect":
        out = query.collect(engine="streaming")
    else:
        ssp.sink_parquet(query, tmp_path / "out.parquet")
        out = pl.read_parquet(tmp_path / "out.parquet")
    assert_frames(out, expected)
    # The expression with .over(id) in the streaming engine: the same numbers.
    expr = ssp.filter("y", time="t", **settings).over("id")
    lazy = pl.scan_parquet(parquet).with_columns(f=expr).unnest("f")
    by_expr = lazy.collect(engine="streaming")
    for name in expected.columns[3:]:
        assert_bits(out[name].to_numpy(), by_expr[name].to_numpy(), name)


def test_query_comes_in_many_batches(parquet):
    """The input reaches the filter in pieces (the test above is not one batch)."""
    sizes = [b.height for b in pl.scan_parquet(parquet).collect_batches(chunk_size=97)]
    assert len(sizes) >= 10 and sum(sizes) == 1200


def test_default_tau_from_the_first_rows(tmp_path):
    """Without tau, fading memory's tau is filter_frame's default (the median step of the
    first TAU_SCAN_ROWS rows): the batches before it are held, then filtered."""
    rng = np.random.default_rng(8)
    rows = TAU_SCAN_ROWS + 4000
    ids = rng.integers(0, 25, rows)
    t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, rows)) / 25
    y = np.sin(t / 50.0) * 10 + ids + 0.3 * rng.standard_normal(rows)
    df = pl.DataFrame({"id": [f"s{k}" for k in ids], "t": t, "y": y})
    settings = dict(kind="fading", degree=1, theta=0.9, sigma=0.3)
    expected = ss.filter_frame(df, by="id", **settings)
    out = ssp.filter_batches(df.lazy(), by="id", chunk_size=5000, **settings).collect()
    assert_frames(out, expected)
    stream = FilterStream("fading", 1, theta=0.9)
    codes = np.zeros(10, np.int64)
    with pytest.raises(ss.InvalidInputError, match="tau"):
        stream.update(codes, np.arange(10.0), np.zeros(10))


def test_integer_ids_dates_and_one_series(frame, parquet):
    settings = KINDS["fading"]
    numbered = frame.with_columns(id=pl.col("id").str.slice(7).cast(pl.Int64))
    expected = ss.filter_frame(numbered, by="id", **settings)
    out = ssp.filter_batches(numbered.lazy(), by="id", chunk_size=50, **settings).collect()
    assert out.schema["id"] == pl.Int64
    assert_frames(out, expected)
    # Dates are their seconds since the epoch, as filter_frame reads them.
    dated = frame.with_columns(t=(pl.col("t") * 1e6).round().cast(pl.Int64).cast(pl.Datetime))
    expected = ss.filter_frame(dated, by="id", **settings)
    assert_frames(ssp.filter_batches(dated.lazy(), by="id", **settings).collect(), expected)
    # Without by, one series.
    one = frame.filter(pl.col("id") == "sensor-03").drop("id")
    expected = ss.filter_frame(one, **settings)
    out = ssp.filter_batches(one.lazy(), chunk_size=7, **settings).collect()
    assert out.columns == expected.columns
    for name in expected.columns:
        assert_bits(out[name].to_numpy(), expected[name].to_numpy(), name)


def test_projection_filter_and_head(frame, parquet):
    """Columns chosen, rows filtered and a head on the result: those of filter_frame's."""
    settings = KINDS["auto"]
    expected = ss.filter_frame(frame, by="id", **settings)
    query = ssp.filter_batches(pl.scan_parquet(parquet), by="id", chunk_size=97, **settings)
    picked = query.filter(pl.col("id") == "sensor-03").select("t", "d1").collect()
    want = expected.filter(pl.col("id") == "sensor-03").select("t", "d1")
    assert_bits(picked["d1"].to_numpy(), want["d1"].to_numpy(), "d1")
    assert_bits(picked["t"].to_numpy(), want["t"].to_numpy(), "t")
    head = query.head(250).collect()
    assert_frames(head, expected.head(250))


def test_bad_row_named_and_no_file_left(frame, tmp_path):
    """A bad row raises filter_frame's error (its row among all rows, its series);
    sink_parquet then leaves an existing file as it was and no temporary file."""
    settings = KINDS["expanding"]
    bad = frame.with_columns(y=pl.when(pl.int_range(pl.len()) == 900).then(np.inf).otherwise("y"))
    with pytest.raises(ss.InvalidInputError) as want:
        ss.filter_frame(bad, by="id", **settings)
    query = ssp.filter_batches(bad.lazy(), by="id", chunk_size=100, **settings)
    target = tmp_path / "out.parquet"
    target.write_bytes(b"the old file")
    with pytest.raises(ss.InvalidInputError) as got:
        ssp.sink_parquet(query, target)
    # filter_frame's row, series and reason (its series named by the id itself here).
    why = str(want.value).split("): ", 1)[1]
    name = bad["id"][900]
    assert got.value.index == 900 == want.value.index
    assert str(got.value) == f"row 900 (series {name!r} of column 'id'): {why}"
    assert target.read_bytes() == b"the old file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.parquet"]
    with pytest.raises(ss.InvalidInputError) as direct:
        query.collect()
    assert str(direct.value) == str(got.value)


def test_settings_and_columns_refused_at_once(frame):
    with pytest.raises(ss.ParameterError):
        ssp.filter_batches(frame.lazy(), by="id", kind="fading", degree=1, theta=1.5)
    with pytest.raises(ss.InvalidInputError, match="no column 'x'"):
        ssp.filter_batches(frame.lazy(), value="x", by="id", **KINDS["fading"])


@pytest.mark.parametrize("t0", [None, 1.7e9])
def test_kalman_batches_equal_the_expression_and_one_filter_per_series(frame, parquet, t0):
    """kalman_batches: the expression's numbers with .over(id) (streaming engine), and those
    of one KalmanFilter per series given its whole series at once."""
    settings = dict(degree=1, x0=[0.0, 0.0], P0=1e4, R=0.09, q=0.01, t0=t0)
    query = ssp.kalman_batches(pl.scan_parquet(parquet), by="id", chunk_size=97, **settings)
    out = query.collect(engine="streaming")
    assert out.columns == ["id", "t", "y", "d0", "d1", "s0", "s1", "nis"]
    assert out["id"].to_list() == frame["id"].to_list()
    expr = ssp.kalman("y", time="t", **settings).over("id")
    by_expr = pl.scan_parquet(parquet).with_columns(k=expr).unnest("k").collect()
    ids, t, y = frame["id"].to_numpy(), frame["t"].to_numpy(), frame["y"].to_numpy()
    for key in np.unique(ids):
        rows = np.flatnonzero(ids == key)
        start = t[rows[0]] if t0 is None else t0
        kf = ss.KalmanFilter(1, [0.0, 0.0], 1e4, start, q=0.01)
        states, covariances, nis = kf.update_many(t[rows], y[rows], 0.09)
        sd = np.sqrt(np.diagonal(covariances, axis1=1, axis2=2))
        for name, column in [("d1", states[:, 1]), ("s0", sd[:, 0]), ("nis", nis)]:
            assert_bits(out[name].to_numpy()[rows], column, name)
    for name in ["d0", "d1", "s0", "s1", "nis"]:
        assert_bits(out[name].to_numpy(), by_expr[name].to_numpy(), name)


def test_kalman_batches_bad_row(frame):
    bad = frame.with_columns(t=pl.when(pl.int_range(pl.len()) == 700).then(0.0).otherwise("t"))
    query = ssp.kalman_batches(
        bad.lazy(), by="id", chunk_size=100, degree=1, x0=[0.0, 0.0], P0=1e4, R=0.09
    )
    with pytest.raises(ss.InvalidInputError) as got:
        query.collect()
    assert got.value.index == 700
    assert str(got.value).startswith(f"row 700 (series {bad['id'][700]!r} of column 'id'): ")


def test_empty_ids_refused_as_filter_frame_refuses_them(frame):
    """A null id (a NaN one in a float column) names no series: refused with its row, as
    filter_frame refuses it."""
    settings = KINDS["fading"]
    row = pl.int_range(pl.len()) == 300
    null = frame.with_columns(id=pl.when(row).then(None).otherwise(pl.col("id")))
    numbered = frame.with_columns(
        id=pl.when(row).then(float("nan")).otherwise(pl.col("id").str.slice(7).cast(pl.Float64))
    )
    for bad in [null, numbered]:
        with pytest.raises(ss.InvalidInputError, match="row 300: the 'id' cell is empty"):
            ss.filter_frame(bad, by="id", **settings)
        with pytest.raises(ss.InvalidInputError, match="row 300: the 'id' cell is empty"):
            ssp.filter_batches(bad.lazy(), by="id", chunk_size=100, **settings).collect()


def test_a_null_time_named_by_its_row_among_all_rows(frame):
    """A null date in a later batch: its row among all rows and its series (not its place in
    the batch)."""
    dated = frame.with_columns(t=(pl.col("t") * 1e6).cast(pl.Datetime("us")))
    bad = dated.with_columns(t=pl.when(pl.int_range(pl.len()) == 700).then(None).otherwise("t"))
    with pytest.raises(ss.InvalidInputError) as want:
        ss.filter_frame(bad, by="id", **KINDS["fading"])
    query = ssp.filter_batches(bad.lazy(), by="id", chunk_size=100, **KINDS["fading"])
    with pytest.raises(ss.InvalidInputError) as got:
        query.collect()
    assert got.value.index == 700 == want.value.index
    assert str(got.value).startswith(f"row 700 (series {bad['id'][700]!r}): ")


def test_sink_parquet_keeps_modes_makes_directories_and_refuses_lazy(frame, tmp_path):
    query = ssp.filter_batches(frame.lazy(), by="id", **KINDS["fading"])
    target = tmp_path / "out.parquet"
    target.write_bytes(b"old")
    target.chmod(0o640)
    ssp.sink_parquet(query, target)
    assert (target.stat().st_mode & 0o777) == 0o640 and pl.read_parquet(target).height > 0
    fresh = tmp_path / "new" / "deeper" / "out.parquet"
    ssp.sink_parquet(query, fresh, mkdir=True)
    assert pl.read_parquet(fresh).height == frame.height
    assert (fresh.stat().st_mode & 0o077) == (0o666 & ~ssp._umask() & 0o077)
    with pytest.raises(ss.ParameterError, match="lazy"):
        ssp.sink_parquet(query, target, lazy=True)
    with pytest.raises(ss.ParameterError, match="local file"):
        ssp.sink_parquet(query, "s3://bucket/out.parquet")
    assert pl.read_parquet(target).height == frame.height  # untouched by the refusals
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new", "out.parquet"]
