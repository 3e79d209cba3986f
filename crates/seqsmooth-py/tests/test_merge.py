"""Exact merges (docs/python.md, "One long series across a cluster"): one series of 10⁶
samples cut into partitions, each reduced to its ``Information`` on a Dask cluster of two
worker processes and on Spark in local mode, merged in a tree, against the single passes:
``Information`` over all the samples in one call, the expanding-memory filter run sample by
sample, the Bayes filter (expanding memory with a prior) and numpy's least squares.

Two measures of "relative" (ACCURACY.md): **derivatives**, ``max_k |Δd_k| h^k / max_k |d_k|
h^k`` at the end of the span (``h`` the half span); **curve**, ``max_t |Δp(t)| / max_t |p(t)|``
over 201 times of the span."""

from __future__ import annotations

import copy
import functools
import operator
import pickle

import numpy as np
import pandas as pd
import pytest

import seqsmooth

N = 1_000_000
DEGREES = range(9)
SIGMA = 0.9


@pytest.fixture(scope="module")
def rows() -> pd.DataFrame:
    """10⁶ samples at irregular times over about 10⁶ s of a smooth curve with noise."""
    rng = np.random.default_rng(34)
    t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, N))
    u = (t - t[0]) / (t[-1] - t[0])
    y = 5.0 + 3.0 * u - 2.0 * u**2 + np.sin(6.0 * u) + SIGMA * rng.standard_normal(N)
    return pd.DataFrame({"t": t, "y": y})


@pytest.fixture(scope="module")
def span(rows) -> tuple[float, float]:
    return float(rows.t.min()), float(rows.t.max())


@pytest.fixture(scope="module")
def single(rows, span) -> dict[int, seqsmooth.Information]:
    """The single pass of the same reduction: all the samples in one call."""
    out = {}
    for m in DEGREES:
        info = seqsmooth.Information(m, *span, sigma=SIGMA)
        info.reduce(rows.t.to_numpy(), rows.y.to_numpy())
        out[m] = info
    return out


# The recipe functions (as in docs/python.md).
def reduce_partition(part: pd.DataFrame, span) -> list[seqsmooth.Information]:
    """One partition, any rows of the series in any order: its information at each degree."""
    infos = []
    for m in DEGREES:
        info = seqsmooth.Information(m, *span, sigma=SIGMA)
        info.reduce(np.array(part["t"], dtype=float), np.array(part["y"], dtype=float))
        infos.append(info)
    return infos


def merge_lists(a, b):
    return [x + y for x, y in zip(a, b)]


def reduce_rows(rows_iter, span):
    """Spark's ``mapPartitions``: an iterator of Rows in, one list of informations out."""
    pairs = np.array([(r.t, r.y) for r in rows_iter], dtype=float).reshape(-1, 2)
    yield reduce_partition(pd.DataFrame({"t": pairs[:, 0], "y": pairs[:, 1]}), span)


def derivatives_relative(a, b, h) -> float:
    s = h ** np.arange(len(b))
    return float(np.max(np.abs((a - b) * s)) / np.max(np.abs(b * s)))


def curve_relative(p, q, span) -> float:
    grid = np.linspace(*span, 201)
    a = np.array([p(t) for t in grid])
    b = np.array([q(t) for t in grid])
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def check_against_single_passes(infos, rows, span, single):
    t, y = rows.t.to_numpy(), rows.y.to_numpy()
    h = 0.5 * (span[1] - span[0])
    end = span[1]
    centre = 0.5 * (span[0] + span[1])
    for m, info in zip(DEGREES, infos):
        assert info.samples == N
        got = info.estimate(end)
        # The same reduction in one pass: to the last few bits, at every degree.
        one = single[m].estimate(end)
        assert derivatives_relative(got.derivatives, one.derivatives, h) < 1e-14, m
        np.testing.assert_allclose(got.covariance, one.covariance, rtol=1e-12)
        # Expanding memory, sample by sample (an independent single pass).
        f = seqsmooth.ExpandingMemory(m, sigma=SIGMA)
        f.update_many(t, y)
        want = f.estimate()
        r = derivatives_relative(got.derivatives, want.derivatives, h)
        # The derivatives at the end of the span: 1e-12 to degree 5; above, the filter's own
        # rounding (ACCURACY.md, measured up to 4e-11 at degree 8).
        assert r < (1e-12 if m <= 5 else 1e-10), (m, r)
        c = curve_relative(
            lambda s, info=info: info.estimate(s).derivatives[0],
            lambda s, f=f: f.estimate_at(s).derivatives[0],
            span,
        )
        assert c < 1e-12, (m, c)
        np.testing.assert_allclose(got.std_devs, want.std_devs, rtol=1e-9)
        # numpy's least squares (LAPACK's SVD solver) on the Legendre basis of the span.
        u = (t - centre) / h
        coef = np.linalg.lstsq(np.polynomial.legendre.legvander(u, m), y, rcond=None)[0]
        c = curve_relative(
            lambda s, info=info: info.estimate(s).derivatives[0],
            lambda s, coef=coef: np.polynomial.legendre.legval((s - centre) / h, coef),
            span,
        )
        assert c < 1e-12, (m, c)


