"""ExpandingMemory, FadingMemory, FixedMemory: the same numbers as `seqsmooth filter` to the
last bit (same inputs, same path), against filterpy's FadingMemoryFilter (the same
recursion), against a direct least-squares solve, and their errors."""

from __future__ import annotations

import re

import numpy as np
import pytest

import seqsmooth as ss
from conftest import irregular_series, run_filter


def same_bits(a: np.ndarray, b: np.ndarray) -> None:
    """Equal to the last bit, NaN where the other is NaN."""
    assert a.shape == b.shape
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
    ok = ~np.isnan(a)
    assert np.array_equal(a[ok].view(np.int64), b[ok].view(np.int64)), np.max(np.abs(a[ok] - b[ok]))


CASES = [
    ("expanding", {"degree": 2}, ["--kind", "expanding", "--degree", "2"]),
    (
        "expanding-gain",
        {"degree": 1, "engine": "gain"},
        ["--kind", "expanding", "--degree", "1", "--engine", "gain"],
    ),
    (
        "fading",
        {"degree": 3, "theta": 0.95, "tau": 2.0},
        ["--kind", "fading", "--degree", "3", "--theta", "0.95", "--tau", "2"],
    ),
    (
        "fading-gain",
        {"degree": 2, "theta": 0.9, "tau": 1.0, "engine": "gain"},
        ["--kind", "fading", "--degree", "2", "--theta", "0.9", "--tau", "1", "--engine", "gain"],
    ),
    ("fixed", {"degree": 2, "window": 15}, ["--kind", "fixed", "--degree", "2", "--window", "15"]),
]


def make(kind: str, kwargs: dict, sigma=None) -> ss.PolynomialFilter:
    cls = {"expanding": ss.ExpandingMemory, "fading": ss.FadingMemory, "fixed": ss.FixedMemory}[
        kind.split("-")[0]
    ]
    return cls(**kwargs, sigma=sigma)


