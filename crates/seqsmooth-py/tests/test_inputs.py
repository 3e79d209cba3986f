"""Inputs users have: dates as times (numpy ``datetime64`` of any unit, pandas naive and
tz-aware, Polars ``Datetime``/``Date``, Arrow timestamps and dates) read as seconds since the
Unix epoch in every entry point that takes times, equal to the same times given as numbers;
their refusals; and ``__version__``."""

from __future__ import annotations

import datetime as dt
import subprocess

import numpy as np
import pandas as pd
import polars as pl
import pyarrow as pa
import pytest
import tomllib

import seqsmooth as ss
from conftest import ROOT, cli_path

# 2024-03-01T12:00:00Z, and 40 samples 250 ms apart from it.
EPOCH = 1_709_294_400
N = 40


def _seconds() -> np.ndarray:
    return EPOCH + 0.25 * np.arange(N)


def _values() -> np.ndarray:
    rng = np.random.default_rng(30)
    return np.sin(0.3 * np.arange(N)) + 0.05 * rng.standard_normal(N)


def _dates(unit: str) -> np.ndarray:
    return (np.datetime64(EPOCH, "s") + (250 * np.arange(N)).astype("timedelta64[ms]")).astype(
        f"datetime64[{unit}]"
    )


@pytest.mark.parametrize("unit", ["ms", "us", "ns"])
def test_datetime64_units_are_seconds(unit):
    np.testing.assert_array_equal(ss.seconds(_dates(unit)), _seconds())


def test_coarse_and_fine_units():
    # whole units above a second, and below a microsecond, exactly
    d = np.array(["2024-03-01", "2024-03-02"], dtype="datetime64[D]")
    np.testing.assert_array_equal(ss.seconds(d), [1_709_251_200.0, 1_709_337_600.0])
    np.testing.assert_array_equal(ss.seconds(d.astype("datetime64[h]")), ss.seconds(d))
    np.testing.assert_array_equal(
        ss.seconds(np.array(["2024-03", "2024-04"], dtype="datetime64[M]")),
        [1_709_251_200.0, 1_711_929_600.0],
    )
    np.testing.assert_array_equal(
        ss.seconds(np.array(["1970", "2024"], dtype="datetime64[Y]")), [0.0, 1_704_067_200.0]
    )
    # nanoseconds beyond 2^53 ticks: the double nearest to the exact decimal
    ns = np.array(["2024-03-01T12:00:00.123456789"], dtype="datetime64[ns]")
    assert ss.seconds(ns)[0] == float("1709294400.123456789")
    # before the epoch
    neg = np.array(["1969-12-31T23:59:59.5"], dtype="datetime64[ms]")
    assert ss.seconds(neg)[0] == -0.5
    # a duration is its seconds
    np.testing.assert_array_equal(ss.seconds(np.array([1500, 2500], "timedelta64[ms]")), [1.5, 2.5])
    # numbers are untouched
    np.testing.assert_array_equal(ss.seconds([1, 2.5]), [1.0, 2.5])


def test_frame_libraries_are_seconds():
    naive = pd.Series(_dates("ns"))
    aware = naive.dt.tz_localize("UTC").dt.tz_convert("Europe/Paris")
    for t in [
        naive,
        aware,
        pd.DatetimeIndex(_dates("us")),
        pl.Series(_dates("us")),
        pl.Series(_dates("ms")).dt.replace_time_zone("UTC").dt.convert_time_zone("Asia/Tokyo"),
        pa.array(_dates("us")),
        pa.array(_dates("ns"), type=pa.timestamp("ns", tz="America/New_York")),
        pa.chunked_array([pa.array(_dates("ms")[:10]), pa.array(_dates("ms")[10:])]),
    ]:
        np.testing.assert_array_equal(ss.seconds(t), _seconds(), err_msg=repr(type(t)))
    days = [dt.date(2024, 3, 1), dt.date(2024, 3, 2)]
    want = [1_709_251_200.0, 1_709_337_600.0]
    np.testing.assert_array_equal(ss.seconds(pl.Series(days)), want)
    np.testing.assert_array_equal(ss.seconds(pa.array(days, type=pa.date32())), want)


