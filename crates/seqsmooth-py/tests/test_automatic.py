"""AutomaticFilter: the numbers of `seqsmooth filter --kind auto` to the last bit (estimate,
1σ, noise, bias, misfit) and its final outlier decisions, on irregular times with outliers
and a manoeuvre; its errors."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import seqsmooth as ss
from conftest import irregular_series, run_filter


def same_bits(a, b, name):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
    ok = ~np.isnan(a)
    assert np.array_equal(a[ok].view(np.int64), b[ok].view(np.int64)), name


@pytest.mark.parametrize("sigma", [None, 0.3])
def test_equals_the_command(tmp_path, rng, sigma):
    t, y = irregular_series(rng, 600, start=1.7e9)
    y = y.copy()
    y[[100, 250, 251, 400]] += [8.0, -6.0, 7.0, 9.0]  # outliers
    y[500:] += 0.2 * (t[500:] - t[500])  # a change of slope
    m = 2
    f = ss.AutomaticFilter(degree=m, theta=0.95, tau=1.0, sigma=sigma)
    got = f.update_many(t, y)
    assert f.decided == len(got["decided"]) and len(t) - f.decided <= 2 + 4  # the review's
    final = np.concatenate([got["decided"], f.finish()])
    assert f.decided == len(t)
    flags = ["--kind", "auto", "--degree", "2", "--theta", "0.95", "--tau", "1"]
    want = run_filter(tmp_path, t, y, *flags, *(["--sigma", "0.3"] if sigma else []))
    for k in range(m + 1):
        same_bits(got["d"][:, k], want[f"d{k}"], f"d{k}")
        same_bits(got["s"][:, k], want[f"s{k}"], f"s{k}")
    same_bits(got["noise"], want["noise"], "noise")
    same_bits(got["bias"], want["bias"], "bias")
    assert np.array_equal(got["misfit"], want["misfit"] == 1.0)
    assert np.array_equal(final, want["outlier"] == 1.0)
    assert final[[100, 400]].all() and final.sum() < 20
    assert len(final) == len(t) and f.samples <= len(t)  # samples counts the accepted ones
    assert set(got["degree"]) <= set(range(m + 1))
    # The degree in use is the estimate's: d is NaN above it, and it settles from 0 to m.
    shown = ~np.isnan(got["d"][:, 0])
    assert shown.sum() > 500
    assert np.array_equal(np.isfinite(got["d"][shown]).sum(axis=1) - 1, got["degree"][shown])
    assert got["degree"][0] == 0 and got["degree"][-1] == m
    assert np.isfinite(f.estimate().derivatives).all()
    # In pieces: the same rows, degrees and final decisions.
    g = ss.AutomaticFilter(degree=m, theta=0.95, tau=1.0, sigma=sigma)
    parts = [g.update_many(t[k], y[k]) for k in (slice(0, 251), slice(251, None))]
    for key in got:
        same_bits(np.concatenate([p[key] for p in parts]), got[key], key)
    assert np.array_equal(np.concatenate([p["decided"] for p in parts] + [g.finish()]), final)
    # Pickled between the pieces: the same decisions, and a state that does not grow with
    # the samples (no decision is kept once reported).
    h = ss.AutomaticFilter(degree=m, theta=0.95, tau=1.0, sigma=sigma)
    first = h.update_many(t[:251], y[:251])["decided"]
    small = len(pickle.dumps(h))
    h = pickle.loads(pickle.dumps(h))
    assert h.decided == len(first)
    rest = h.update_many(t[251:], y[251:])["decided"]
    assert abs(len(pickle.dumps(h)) - small) < 200
    assert np.array_equal(np.concatenate([first, rest, h.finish()]), final)
    # A refused sample: the decisions its call made before it are reported by the next call
    # (and survive a pickle), none lost.
    e = ss.AutomaticFilter(degree=m, theta=0.95, tau=1.0, sigma=sigma)
    first = e.update_many(t[:200], y[:200])["decided"]
    with pytest.raises(ss.InvalidInputError) as bad:
        e.update_many(np.append(t[200:260], t[259]), np.append(y[200:260], 0.0))
    assert bad.value.index == 60 and e.decided == len(first)
    e = pickle.loads(pickle.dumps(e))
    rest = e.update_many(t[260:], y[260:])["decided"]
    assert np.array_equal(np.concatenate([first, rest, e.finish()]), final)
    # A pickle of an earlier version kept every decision made, none reported: the next call
    # reports them, from the first sample.
    fn, (cls, (body, _)) = g.__reduce__()
    old = fn(cls, (body, bytes(len(final) - 3) + b"\x01\x00\x01"))
    assert old.decided == 0
    assert np.array_equal(old.finish(), [False] * (len(final) - 3) + [True, False, True])
    with pytest.raises(ss.DamagedStateError):
        fn(cls, (body, b"\x02"))
    with pytest.raises(ss.DamagedStateError):
        fn(cls, (body, (-1, b"")))


def test_errors():
    with pytest.raises(ss.ParameterError):
        ss.AutomaticFilter(degree=2, theta=1.2)
    with pytest.raises(ss.ParameterError):
        ss.AutomaticFilter(degree=2, theta=0.9, engine="x")
    with pytest.raises(ss.ParameterError):
        ss.AutomaticFilter(degree=3, theta=0.9, review_window=2)
    f = ss.AutomaticFilter(degree=1, theta=0.9)
    with pytest.raises(ss.InvalidInputError) as e:
        f.update_many([0.0, 1.0, 1.0], [1.0, 2.0, 3.0])
    assert e.value.index == 2 and f.samples == 2


def test_no_estimate_without_its_sigma(rng):
    """Without ``sigma``, the first m + 5 rows have no estimate (NaN ``d`` and ``s``) while
    ``noise`` is NaN (not estimated yet); every row with an estimate has its σ."""
    t, y = irregular_series(rng, 100, start=0.0)
    got = ss.AutomaticFilter(degree=2, theta=0.95, tau=1.0).update_many(t, y)
    unknown = np.isnan(got["noise"])
    assert unknown[:7].all() and not unknown[7:].any()
    assert np.isnan(got["d"][unknown]).all() and np.isnan(got["s"][unknown]).all()
    has = ~np.isnan(got["d"][:, 0])
    assert has[7:].all() and np.isfinite(got["s"][has, 0]).all()
    known = ss.AutomaticFilter(degree=2, theta=0.95, tau=1.0, sigma=0.3).update_many(t, y)
    assert np.isfinite(known["d"][:, 0]).all() and np.isfinite(known["s"][:, 0]).all()