def test_dask_tree_merge_equals_the_single_passes(rows, span, single, client):
    import dask
    import dask.dataframe as dd

    ddf = dd.from_pandas(rows, npartitions=10)
    start, end = dask.compute(ddf.t.min(), ddf.t.max())
    assert (start, end) == span
    parts = [dask.delayed(reduce_partition)(p, (start, end)) for p in ddf.to_delayed()]
    while len(parts) > 1:  # a tree of pairwise merges
        parts = [
            dask.delayed(merge_lists)(*parts[i : i + 2]) if i + 1 < len(parts) else parts[i]
            for i in range(0, len(parts), 2)
        ]
    infos = parts[0].compute()
    check_against_single_passes(infos, rows, span, single)


def test_spark_map_partitions_reduce_equals_the_single_passes(rows, span, single, spark):
    import pyspark.sql.functions as F

    df = spark.createDataFrame(rows).repartition(10)
    lo, hi = df.agg(F.min("t"), F.max("t")).first()
    assert (lo, hi) == span
    infos = df.rdd.mapPartitions(functools.partial(reduce_rows, span=(lo, hi))).treeReduce(
        merge_lists
    )
    check_against_single_passes(infos, rows, span, single)


def test_bayes_prior_in_one_partition_equals_the_bayes_filter(rows, span):
    t, y = rows.t.to_numpy(), rows.y.to_numpy()
    h = 0.5 * (span[1] - span[0])
    cuts = np.sort(np.random.default_rng(1).choice(np.arange(1, N), 9, replace=False))
    for m in [0, 1, 2, 4, 8]:
        x0 = np.array([5.0, 3e-6, -1e-12] + [0.0] * 6)[: m + 1]
        P0 = 4.0 / 1e6 ** (2.0 * np.arange(m + 1))
        t0 = span[0] - 10.0
        f = seqsmooth.ExpandingMemory(m, sigma=SIGMA, x0=x0, P0=P0, t0=t0)
        f.update_many(t, y)
        want = f.estimate()
        infos = []
        for a, b in zip(np.r_[0, cuts], np.r_[cuts, N]):
            info = seqsmooth.Information(m, *span, sigma=SIGMA)
            info.reduce(t[a:b], y[a:b])
            infos.append(info)
        infos[3].add_prior(x0, P0, t0)  # once, in any one partition
        got = functools.reduce(operator.add, infos).estimate(span[1])
        r = derivatives_relative(got.derivatives, want.derivatives, h)
        assert r < (1e-12 if m <= 4 else 1e-10), (m, r)
        np.testing.assert_allclose(got.std_devs, want.std_devs, rtol=1e-9)


def test_pickle_merge_rules_and_errors(span):
    a = seqsmooth.Information(2, 0.0, 10.0, sigma=1.0)
    a.reduce([0.0, 1.0, 2.0, 3.0], [1.0, 2.0, 5.0, 10.0])
    for b in [pickle.loads(pickle.dumps(a)), copy.deepcopy(a), copy.copy(a)]:
        assert b.samples == 4 and b.span == (0.0, 10.0) and b.degree == 2
        assert np.array_equal(b.estimate(2.5).derivatives, a.estimate(2.5).derivatives)
    e = seqsmooth.Information(2, 0.0, 10.0, sigma=1.0)
    e.reduce([], [])  # an empty partition adds nothing
    assert (a + e).samples == 4 and a.samples == 4
    with pytest.raises(seqsmooth.ParameterError):
        a.merge(seqsmooth.Information(2, 0.0, 11.0, sigma=1.0))
    with pytest.raises(seqsmooth.ParameterError):
        seqsmooth.Information(2, 1.0, 0.0)
    with pytest.raises(seqsmooth.ParameterError):
        seqsmooth.Information(2, 0.0, 1.0).add_prior([0.0, 0.0, 0.0], 1.0)
    with pytest.raises(seqsmooth.TooFewSamplesError):
        seqsmooth.Information(2, 0.0, 1.0).estimate(0.5)
    two_times = seqsmooth.Information(2, 0.0, 1.0)
    two_times.reduce([0.2, 0.7] * 50, [1.0] * 100)
    with pytest.raises(seqsmooth.NotDeterminedError):
        two_times.estimate(0.5)
    with pytest.raises(seqsmooth.InvalidInputError) as big:
        a.reduce([4.0, 5.0], [1.0, 1e200])  # its square leaves the double range
    assert big.value.index == 1 and a.samples == 4
    with pytest.raises(seqsmooth.InvalidInputError) as bad:
        a.reduce([4.0, 5.0], [1.0, np.nan])
    assert bad.value.index == 1 and a.samples == 4
    a.add_prior([1.0, 0.0, 0.0], [1.0, 1.0, 1.0], t0=0.0)
    b = pickle.loads(pickle.dumps(a))
    assert b.has_prior
    with pytest.raises(seqsmooth.ParameterError):
        a.merge(b)  # a prior in both
    with pytest.raises(seqsmooth.DamagedStateError):
        seqsmooth.Information._from_state(b"not a state")
