"""filter_frame: the same rows as `seqsmooth filter --id-col` for pandas, Polars, pyarrow and
dict inputs, and its errors with the frame's row."""

from __future__ import annotations

import csv
import subprocess

import numpy as np
import pandas as pd
import polars as pl
import pyarrow as pa
import pytest

import seqsmooth as ss
from conftest import cli_path


def interleaved(rng: np.random.Generator, series: int = 25, rows: int = 1200):
    """`rows` rows of `series` series with string ids, interleaved at random; each series'
    times increase (irregular steps, Unix-epoch origin); one row in 40 an outlier (+5)."""
    ids = rng.integers(0, series, rows)
    t = np.empty(rows)
    clock = 1.7e9 + rng.uniform(0, 100, series)
    for i, k in enumerate(ids):
        clock[k] += rng.uniform(0.5, 1.5)
        t[i] = clock[k]
    y = np.sin(t / 50.0) * 10 + ids + 0.3 * rng.standard_normal(rows)
    y[rng.uniform(size=rows) < 1 / 40] += 5.0
    names = np.array([f"sensor-{k:02d}" for k in ids], dtype=object)
    return names, t, y


def run_cli(tmp_path, names, t, y, *flags) -> dict[str, np.ndarray]:
    source = tmp_path / "in.csv"
    with open(source, "w") as f:
        f.write("id,t,y\n")
        for a, b, c in zip(names, t.tolist(), y.tolist()):
            f.write(f"{a},{b!r},{c!r}\n")
    out = subprocess.run(
        [str(cli_path()), "filter", str(source), "--id-col", "id", "--no-progress", *flags],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    rows = list(csv.reader(out.splitlines()))
    header = rows[0]
    return {
        h: np.array([r[i] for r in rows[1:]], dtype=object)
        if h == "id"
        else np.array([float(r[i]) if r[i] else np.nan for r in rows[1:]])
        for i, h in enumerate(header)
    }


def as_numpy(frame, name) -> np.ndarray:
    if isinstance(frame, pa.Table):
        return frame.column(name).to_numpy(zero_copy_only=False)
    return np.asarray(frame[name])


SETTINGS = [
    (
        dict(kind="fading", degree=2, theta=0.9, tau=1.0, sigma=0.3),
        ["--kind", "fading", "--degree", "2", "--theta", "0.9", "--tau", "1", "--sigma", "0.3"],
    ),
    # Without tau, the library's default (the median time step within series) on both sides.
    (
        dict(kind="fading", degree=1, theta=0.8),
        ["--kind", "fading", "--degree", "1", "--theta", "0.8"],
    ),
    (dict(kind="expanding", degree=1), ["--kind", "expanding", "--degree", "1"]),
    (
        dict(kind="fixed", degree=2, window=7),
        ["--kind", "fixed", "--degree", "2", "--window", "7"],
    ),
    # The automatic filter: its noise σ estimated, τ the library's default; then with tau, σ
    # and a review window. Its `outlier` column is the final decision on both sides.
    (
        dict(kind="auto", degree=1, theta=0.9),
        ["--kind", "auto", "--degree", "1", "--theta", "0.9"],
    ),
    (
        dict(kind="auto", degree=2, theta=0.8, tau=2.0, sigma=0.3, review_window=5),
        ["--kind", "auto", "--degree", "2", "--theta", "0.8", "--tau", "2"]
        + ["--sigma", "0.3", "--review-window", "5"],
    ),
]


@pytest.mark.parametrize(
    "settings,flags",
    SETTINGS,
    ids=[
        s[0]["kind"]
        + ("" if "tau" in s[0] or s[0]["kind"] not in ("fading", "auto") else "-default-tau")
        for s in SETTINGS
    ],
)
@pytest.mark.parametrize("library", ["pandas", "polars", "pyarrow", "dict"])
def test_same_rows_as_the_command(tmp_path, rng, settings, flags, library):
    names, t, y = interleaved(rng)
    want = run_cli(tmp_path, names, t, y, *flags)
    data = {"id": names, "t": t, "y": y}
    frame = {
        "pandas": lambda: pd.DataFrame(data),
        "polars": lambda: pl.DataFrame({"id": names.tolist(), "t": t, "y": y}),
        "pyarrow": lambda: pa.table({"id": names.tolist(), "t": t, "y": y}),
        "dict": lambda: data,
    }[library]()
    got = ss.filter_frame(frame, by="id", **settings)
    assert type(got) is type(frame)
    columns = (
        list(got.keys())
        if isinstance(got, dict)
        else list(got.columns if not isinstance(got, pa.Table) else got.column_names)
    )
    assert columns == list(want.keys())
    assert [str(v) for v in as_numpy(got, "id")] == list(want["id"])
    for name in columns[1:]:
        a, b = as_numpy(got, name).astype(float), want[name]
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
        ok = ~np.isnan(a)
        assert np.array_equal(a[ok].view(np.int64), b[ok].view(np.int64)), name


def test_one_series_without_by(rng):
    _, t, y = interleaved(rng, series=1, rows=300)
    got = ss.filter_frame(
        pd.DataFrame({"t": t, "y": y}), kind="fading", degree=1, theta=0.8, tau=1.0
    )
    want = ss.FadingMemory(1, 0.8).update_many(t, y)
    np.testing.assert_array_equal(got[["d0", "d1"]].to_numpy(), want)


def test_pandas_result_is_writable_and_leaves_the_input_alone(rng):
    # The input's columns in the result share its memory under pandas' copy-on-write: every
    # column of the result can be written, without changing the input.
    names, t, y = interleaved(rng, series=4, rows=200)
    df = pd.DataFrame({"id": names, "t": t, "y": y}, index=np.arange(200) * 2)
    before = df.copy(deep=True)
    out = ss.filter_frame(df, by="id", kind="fading", degree=1, theta=0.8, tau=1.0)
    assert isinstance(out.index, pd.RangeIndex)
    np.testing.assert_array_equal(out["y"].to_numpy(), y)
    for c in out.columns:
        out.loc[0, c] = "x" if c == "id" else 7.0
    pd.testing.assert_frame_equal(df, before)


def test_auto_outliers_are_the_final_decisions(rng):
    """The `outlier` column of kind "auto" is each series' final decision, as
    `AutomaticFilter.finish` gives it series by series (the review may overturn the gate)."""
    names, t, y = interleaved(rng, series=6, rows=900)
    got = ss.filter_frame(
        {"id": names, "t": t, "y": y}, by="id", kind="auto", degree=1, theta=0.9, tau=1.0
    )
    overturned = 0
    for name in np.unique(names):
        rows = names == name
        f = ss.AutomaticFilter(1, 0.9, tau=1.0)
        out = f.update_many(t[rows], y[rows])
        final = np.concatenate([out["decided"], f.finish()]).astype(float)
        np.testing.assert_array_equal(got["noise"][rows], out["noise"])
        flags = got["outlier"][rows]
        shown = ~np.isnan(flags)
        np.testing.assert_array_equal(flags[shown], final[shown])
        overturned += int(np.sum(flags[shown] != np.asarray(out["outlier"], float)[shown]))
    assert overturned > 0  # the decisions matter here: the gate's flags are not the answer
    assert np.nansum(got["outlier"]) > 0


def test_errors_name_the_row_of_the_frame(rng):
    names, t, y = interleaved(rng, series=5, rows=200)
    y = y.copy()
    y[137] = np.nan
    with pytest.raises(ss.InvalidInputError) as e:
        ss.filter_frame({"id": names, "t": t, "y": y}, by="id", kind="expanding", degree=1)
    assert e.value.index == 137 and "row 137" in str(e.value) and names[137] in str(e.value)
    t = t.copy()
    later = np.flatnonzero(names == names[150])
    later = later[later > 150][0]
    t[later] = t[150]  # the series' time repeats
    with pytest.raises(ss.InvalidInputError) as e:
        ss.filter_frame(
            {"id": names, "t": t, "y": np.ones(200)}, by="id", kind="expanding", degree=1
        )
    assert e.value.index == later
    with pytest.raises(ss.InvalidInputError, match="no column 'time'"):
        ss.filter_frame(pd.DataFrame({"t": t, "y": y}), time="time", kind="expanding", degree=1)
    with pytest.raises(ss.ParameterError):
        ss.filter_frame(pd.DataFrame({"t": t, "y": y}), kind="fading", degree=1)
    with pytest.raises(ss.InvalidInputError):
        ss.filter_frame(pd.DataFrame({"t": [], "y": []}), kind="expanding", degree=1)
