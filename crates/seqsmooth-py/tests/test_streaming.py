"""The Spark Structured Streaming recipe of docs/python.md: each key's filter kept across
micro-batches by ``applyInPandasWithState``, its state the filter's pickle, gives the numbers
of one pass over all the data bit for bit.

The stream: 12 keys with string ids interleaved, each on its own irregular clock, about 8 %
of the values missing (NaN) and a few outliers, cut at random rows into 24 Parquet files, the
rows of each file shuffled (a key's rows within a micro-batch in any order; across
micro-batches in time order, as a stream delivers them). A file source with
``maxFilesPerTrigger=1`` makes each file one micro-batch; the query runs with
``trigger(availableNow=True)`` over the first 11 files, stops, and a second query resumes from
its checkpoint over the rest, so that the filters pass through Spark's state store and its
checkpoint on disk. The oracles are independent of the stream: ``filter_frame`` and
``kalman_frame`` over all the rows at once (the library's banks), and one filter per key
over its whole series.

One query filters the rows with three filters at once (the fading-memory, Kalman and
automatic filters of the recipe, each key's three filters in one state), so that the test
pays Spark's cost per micro-batch (seconds in local mode) once."""

from __future__ import annotations

import os
import pickle
import time

import numpy as np
import pandas as pd
import pytest
from test_scaleout import same_bits

import seqsmooth

KEYS, EACH, FILES, FIRST_RUN = 12, 150, 24, 11
FADING = dict(degree=2, theta=0.9, tau=1.0, sigma=0.5)
KALMAN = dict(degree=1, P0=100.0, R=0.5, q=0.01)
AUTO = dict(degree=2, theta=0.9, tau=1.0)


@pytest.fixture(scope="module")
def rows() -> pd.DataFrame:
    """The stream's rows in arrival order: every key's rows in time order, keys interleaved."""
    rng = np.random.default_rng(34)
    parts = []
    for k in range(KEYS):
        t = 1.7e9 + rng.uniform(0, 5) + np.cumsum(rng.uniform(0.2, 1.8, EACH))
        y = 3 * np.sin(t / 40.0) + 0.1 * k + rng.normal(0, 0.5, EACH)
        y[rng.random(EACH) < 0.02] += 30.0  # outliers for the automatic filter
        y[rng.random(EACH) < 0.08] = np.nan  # missing values
        parts.append(pd.DataFrame({"id": f"pump-{k:02d}", "t": t, "y": y}))
    return pd.concat(parts).sort_values("t", kind="stable").reset_index(drop=True)


# The recipe's functions (as in docs/python.md), the three filters side by side.
def fading_rows(f, batch: pd.DataFrame) -> pd.DataFrame:
    """The fading-memory filter's rows: a NaN value is refused by the polynomial filters, so
    those rows are left out (None if none is left: ``update_many`` refuses an empty batch)."""
    batch = batch[batch["y"].notna()]
    if batch.empty:
        return None
    d, s = f.update_many(batch["t"].to_numpy(), batch["y"].to_numpy(), return_sigma=True)
    out = batch[["id", "t", "y"]].reset_index(drop=True)
    for k in range(d.shape[1]):
        out[f"d{k}"] = d[:, k]
    for k in range(s.shape[1]):
        out[f"s{k}"] = s[:, k]
    return out


def kalman_rows(f, batch: pd.DataFrame) -> pd.DataFrame:
    """The Kalman filter's rows: a NaN value is a missing measurement (prediction only)."""
    x, p, nis = f.update_many(batch["t"].to_numpy(), batch["y"].to_numpy(), KALMAN["R"])
    out = batch[["id", "t", "y"]].reset_index(drop=True)
    s = np.sqrt(np.diagonal(p, axis1=1, axis2=2))
    for k in range(x.shape[1]):
        out[f"d{k}"] = x[:, k]
    for k in range(x.shape[1]):
        out[f"s{k}"] = s[:, k]
    out["nis"] = nis
    return out


def auto_rows(f, batch: pd.DataFrame) -> pd.DataFrame:
    """The automatic filter's rows (``outlier``: the decision at the update), as the
    fading-memory filter's."""
    batch = batch[batch["y"].notna()]
    if batch.empty:
        return None
    r = f.update_many(batch["t"].to_numpy(), batch["y"].to_numpy())
    out = batch[["id", "t", "y"]].reset_index(drop=True)
    for k in range(r["d"].shape[1]):
        out[f"d{k}"] = r["d"][:, k]
    for k in range(r["s"].shape[1]):
        out[f"s{k}"] = r["s"][:, k]
    out["noise"] = r["noise"]
    out["outlier"] = r["outlier"].astype(np.float64)
    out["misfit"] = r["misfit"].astype(np.float64)
    out["bias"] = r["bias"]
    return out


def new_filters(t0: float):
    """A key's filters, made on its first row (the Kalman filter starts at that time)."""
    return (
        seqsmooth.FadingMemory(**FADING),
        seqsmooth.KalmanFilter(KALMAN["degree"], np.zeros(2), KALMAN["P0"], t0=t0, q=KALMAN["q"]),
        seqsmooth.AutomaticFilter(**AUTO),
    )


FADING_COLUMNS = "d0 double, d1 double, d2 double, s0 double, s1 double, s2 double"
OUTPUT = (
    "kind string, id string, t double, y double, "
    + FADING_COLUMNS
    + ", noise double, outlier double, misfit double, bias double, nis double"
)


