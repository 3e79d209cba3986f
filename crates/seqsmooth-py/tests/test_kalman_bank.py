"""``KalmanBank`` and ``kalman_frame``: one ``KalmanFilter`` per series (its ``update_many``,
RTS ``smooth`` and ``fixed_lag_smoother``) to 1e-12 relative, on interleaved series with their
own irregular times and 10 % missing components; pandas, Polars, Arrow and dicts the same
numbers; a bad row named with its series."""

from __future__ import annotations

import numpy as np
import pytest

import seqsmooth

P0 = np.diag([100.0, 100.0, 25.0, 25.0])
R = np.array([[1.5, 0.3], [0.3, 0.8]])
Q = 0.05


def rows(series: int = 200, seed: int = 5):
    """Interleaved series of 20..60 rows, irregular times, two components, 10 % missing."""
    rng = np.random.default_rng(seed)
    ids, ts, zs = [], [], []
    for s in range(series):
        k = int(rng.integers(20, 60))
        t = rng.uniform(-5, 5) + np.cumsum(rng.uniform(0.1, 2.0, k))
        v = rng.uniform(-3, 3, 2)
        z = np.outer(t, v) + rng.standard_normal((k, 2))
        z[rng.random((k, 2)) < 0.1] = np.nan
        ids.append(np.full(k, s))
        ts.append(t)
        zs.append(z)
    ids, t, z = np.concatenate(ids), np.concatenate(ts), np.concatenate(zs)
    order = np.lexsort((rng.random(t.size), t))  # interleaved by time, each series in order
    return ids[order].astype(np.int64), t[order], z[order]


def close(a, b):
    a, b = np.asarray(a), np.asarray(b)
    scale = np.max(np.abs(b), axis=-1, keepdims=True)
    assert np.all(np.abs(a - b) <= 1e-12 * scale)


def sigmas(covariances):
    return np.sqrt(np.maximum(np.diagonal(covariances, axis1=1, axis2=2), 0.0))


def library(ids, t, z, s, method, *extra):
    rows_s = np.flatnonzero(ids == s)
    f = seqsmooth.KalmanFilter(1, np.zeros(4), P0, t0=t[rows_s[0]], axes=2, q=Q)
    return rows_s, getattr(f, method)(t[rows_s], z[rows_s], R, *extra)


def test_bank_equals_one_kalman_filter_per_series():
    ids, t, z = rows()
    bank = seqsmooth.KalmanBank(1, np.zeros(4), P0, R, axes=2, q=Q)
    state, sigma, nis = bank.filter(ids, t, z)
    rts_state, rts_sigma, _ = bank.smooth(ids, t, z)
    lag_state, lag_sigma, _ = bank.fixed_lag_smoother(ids, t, z, 4)
    # The NIS is one float64 a row, contiguous (the bank's own buffer).
    assert nis.shape == (len(t),) and nis.dtype == np.float64 and nis.flags.c_contiguous
    for s in range(0, 200, 7):
        at, (x, cov, nis_s) = library(ids, t, z, s, "update_many")
        close(state[at], x)
        close(sigma[at], sigmas(cov))
        assert np.array_equal(np.isnan(nis[at]), np.isnan(nis_s))
        ok = ~np.isnan(nis_s)
        close(nis[at][ok][:, None], nis_s[ok][:, None])
        at, (x, cov) = library(ids, t, z, s, "smooth")
        close(rts_state[at], x)
        close(rts_sigma[at], sigmas(cov))
        at, (x, cov) = library(ids, t, z, s, "fixed_lag_smoother", 4)
        close(lag_state[at], x)
        close(lag_sigma[at], sigmas(cov))


@pytest.mark.parametrize("kind", ["dict", "pandas", "polars", "pyarrow"])
@pytest.mark.parametrize("smoother", ["filter", "rts", "fixed_lag"])
def test_kalman_frame_is_the_bank_in_every_frame_kind(kind, smoother):
    ids, t, z = rows(60, seed=9)
    names = np.array([f"sensor-{i}" for i in ids])
    columns = {"sensor": names, "t": t, "x": z[:, 0], "y": z[:, 1]}
    if kind == "dict":
        df = columns
    else:
        module = pytest.importorskip(kind)
        df = module.table(columns) if kind == "pyarrow" else module.DataFrame(columns)
    lag = 3 if smoother == "fixed_lag" else None
    out = seqsmooth.kalman_frame(
        df, value=["x", "y"], by="sensor", P0=P0, R=R, q=Q, smoother=smoother, lag=lag
    )
    assert type(out).__module__.split(".")[0] == type(df).__module__.split(".")[0]
    bank = seqsmooth.KalmanBank(1, np.zeros(4), P0, R, axes=2, q=Q)
    codes = np.unique(names, return_inverse=True)[1].astype(np.int64)
    run = {"filter": bank.filter, "rts": bank.smooth}.get(smoother)
    state, sigma, nis = run(codes, t, z) if run else bank.fixed_lag_smoother(codes, t, z, 3)

    def col(c):
        return np.asarray(out[c].to_numpy() if kind == "pyarrow" else out[c], dtype=float)

    # Component k·2 + a of the state is axis a's k-th derivative.
    for k in range(2):
        for a, axis in enumerate(["x", "y"]):
            assert np.array_equal(col(f"{axis}_d{k}"), state[:, 2 * k + a])
            assert np.array_equal(col(f"{axis}_s{k}"), sigma[:, 2 * k + a])
    assert np.array_equal(col("nis"), nis, equal_nan=True)


