"""FadingBank and ExpandingBank: each channel as its single-stream filter (≤ 1e-11), the
expanding bank as numpy's least-squares fit, one step at a time as many at once (bit for
bit), and their errors."""

from __future__ import annotations

import numpy as np
import pytest

import seqsmooth as ss


def channels(rng, steps, k, tau):
    t = tau * np.arange(steps)
    y = (
        rng.uniform(-5, 5, k)
        + np.outer(t, rng.uniform(-1, 1, k))
        + 0.01 * np.outer(t**2, rng.uniform(-1, 1, k))
        + 0.2 * rng.standard_normal((steps, k))
    )
    return t, y


@pytest.mark.parametrize("m", [0, 1, 2, 3])
def test_fading_bank_equals_single_streams(m):
    """The bank runs Morrison's gain recursion from a zero state, the single stream from an
    exact start: equal to 1e-11 of the scale once past the start (as tests/bank.rs)."""
    rng = np.random.default_rng(m)
    t, y = channels(rng, 400, 7, 0.5)
    bank = ss.FadingBank(degree=m, theta=0.9, channels=7, tau=0.5)
    bank.update(y)
    got = bank.estimate()
    for c in range(7):
        f = ss.FadingMemory(degree=m, theta=0.9, tau=0.5, engine="gain")
        want = f.update_many(t, y[:, c])[-1]
        scale = np.maximum(np.abs(want), 1.0)
        assert np.max(np.abs(got[c] - want) / scale) <= 1e-11


@pytest.mark.parametrize("m", [0, 2, 4])
def test_expanding_bank_is_the_least_squares_fit(m):
    rng = np.random.default_rng(10 + m)
    t, y = channels(rng, 60, 4, 0.25)
    bank = ss.ExpandingBank(degree=m, channels=4, tau=0.25)
    bank.update(y)
    for c, row in enumerate(bank.estimate()):
        p = np.polynomial.Polynomial.fit(t, y[:, c], m)
        want = [p.deriv(k)(t[-1]) for k in range(m + 1)]
        np.testing.assert_allclose(row, want, rtol=1e-9, atol=1e-9)


def test_one_step_at_a_time_equals_many():
    rng = np.random.default_rng(3)
    _, y = channels(rng, 50, 5, 1.0)
    a = ss.FadingBank(degree=2, theta=0.8, channels=5)
    b = ss.FadingBank(degree=2, theta=0.8, channels=5)
    a.update(y)
    for row in y:
        b.update(row)
    assert a.samples == b.samples == 50
    assert np.array_equal(a.estimate(), b.estimate())


def test_undetermined_then_errors():
    bank = ss.ExpandingBank(degree=2, channels=3)
    bank.update([1.0, 2.0, 3.0])
    assert np.isnan(bank.estimate()).all()
    with pytest.raises(ss.InvalidInputError):
        bank.update([1.0, 2.0])  # two values for three channels
    y = np.ones((4, 3))
    y[2, 1] = np.nan
    with pytest.raises(ss.InvalidInputError) as e:
        bank.update(y)
    assert e.value.index == 2 and bank.samples == 3  # the rows before it are taken
    with pytest.raises(ss.ParameterError):
        ss.FadingBank(degree=2, theta=1.0, channels=3)
    with pytest.raises(ss.ParameterError):
        ss.FadingBank(degree=2, theta=0.9, channels=0)