@pytest.mark.parametrize("kind,kwargs,flags", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("with_sigma", [False, True])
def test_update_many_equals_the_command_to_the_last_bit(
    tmp_path, rng, kind, kwargs, flags, with_sigma
):
    t, y = irregular_series(rng, 400, start=1.7e9)  # Unix-epoch times
    m = kwargs["degree"]
    sigma = 0.3 if with_sigma else None
    got = make(kind, kwargs, sigma).update_many(t, y, return_sigma=with_sigma)
    extra = ["--sigma", "0.3"] if with_sigma else []
    want = run_filter(tmp_path, t, y, *flags, *extra)
    d = np.column_stack([want[f"d{k}"] for k in range(m + 1)])
    if with_sigma:
        est, sd = got
        same_bits(est, d)
        same_bits(sd, np.column_stack([want[f"s{k}"] for k in range(m + 1)]))
    else:
        same_bits(got, d)


@pytest.mark.parametrize("kind,kwargs,flags", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("with_sigma", [False, True])
def test_update_many_into_out_is_the_new_arrays_bits(rng, kind, kwargs, flags, with_sigma):
    # A reused out= buffer, dirty from the batch before, written in place: the same bits as
    # new arrays, batch after batch, and the returned arrays are that buffer (or its views).
    t, y = irregular_series(rng, 300)
    m = kwargs["degree"]
    sigma = 0.3 if with_sigma else None
    fresh, reused = make(kind, kwargs, sigma), make(kind, kwargs, sigma)
    out = np.full((100, (m + 1) * (2 if with_sigma else 1)), 1e300)
    for start in range(0, 300, 100):
        part = slice(start, start + 100)
        want = fresh.update_many(t[part], y[part], return_sigma=with_sigma)
        got = reused.update_many(t[part], y[part], return_sigma=with_sigma, out=out)
        if with_sigma:
            for a, b in zip(got, want):
                same_bits(a, b)
                assert np.shares_memory(a, out)
            np.testing.assert_array_equal(np.hstack(got), out)
        else:
            assert got is out
            same_bits(got, want)


@pytest.mark.parametrize(
    "bad,error,words",
    [
        (np.empty((50, 5)), ss.InvalidInputError, "shape (50, 5)"),
        (np.empty((49, 6)), ss.InvalidInputError, "need (50, 6)"),
        (np.empty((50, 6), dtype=np.float32), ss.InvalidTypeError, "dtype float32"),
        (np.empty((50, 6), dtype=">f8"), ss.InvalidTypeError, "native byte order"),
        (np.empty(300), ss.InvalidInputError, "shape (300,)"),
        (np.empty((50, 6), order="F"), ss.InvalidInputError, "C-contiguous"),
        (np.empty((100, 6))[::2], ss.InvalidInputError, "C-contiguous"),
        (
            np.frombuffer(bytearray(50 * 6 * 8 + 1), offset=1).reshape(50, 6),
            ss.InvalidInputError,
            "aligned",
        ),
        ([[0.0] * 6] * 50, ss.InvalidTypeError, "not a list"),
    ],
)
def test_update_many_refuses_an_unusable_out_before_taking_a_sample(bad, error, words):
    f = ss.FadingMemory(2, 0.9, 1.0, sigma=0.3)
    t = np.arange(50.0)
    with pytest.raises(error, match=re.escape(words)):
        f.update_many(t, np.sin(t), return_sigma=True, out=bad)
    assert f.samples == 0


def test_update_many_refuses_an_out_over_its_inputs_memory():
    # Two frombuffer arrays over one buffer have different bases, so numpy's borrow check
    # does not see them overlap: the filter compares the memory itself.
    memory = bytearray(8 * 30)
    y = np.frombuffer(memory, count=10)
    y[:] = np.arange(10.0)
    out = np.frombuffer(memory, offset=8 * 3, count=10).reshape(10, 1)
    f = ss.ExpandingMemory(0)
    with pytest.raises(ss.InvalidInputError, match="shares memory with y"):
        f.update_many(np.arange(10.0), y, out=out)
    assert f.samples == 0
    # Beside it, not over it: taken.
    apart = np.frombuffer(memory, offset=8 * 10, count=10).reshape(10, 1)
    got = ss.ExpandingMemory(0).update_many(np.arange(10.0), y, out=apart)
    np.testing.assert_allclose(got[:, 0], np.cumsum(np.arange(10.0)) / np.arange(1, 11))


def test_update_many_refuses_a_read_only_out():
    out = np.empty((10, 2))
    out.flags.writeable = False
    f = ss.FadingMemory(1, 0.9, 1.0)
    with pytest.raises(ss.InvalidInputError, match="not writeable"):
        f.update_many(np.arange(10.0), np.ones(10), out=out)
    assert f.samples == 0


def test_update_many_out_keeps_the_rows_before_a_refused_sample():
    t = np.arange(10.0)
    y = np.ones(10)
    y[6] = np.nan
    out = np.full((10, 2), 5.0)
    f = ss.FadingMemory(1, 0.9, 1.0)
    with pytest.raises(ss.InvalidInputError) as e:
        f.update_many(t, y, out=out)
    assert e.value.index == 6 and f.samples == 6
    want = ss.FadingMemory(1, 0.9, 1.0).update_many(t[:6], y[:6])
    same_bits(out[:6], want)


@pytest.mark.parametrize("kind,kwargs,flags", CASES, ids=[c[0] for c in CASES])
def test_update_and_estimate_match_update_many(rng, kind, kwargs, flags):
    t, y = irregular_series(rng, 120)
    batch = make(kind, kwargs, 0.3).update_many(t, y)
    one = make(kind, kwargs, 0.3)
    for i, (a, b) in enumerate(zip(t, y)):
        one.update(a, b)
        if one.is_determined:
            s = one.estimate()
            assert s.time == a
            np.testing.assert_allclose(s.derivatives, batch[i], rtol=1e-12, atol=1e-12)
            assert s.covariance.shape == (kwargs["degree"] + 1,) * 2
            np.testing.assert_array_equal(s.sigma, np.sqrt(np.diag(s.covariance)))
    assert one.samples == len(t) and one.last_time == t[-1]


def test_expanding_memory_is_the_least_squares_fit(rng):
    """The expanding-memory estimate equals numpy's least-squares polynomial of every sample
    so far (an independent solve), at degrees up to 8."""
    for m in (0, 1, 4, 8):
        t, y = irregular_series(rng, 60)
        f = ss.ExpandingMemory(degree=m)
        f.update_many(t, y)
        c = np.polynomial.Polynomial.fit(t, y, m)
        want = [c.deriv(k)(t[-1]) for k in range(m + 1)]
        np.testing.assert_allclose(f.estimate().derivatives, want, rtol=1e-8, atol=1e-9)
        later = t[-1] + 3.5
        np.testing.assert_allclose(
            f.estimate_at(later).derivatives[0], c(later), rtol=1e-8, atol=1e-9
        )


@pytest.mark.parametrize("order", [0, 1, 2])
def test_fading_memory_equals_filterpy(order):
    """filterpy's FadingMemoryFilter runs Morrison's fixed fading gains (13.x) from its x0;
    ours starts expanding and switches to the same gains, so both forget their start at the
    rate θ^n: after 600 samples at θ = 0.9 they agree to rounding (≤ 1e-10 relative)."""
    from filterpy.memory import FadingMemoryFilter

    dt, theta, n = 2.0**-10, 0.9, 1200
    rng = np.random.default_rng(order)
    t = dt * np.arange(n)
    y = 5.0 + 40.0 * t - 300.0 * t**2 + 0.5 * rng.standard_normal(n)
    ours = ss.FadingMemory(degree=order, theta=theta, tau=dt, engine="gain").update_many(t, y)
    peer = FadingMemoryFilter(x0=np.zeros(order + 1), dt=dt, order=order, beta=theta)
    theirs = np.empty((n, order + 1))
    for i, z in enumerate(y):
        peer.update(z)
        theirs[i] = peer.x
    scale = np.max(np.abs(ours[600:]), axis=0)
    assert np.max(np.abs(ours[600:] - theirs[600:]) / scale) <= 1e-10


def test_estimates_are_undetermined_then_nan_free(rng):
    t, y = irregular_series(rng, 10)
    out = ss.ExpandingMemory(degree=3).update_many(t, y)
    assert np.isnan(out[:3]).all() and np.isfinite(out[3:]).all()
    f = ss.ExpandingMemory(degree=3)
    with pytest.raises(ss.TooFewSamplesError):
        f.estimate()


def test_inputs_convert_without_changing_the_numbers(rng):
    """Lists, float32, integers and strided views give the numbers of the float64 array
    they convert to."""
    t, y = irregular_series(rng, 50)
    want = ss.FadingMemory(degree=1, theta=0.8).update_many(t, y)
    both = np.column_stack([t, y])
    for tt, yy in [
        (t.tolist(), y.tolist()),
        (both[:, 0], both[:, 1]),  # strided views
    ]:
        same_bits(ss.FadingMemory(degree=1, theta=0.8).update_many(tt, yy), want)
    ti = np.arange(20)
    yi = np.arange(20) * 3
    same_bits(
        ss.ExpandingMemory(degree=1).update_many(ti, yi),
        ss.ExpandingMemory(degree=1).update_many(ti.astype(float), yi.astype(float)),
    )
    y32 = y.astype(np.float32)
    same_bits(
        ss.ExpandingMemory(degree=1).update_many(t, y32),
        ss.ExpandingMemory(degree=1).update_many(t, y32.astype(np.float64)),
    )


def test_the_time_origin_does_not_matter(rng):
    """The same series at t and at t + 1.7e9 (Unix epoch): the same estimates to rounding
    of the timestamps."""
    t, y = irregular_series(rng, 200)
    a = ss.FadingMemory(degree=2, theta=0.9).update_many(t, y)
    b = ss.FadingMemory(degree=2, theta=0.9).update_many(t + 1.7e9, y)
    ok = ~np.isnan(a)
    # The shifted times are rounded to ε·1.7e9/2 ≈ 1.2e-7 each; the estimates move by that
    # times their slopes (measured: at most 6.0e-7, 8.0e-8, 6.4e-8 for d0, d1, d2).
    np.testing.assert_allclose(a[ok], b[ok], rtol=1e-8, atol=2e-6)