def filter_key(key, batches, state):
    """``applyInPandasWithState``'s function: one key's rows of one micro-batch (in any order,
    in one or more frames), its filters from the state (their pickle) or new, the rows in
    time order through them, the filters back into the state."""
    batch = pd.concat(list(batches)).sort_values("t", kind="stable")
    if state.exists:
        filters = pickle.loads(state.get[0])
    else:
        filters = new_filters(float(batch["t"].iloc[0]))
    fading, kalman, auto = filters
    parts = {
        "fading": fading_rows(fading, batch),
        "kalman": kalman_rows(kalman, batch),
        "auto": auto_rows(auto, batch),
    }
    state.update((pickle.dumps(filters),))
    names = [c.split()[0] for c in OUTPUT.split(", ")]
    for kind, part in parts.items():
        if part is not None:
            yield part.assign(kind=kind).reindex(columns=names)


def write_files(rows: pd.DataFrame, folder: str, rng) -> list[str]:
    """The rows cut at random rows into FILES Parquet files (none empty), each shuffled, in
    `folder`; the files' modification times in stream order (the file source takes the oldest
    first)."""
    cuts = np.sort(rng.choice(np.arange(1, len(rows)), FILES - 1, replace=False))
    paths = []
    start = time.time() - 10 * FILES
    for k, piece in enumerate(np.split(np.arange(len(rows)), cuts)):
        part = rows.iloc[rng.permutation(piece)]
        path = os.path.join(folder, f"part-{k:03d}.parquet")
        part.to_parquet(path, index=False)
        os.utime(path, (start + 10 * k, start + 10 * k))
        paths.append(path)
    return paths


def run_stream(spark, source: str, out: str, checkpoint: str) -> int:
    """One query over the files now in `source`, a micro-batch each; returns the batches."""
    from pyspark.sql.streaming.state import GroupStateTimeout

    stream = (
        spark.readStream.schema("id string, t double, y double")
        .option("maxFilesPerTrigger", 1)
        .parquet(source)
    )
    filtered = stream.groupBy("id").applyInPandasWithState(
        filter_key, OUTPUT, "filters binary", "append", GroupStateTimeout.NoTimeout
    )
    query = (
        filtered.writeStream.format("parquet")
        .option("path", out)
        .option("checkpointLocation", checkpoint)
        .outputMode("append")
        .trigger(availableNow=True)
        .start()
    )
    query.awaitTermination()
    assert query.exception() is None
    return sum(1 for p in query.recentProgress if p["numInputRows"] > 0)


@pytest.fixture(scope="module")
def streamed(rows, spark, tmp_path_factory) -> pd.DataFrame:
    folder = tmp_path_factory.mktemp("stream")
    names = ("staged", "in", "out", "checkpoint")
    staged, source, out, checkpoint = (str(folder / n) for n in names)
    os.mkdir(staged)
    os.mkdir(source)
    paths = write_files(rows, staged, np.random.default_rng(7))
    before = spark.conf.get("spark.sql.shuffle.partitions")
    spark.conf.set("spark.sql.shuffle.partitions", "2")  # the state's partitions, fixed at start
    try:
        batches = 0
        for first, last in ((0, FIRST_RUN), (FIRST_RUN, FILES)):
            for path in paths[first:last]:  # whole files into the source (a rename)
                os.rename(path, os.path.join(source, os.path.basename(path)))
            batches += run_stream(spark, source, out, checkpoint)
    finally:
        spark.conf.set("spark.sql.shuffle.partitions", before)
    assert batches == FILES  # one micro-batch a file, over two queries
    return spark.read.parquet(out).toPandas()


def by_key_time(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.sort_values(["id", "t"], kind="stable").reset_index(drop=True)


def kind_of(streamed: pd.DataFrame, kind: str, columns) -> pd.DataFrame:
    part = streamed[streamed["kind"] == kind]
    return by_key_time(part[list(columns)])


def test_fading_stream_equals_filter_frame(rows, streamed):
    present = rows[rows["y"].notna()]
    want = by_key_time(seqsmooth.filter_frame(present, by="id", kind="fading", **FADING))
    got = kind_of(streamed, "fading", want.columns)
    assert len(got) == len(present)
    same_bits(got, want)


def test_kalman_stream_equals_kalman_frame_and_one_filter(rows, streamed):
    want = by_key_time(seqsmooth.kalman_frame(rows, by="id", **KALMAN))
    got = kind_of(streamed, "kalman", want.columns)
    assert len(got) == len(rows) and got["y"].isna().sum() > 0
    same_bits(got, want)
    # One KalmanFilter over each key's whole series, the recipe's own filter unbroken.
    for key, series in rows.groupby("id"):
        one = new_filters(float(series["t"].iloc[0]))[1]
        mine = got[got["id"] == key].reset_index(drop=True)
        same_bits(mine, kalman_rows(one, series.reset_index(drop=True))[list(want.columns)])


def test_auto_stream_equals_one_pass(rows, streamed):
    present = rows[rows["y"].notna()]
    columns = [c.split()[0] for c in OUTPUT.split(", ")[1:-1]]
    got = kind_of(streamed, "auto", columns)
    # One AutomaticFilter over each key's whole series: every cell, the update's flags too.
    want = by_key_time(
        pd.concat(auto_rows(seqsmooth.AutomaticFilter(**AUTO), s) for _, s in present.groupby("id"))
    )
    same_bits(got, want)
    assert got["outlier"].sum() > 0  # the outliers reached the filter's gate
    # filter_frame's rows, but for its outlier column (the final decision, the whole series
    # being there: a stream cannot know it when it writes a row).
    frame = by_key_time(seqsmooth.filter_frame(present, by="id", kind="auto", **AUTO))
    same_bits(got.drop(columns="outlier"), frame.drop(columns="outlier"))
