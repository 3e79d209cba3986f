"""FadingBank and ExpandingBank: the library's run to the last bit, each channel as its
single-stream filter (≤ 1e-11), the expanding bank as numpy's least-squares fit, one step at a
time as many at once (bit for bit), and their errors."""

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


def test_banks_equal_the_librarys_run_to_the_last_bit():
    """The library's own run (tests/fixtures/bank_rust.txt, written and checked by
    crates/seqsmooth/tests/bank_python_fixture.rs): five channels, 60 steps taken in chunks of
    1, 2, 7 and 50 rows, fading (θ = 0.875) of degrees 0-3 and 5, expanding of degrees 0-2, 4
    and 8, every channel's estimate after each chunk."""
    from pathlib import Path

    path = Path(__file__).parent / "fixtures" / "bank_rust.txt"
    lines = [text.split(",") for text in path.read_text().splitlines()]
    assert lines[0][0] == "input"
    y = np.array([float(c) for c in lines[0][1:]]).reshape(60, 5)
    runs: dict[tuple[str, int], list[list[str]]] = {}
    for tag, degree, *cells in lines[1:]:
        runs.setdefault((tag, int(degree)), []).append(cells)
    assert len(runs) == 10
    for (tag, m), rows in runs.items():
        if tag == "fading":
            bank = ss.FadingBank(degree=m, theta=0.875, channels=5, tau=0.25)
        else:
            bank = ss.ExpandingBank(degree=m, channels=5, tau=0.25)
        done = 0
        for chunk, (steps, *cells) in zip([1, 2, 7, 50], rows):
            bank.update(y[done : done + chunk])
            done += chunk
            assert int(steps) == done == bank.samples
            got = bank.estimate()
            if cells == ["-"]:
                assert np.isnan(got).all()
                continue
            want = np.array([float(c) for c in cells]).reshape(5, m + 1)
            assert np.array_equal(got.view(np.int64), want.view(np.int64)), (tag, m, done)
