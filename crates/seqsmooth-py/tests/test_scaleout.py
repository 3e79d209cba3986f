"""The scale-out recipes of docs/python.md: Dask (`map_partitions` after a shuffle on the
series, and `groupby(...).apply`) on a `dask.distributed.LocalCluster` of two worker
processes, filtering 10⁴ series × 10³ samples, give exactly the single-process
`filter_frame` result."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import seqsmooth

SERIES, EACH = 10_000, 1_000
SETTINGS = dict(kind="fading", degree=2, theta=0.9, tau=1.0, sigma=0.5)


@pytest.fixture(scope="module")
def rows() -> pd.DataFrame:
    """10⁴ series of 10³ samples, interleaved, each on its own irregular clock."""
    rng = np.random.default_rng(2026)
    ids = np.tile(np.arange(SERIES), EACH)
    steps = rng.uniform(0.5, 1.5, (EACH, SERIES))
    t = np.cumsum(steps, axis=0).ravel() + 1.7e9
    y = np.sin(t / 300.0) * 5 + ids * 1e-3 + rng.standard_normal(t.size)
    return pd.DataFrame({"id": ids, "t": t, "y": y})


@pytest.fixture(scope="module")
def single(rows) -> pd.DataFrame:
    return seqsmooth.filter_frame(rows, by="id", **SETTINGS)


# The recipe functions (as in docs/python.md): each gets whole series.
def filter_partition(part: pd.DataFrame) -> pd.DataFrame:
    """One partition holding whole series, in any row order: each series in time order."""
    part = part.sort_values(["id", "t"], kind="stable")
    out = seqsmooth.filter_frame(part, by="id", **SETTINGS)
    out.index = part.index
    return out


def filter_group(group: pd.DataFrame) -> pd.DataFrame:
    """One series, its key column selected into the group (``groupby("id")[["id", ...]]``)."""
    group = group.sort_values("t", kind="stable")
    out = seqsmooth.filter_frame(group, by="id", **SETTINGS)
    out.index = group.index
    return out


def same_bits(got: pd.DataFrame, want: pd.DataFrame) -> None:
    got = got.sort_index()
    assert list(got.columns) == list(want.columns) and len(got) == len(want)
    for c in want.columns:
        a, b = got[c].to_numpy(), want[c].to_numpy()
        if a.dtype.kind == "f":
            assert np.array_equal(a, b, equal_nan=True), c
            ok = ~np.isnan(a)
            assert np.array_equal(a[ok].view(np.int64), b[ok].view(np.int64)), c
        else:
            assert np.array_equal(a, b), c


def test_dask_map_partitions_equals_one_process(rows, single, client):
    import dask.dataframe as dd

    ddf = dd.from_pandas(rows, npartitions=8).shuffle(on="id")
    out = ddf.map_partitions(filter_partition, meta=single.iloc[:0]).compute()
    same_bits(out, single)


def test_dask_groupby_apply_equals_one_process(rows, single, client):
    import dask.dataframe as dd

    ddf = dd.from_pandas(rows, npartitions=8)
    groups = ddf.groupby("id")[["id", "t", "y"]]
    out = groups.apply(filter_group, meta=single.iloc[:0]).compute()
    same_bits(out.reset_index(level=0, drop=True) if out.index.nlevels > 1 else out, single)


# Spark: groupBy(...).applyInPandas and applyInArrow in local mode, with the machine's Java.
def filter_pandas_group(group: pd.DataFrame) -> pd.DataFrame:
    group = group.sort_values("t", kind="stable")
    return seqsmooth.filter_frame(group, by="id", **SETTINGS)


def filter_arrow_group(table):
    table = table.sort_by("t")
    return seqsmooth.filter_frame(table, by="id", **SETTINGS)


def spark_schema(single: pd.DataFrame) -> str:
    return ", ".join(
        f"{c} {'long' if single[c].dtype.kind == 'i' else 'double'}" for c in single.columns
    )


def sorted_rows(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.sort_values(["id", "t"], kind="stable").reset_index(drop=True)


@pytest.mark.parametrize("how", ["applyInPandas", "applyInArrow"])
def test_spark_equals_one_process(rows, single, spark, how):
    sdf = spark.createDataFrame(rows)
    grouped = sdf.groupBy("id")
    function = filter_pandas_group if how == "applyInPandas" else filter_arrow_group
    out = getattr(grouped, how)(function, schema=spark_schema(single)).toPandas()
    want = sorted_rows(single.assign(id=single["id"].astype(np.int64)))
    same_bits(sorted_rows(out), want)
