"""The Kalman-bank scale-out recipes of docs/python.md: Dask (`map_partitions` after a shuffle
on the series) on a `dask.distributed.LocalCluster` of two worker processes, and Spark
(`groupBy(...).applyInPandas`, `applyInArrow`) in local mode, running `kalman_frame` over
500 series × 200 rows with 10 % missing values, give exactly the single-process result (few
enough groups that the Spark tests stay under a minute: each group is one Python call)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from test_scaleout import same_bits, sorted_rows, spark_schema

import seqsmooth

SERIES, EACH = 500, 200
SETTINGS = dict(degree=1, P0=100.0, R=0.5, q=0.01, smoother="rts")


@pytest.fixture(scope="module")
def rows() -> pd.DataFrame:
    """Interleaved series, each on its own irregular clock, 10 % of the values missing."""
    rng = np.random.default_rng(33)
    ids = np.tile(np.arange(SERIES), EACH)
    t = np.cumsum(rng.uniform(0.5, 1.5, (EACH, SERIES)), axis=0).ravel()
    y = np.sin(t / 30.0) * 5 + ids * 1e-3 + rng.standard_normal(t.size)
    y[rng.random(t.size) < 0.1] = np.nan
    return pd.DataFrame({"id": ids, "t": t, "y": y})


@pytest.fixture(scope="module")
def single(rows) -> pd.DataFrame:
    return seqsmooth.kalman_frame(rows, by="id", **SETTINGS)


# The recipe functions (as in docs/python.md): each gets whole series.
def kalman_partition(part: pd.DataFrame) -> pd.DataFrame:
    part = part.sort_values(["id", "t"], kind="stable")
    out = seqsmooth.kalman_frame(part, by="id", **SETTINGS)
    out.index = part.index
    return out


def kalman_pandas_group(group: pd.DataFrame) -> pd.DataFrame:
    return seqsmooth.kalman_frame(group.sort_values("t", kind="stable"), by="id", **SETTINGS)


def kalman_arrow_group(table):
    return seqsmooth.kalman_frame(table.sort_by("t"), by="id", **SETTINGS)


def test_dask_kalman_map_partitions_equals_one_process(rows, single, client):
    import dask.dataframe as dd

    ddf = dd.from_pandas(rows, npartitions=8).shuffle(on="id")
    out = ddf.map_partitions(kalman_partition, meta=single.iloc[:0]).compute()
    same_bits(out, single)


@pytest.mark.parametrize("how", ["applyInPandas", "applyInArrow"])
def test_spark_kalman_equals_one_process(rows, single, spark, how):
    sdf = spark.createDataFrame(rows)
    function = kalman_pandas_group if how == "applyInPandas" else kalman_arrow_group
    out = getattr(sdf.groupBy("id"), how)(function, schema=spark_schema(single)).toPandas()
    want = sorted_rows(single.assign(id=single["id"].astype(np.int64)))
    same_bits(sorted_rows(out), want)
