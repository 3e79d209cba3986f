"""smooth: scipy.signal.savgol_filter's numbers on even samples (≤ 1e-8), an independent
least-squares solve per window on irregular times, and its errors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import savgol_filter

import seqsmooth as ss


@pytest.mark.parametrize("window,order", [(5, 2), (11, 3), (31, 4), (101, 2), (9, 8)])
@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_equals_savgol_filter(window, order, deriv):
    rng = np.random.default_rng(window * 10 + order)
    delta = 0.01
    x = delta * np.arange(2000)
    y = np.sin(3 * x) + 0.5 * x + 0.1 * rng.standard_normal(x.size)
    got = ss.smooth(y, window, order, deriv=deriv, delta=delta)
    want = savgol_filter(y, window, order, deriv=deriv, delta=delta, mode="interp")
    scale = np.max(np.abs(want)) if deriv <= order else 1.0
    assert np.max(np.abs(got - want)) <= 1e-8 * scale


def test_irregular_times_fit_each_window():
    """At each interior sample, the degree-2 least-squares polynomial of the centred window
    (numpy's solve), evaluated at the sample's time."""
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.5, 1.5, 300))
    y = np.cos(t / 10) + 0.05 * rng.standard_normal(t.size)
    window, order = 9, 2
    got0 = ss.smooth(y, window, order, t=t)
    got1 = ss.smooth(y, window, order, deriv=1, t=t)
    half = window // 2
    for i in range(half, t.size - half):
        tw, yw = t[i - half : i + half + 1], y[i - half : i + half + 1]
        p = np.polynomial.Polynomial.fit(tw, yw, order)
        assert abs(got0[i] - p(t[i])) <= 1e-10
        assert abs(got1[i] - p.deriv()(t[i])) <= 1e-10
    # the ends take the first and last full windows
    p = np.polynomial.Polynomial.fit(t[:window], y[:window], order)
    np.testing.assert_allclose(got0[:half], p(t[:half]), atol=1e-10)


def test_derivatives_above_the_order_are_zero():
    assert not ss.smooth(np.arange(10.0) ** 2, 5, 1, deriv=2).any()


@pytest.mark.parametrize(
    "call,kind",
    [
        (lambda: ss.smooth(np.arange(4.0), 5, 2), ss.TooFewSamplesError),
        (lambda: ss.smooth(np.arange(10.0), 2, 2), ss.ParameterError),
        (lambda: ss.smooth([], 3, 1), ss.InvalidInputError),
        (lambda: ss.smooth(np.arange(10.0), 5, 2, delta=0.0), ss.ParameterError),
        (lambda: ss.smooth(np.arange(10.0), 5, 2, t=np.arange(9.0)), ss.InvalidInputError),
        (lambda: ss.smooth([1.0, np.nan, 3.0, 4.0], 3, 1), ss.InvalidInputError),
        (lambda: ss.smooth(np.ones(5), 3, 1, t=[0.0, 1.0, 1.0, 2.0, 3.0]), ss.InvalidInputError),
    ],
)
def test_errors(call, kind):
    with pytest.raises(kind):
        call()


@pytest.mark.parametrize("spacing", ["even", "irregular"])
def test_equals_the_command_to_the_last_bit(tmp_path, spacing):
    """Every derivative of `seqsmooth smooth` for the same rows, bit for bit."""
    import csv
    import subprocess

    from conftest import cli_path

    rng = np.random.default_rng(8)
    n = 500
    t = 0.25 * np.arange(n) if spacing == "even" else np.cumsum(rng.uniform(0.5, 1.5, n))
    y = np.sin(t / 7.0) + 0.1 * rng.standard_normal(n)
    source = tmp_path / "in.csv"
    source.write_text("t,y\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), y.tolist())))
    out = subprocess.run(
        [str(cli_path()), "smooth", str(source), "--degree", "3", "--window", "15"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    rows = list(csv.reader(out.splitlines()))[1:]
    for k in range(4):
        got = ss.smooth(y, 15, 3, deriv=k, t=t)
        want = np.array([float(r[2 + k]) for r in rows])
        assert np.array_equal(got.view(np.int64), want.view(np.int64)), k