def test_every_entry_point_takes_dates():
    """The same numbers, bit for bit, from dates as from their seconds."""
    y = _values()
    secs, dates = _seconds(), _dates("ns")
    for make in [
        lambda: ss.FadingMemory(degree=1, theta=0.9, tau=0.25, sigma=0.1),
        lambda: ss.ExpandingMemory(degree=2),
        lambda: ss.FixedMemory(degree=1, window=9),
    ]:
        a, b = make().update_many(secs, y), make().update_many(dates, y)
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    a = ss.AutomaticFilter(degree=1, theta=0.9).update_many(secs, y)
    b = ss.AutomaticFilter(degree=1, theta=0.9).update_many(pl.Series(dates), y)
    np.testing.assert_array_equal(a["d"], b["d"])
    np.testing.assert_array_equal(a["s"], b["s"])
    kf = ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1e6, t0=float(EPOCH) - 1.0)
    a = kf.update_many(secs, y, 0.01)[0]
    kf = ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1e6, t0=float(EPOCH) - 1.0)
    b = kf.update_many(pa.array(dates), y, 0.01)[0]
    np.testing.assert_array_equal(a, b)
    a = ss.smooth(y, 9, 2, t=secs, return_sigma=True)
    b = ss.smooth(y, 9, 2, t=pd.Series(dates).dt.tz_localize("UTC"), return_sigma=True)
    np.testing.assert_array_equal(a, b)
    frame = pd.DataFrame({"t": dates, "y": y})
    got = ss.filter_frame(frame, kind="fading", degree=1, theta=0.9, tau=0.25)
    want = ss.filter_frame(
        pd.DataFrame({"t": secs, "y": y}), kind="fading", degree=1, theta=0.9, tau=0.25
    )
    pd.testing.assert_frame_equal(got, want)
    got = ss.filter_frame(pl.DataFrame({"t": dates, "y": y}), kind="expanding", degree=1)
    assert got["t"].to_list() == secs.tolist()
    got = ss.filter_frame(pa.table({"t": pa.array(dates), "y": y}), kind="expanding", degree=1)
    assert got.column("t").to_pylist() == secs.tolist()


def test_refusals_name_the_index():
    d = _dates("ms").copy()
    d[7] = np.datetime64("NaT")
    with pytest.raises(ss.InvalidInputError, match=r"t\[7\].*NaT") as e:
        ss.FadingMemory(degree=1, theta=0.9).update_many(d, _values())
    assert e.value.index == 7
    with pytest.raises(ss.InvalidTypeError, match="must hold real numbers"):
        ss.seconds(np.array(["a", "b"]))
    with pytest.raises(ss.InvalidInputError, match="no fixed length"):
        ss.seconds(np.array([1, 2], "timedelta64[M]"))


def test_version_is_the_cargo_version():
    cargo = tomllib.loads((ROOT / "Cargo.toml").read_text())
    assert ss.__version__ == cargo["workspace"]["package"]["version"]
    cli = subprocess.run([str(cli_path()), "--version"], capture_output=True, text=True)
    assert ss.__version__ in cli.stdout


def test_smooth_sigma():
    """``return_sigma``: the 1σ of the value and of a derivative, as the command writes them
    (bit for bit), for a given and for an estimated σ."""
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.5, 1.5, 200))
    y = np.cos(t / 10) + 0.05 * rng.standard_normal(t.size)
    v, s = ss.smooth(y, 11, 2, t=t, return_sigma=True)
    np.testing.assert_array_equal(v, ss.smooth(y, 11, 2, t=t))
    assert np.all(np.isfinite(s)) and np.all(s > 0)
    v1, s1 = ss.smooth(y, 11, 2, deriv=1, t=t, sigma=0.05, return_sigma=True)
    # given σ: σ·√VRF of the window's least-squares fit (numpy's lstsq covariance)
    i = 100
    tw = t[i - 5 : i + 6] - t[i]
    a = np.vander(tw, 3, increasing=True)
    cov = np.linalg.inv(a.T @ a) * 0.05**2
    assert abs(s1[i] - np.sqrt(cov[1, 1])) <= 1e-10 * s1[i]
    with pytest.raises(ss.ParameterError, match="no residuals"):
        ss.smooth(y, 3, 2, return_sigma=True)
    with pytest.raises(ss.ParameterError, match="sigma"):
        ss.smooth(y, 5, 2, sigma=-1.0, return_sigma=True)


def _unaligned(values: np.ndarray) -> np.ndarray:
    """``values`` in a contiguous array one byte off an 8-byte boundary (as an array
    unpickled from a buffer can be)."""
    raw = np.zeros(values.nbytes + 1, dtype=np.uint8)
    out = raw[1:].view(values.dtype)
    out[:] = values
    assert out.flags.c_contiguous and not out.flags.aligned
    return out


def test_unaligned_arrays_are_read_not_refused():
    t, y = _seconds() - EPOCH, _values()
    expected = ss.FadingMemory(degree=1, theta=0.9, tau=0.25).update_many(t, y)
    got = ss.FadingMemory(degree=1, theta=0.9, tau=0.25).update_many(_unaligned(t), _unaligned(y))
    np.testing.assert_array_equal(got, expected)
    stamps = _dates("ns")
    got = ss.FadingMemory(degree=1, theta=0.9, tau=0.25).update_many(_unaligned(stamps), y)
    np.testing.assert_array_equal(
        got, ss.FadingMemory(degree=1, theta=0.9, tau=0.25).update_many(stamps, y)
    )