def test_a_bad_row_is_named_with_its_series():
    ids, t, z = rows(20, seed=3)
    bad = np.flatnonzero(ids == 7)[5]
    t = t.copy()
    t[bad] = t[np.flatnonzero(ids == 7)[4]] - 1.0  # before the series' previous row
    with pytest.raises(seqsmooth.SeqsmoothError) as e:
        seqsmooth.kalman_frame(
            {"id": ids, "t": t, "x": z[:, 0], "y": z[:, 1]},
            value=["x", "y"],
            by="id",
            P0=P0,
            R=R,
        )
    assert e.value.index == bad and "(series 7 of column 'id')" in str(e.value)
    with pytest.raises(seqsmooth.SeqsmoothError):
        seqsmooth.kalman_frame({"t": t, "y": z[:, 0]}, P0=1.0, smoother="rts", lag=2)
    with pytest.raises(seqsmooth.SeqsmoothError):
        seqsmooth.KalmanBank(1, np.zeros(2), -np.eye(2), 1.0)


def test_integer_labels_grouped_or_interleaved_are_the_same_series():
    # Any int64 labels (not codes from 0): interleaved rows grouped by the bank, rows already
    # grouped by label taken as they are; the same numbers either way, in input order.
    ids, t, z = rows(40, seed=4)
    bank = seqsmooth.KalmanBank(1, np.zeros(4), P0, R, axes=2, q=Q)
    labels = ids * 1000 - 7
    order = np.argsort(ids, kind="stable")
    for run in (bank.filter, bank.smooth):
        by_code = run(ids, t, z)
        by_label = run(labels, t, z)
        grouped = run(labels[order], t[order], z[order])
        for a, b, c in zip(by_code, by_label, grouped):
            assert np.array_equal(a, b, equal_nan=True)
            assert np.array_equal(a[order], c, equal_nan=True)


def test_kalman_frame_integer_ids_are_the_string_ids_and_name_a_bad_row():
    ids, t, z = rows(30, seed=6)
    order = np.argsort(ids, kind="stable")
    ids, t, z = ids[order], t[order], z[order]  # grouped by id, as a frame sorted by id
    settings = dict(value=["x", "y"], by="id", P0=P0, R=R, q=Q, smoother="rts")
    by_int = seqsmooth.kalman_frame({"id": ids, "t": t, "x": z[:, 0], "y": z[:, 1]}, **settings)
    names = np.array([f"s{i}" for i in ids])
    by_str = seqsmooth.kalman_frame({"id": names, "t": t, "x": z[:, 0], "y": z[:, 1]}, **settings)
    for c in ["x_d0", "y_d1", "x_s0", "y_s1", "nis"]:
        assert np.array_equal(by_int[c], by_str[c], equal_nan=True)
    bad = np.flatnonzero(ids == 11)[3]
    t = t.copy()
    t[bad] = t[bad - 1] - 1.0
    with pytest.raises(seqsmooth.SeqsmoothError) as e:
        seqsmooth.kalman_frame({"id": ids, "t": t, "x": z[:, 0], "y": z[:, 1]}, **settings)
    assert e.value.index == bad and "(series 11 of column 'id')" in str(e.value)


def _unaligned(values: np.ndarray) -> np.ndarray:
    """``values`` in a contiguous array one byte off its alignment (as an array unpickled
    from a buffer can be)."""
    raw = np.zeros(values.nbytes + 1, dtype=np.uint8)
    out = raw[1:].view(values.dtype).reshape(values.shape)
    out[...] = values
    assert not out.flags.aligned
    return out


def test_kalman_frame_reads_unaligned_columns():
    ids, t, z = rows(30, seed=7)
    settings = dict(value=["x", "y"], by="id", P0=P0, R=R, q=Q, smoother="rts")
    want = seqsmooth.kalman_frame({"id": ids, "t": t, "x": z[:, 0], "y": z[:, 1]}, **settings)
    frame = {
        "id": _unaligned(ids.astype(np.int64)),
        "t": _unaligned(t),
        "x": _unaligned(np.ascontiguousarray(z[:, 0])),
        "y": _unaligned(np.ascontiguousarray(z[:, 1])),
    }
    got = seqsmooth.kalman_frame(frame, **settings)
    for c in ["x_d0", "y_d1", "x_s0", "y_s1", "nis"]:
        assert np.array_equal(got[c], want[c], equal_nan=True)


def test_kalman_frame_pandas_result_is_writable_and_leaves_the_input_alone():
    # The result's input columns share the input's memory under pandas' copy-on-write: every
    # column of the result can be written, and writing it changes neither the input nor
    # another call's result.
    pandas = pytest.importorskip("pandas")
    ids, t, z = rows(30, seed=8)
    df = pandas.DataFrame({"id": ids, "t": t, "x": z[:, 0], "y": z[:, 1]}, index=ids * 3 + 1)
    before = df.copy(deep=True)
    settings = dict(value=["x", "y"], by="id", P0=P0, R=R, q=Q)
    out = seqsmooth.kalman_frame(df, **settings)
    again = seqsmooth.kalman_frame(df, **settings)
    assert isinstance(out.index, pandas.RangeIndex) and len(out) == len(df)
    for c in ["id", "t", "x", "y"]:
        assert np.array_equal(out[c].to_numpy(), df[c].to_numpy(), equal_nan=True)
    for c in out.columns:
        out.loc[0, c] = 7
        out[c] = out[c] * 2
        assert out[c].iloc[0] == 14
    pandas.testing.assert_frame_equal(df, before)
    assert not np.array_equal(again["x_d0"].to_numpy(), out["x_d0"].to_numpy())
    assert again["t"].iloc[0] == t[0] and again["id"].iloc[0] == ids[0]
