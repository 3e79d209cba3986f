"""KalmanFilter: against filterpy's KalmanFilter on the stored fixtures (≤ 1e-10), against
filterpy's fading memory (alpha) live, the RTS smoother against the batch least-squares
solve, update against update_many, and its errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import seqsmooth as ss
from conftest import ROOT

FIXTURES = ROOT / "crates" / "seqsmooth" / "tests" / "fixtures" / "kalman"


def read_fixture(name: str):
    """The setup ('# key,values' lines) and the rows of a fixture of
    scripts/make_kalman_fixtures.py."""
    setup, rows = {}, []
    with open(FIXTURES / f"{name}.csv") as f:
        for line in f:
            if line.startswith("# ") and "," in line and not line.startswith("# made"):
                key, *values = line[2:].strip().split(",")
                setup[key] = [float(v) for v in values]
            elif line[0].isdigit() or line[0] == "-":
                rows.append([float(v) for v in line.strip().split(",")])
    return setup, np.array(rows)


@pytest.mark.parametrize("name", ["cv1", "ca2"])
def test_equals_filterpy_on_the_stored_fixtures(name):
    """Each state component within 1e-10 of max(|x_i|, σ_i) and each covariance entry within
    1e-10 of σ_i σ_j (filterpy's x and σ), at every step, missing rows included."""
    setup, rows = read_fixture(name)
    m, d = int(setup["degree"][0]), int(setup["axes"][0])
    n = (m + 1) * d
    f = ss.KalmanFilter(
        degree=m,
        axes=d,
        q=setup["q"][0],
        t0=setup["t0"][0],
        x0=setup["x0"],
        P0=np.reshape(setup["P0"], (n, n)),
    )
    R = np.reshape(setup["R"], (d, d))
    t, z = rows[:, 0], rows[:, 1 : 1 + d]
    x, P, nis = f.update_many(t, z, R)
    want_x = rows[:, 1 + d : 1 + d + n]
    want_p = rows[:, 1 + d + n :].reshape(-1, n, n)
    sigma = np.sqrt(np.einsum("kii->ki", want_p))
    assert np.max(np.abs(x - want_x) / np.maximum(np.abs(want_x), sigma)) <= 1e-10
    assert np.max(np.abs(P - want_p) / (sigma[:, :, None] * sigma[:, None, :])) <= 1e-10
    missing = np.isnan(z).all(axis=1)
    assert missing.any() and np.isnan(nis[missing]).all() and np.isfinite(nis[~missing]).all()


def test_update_equals_update_many_bit_for_bit():
    setup, rows = read_fixture("ca2")
    kwargs = dict(
        degree=2,
        axes=2,
        q=setup["q"][0],
        t0=setup["t0"][0],
        x0=setup["x0"],
        P0=np.reshape(setup["P0"], (6, 6)),
    )
    R = np.reshape(setup["R"], (2, 2))
    x, P, nis = ss.KalmanFilter(**kwargs).update_many(rows[:, 0], rows[:, 1:3], R)
    one = ss.KalmanFilter(**kwargs)
    for i, row in enumerate(rows):
        innovation = one.update(row[0], row[1:3], R)
        assert np.array_equal(one.state, x[i]) and np.array_equal(one.covariance, P[i])
        if innovation is None:
            assert np.isnan(nis[i])
        else:
            assert innovation.nis == nis[i] and innovation.components == [0, 1]
            assert innovation.gain.shape == (6, 2) and innovation.covariance.shape == (2, 2)
    assert one.time == rows[-1, 0]


def test_fading_memory_per_update_equals_filterpy_alpha():
    """Fading memory per update θ (Morrison ch. 14) is filterpy's alpha = 1/√θ without driving
    noise: the same gains, so the same estimates (≤ 1e-10 of the scale)."""
    from filterpy.kalman import KalmanFilter as Peer

    rng = np.random.default_rng(7)
    dt, theta, steps = 0.5, 0.8, 300
    t = dt * np.arange(1, steps + 1)
    z = 3.0 + 2.0 * t - 0.05 * t**2 + rng.standard_normal(steps)
    ours = ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=100.0, theta_per_update=theta)
    x, _, _ = ours.update_many(t, z, 1.0)
    peer = Peer(dim_x=2, dim_z=1)
    peer.x = np.zeros((2, 1))
    peer.P = 100.0 * np.eye(2)
    peer.F = np.array([[1.0, dt], [0.0, 1.0]])
    peer.H = np.array([[1.0, 0.0]])
    peer.R = np.array([[1.0]])
    peer.Q = np.zeros((2, 2))
    peer.alpha = 1.0 / math.sqrt(theta)
    theirs = np.empty((steps, 2))
    for i in range(steps):
        peer.predict()
        peer.update(z[i])
        theirs[i] = peer.x[:, 0]
    assert np.max(np.abs(x - theirs) / np.max(np.abs(theirs), axis=0)) <= 1e-10


def test_the_smoother_is_the_batch_least_squares_estimate():
    """Without driving noise, the smoothed state at every time is the batch minimum-variance
    estimate from the prior and all the measurements (a whitened least-squares solve in
    numpy, carried to each time by Φ), on irregular times with missing values: ≤ 1e-9."""
    rng = np.random.default_rng(11)
    t = 10.0 + np.cumsum(rng.uniform(0.2, 1.8, 80))
    z = 1.0 + 0.5 * (t - 10) + 0.02 * (t - 10) ** 2 + 0.3 * rng.standard_normal(t.size)
    z[rng.choice(t.size, 8, replace=False)] = np.nan
    x0, p0, r = np.array([0.0, 0.0, 0.0]), np.diag([100.0, 10.0, 1.0]), 0.09
    f = ss.KalmanFilter(degree=2, x0=x0, P0=p0, t0=10.0)
    states, covariances = f.smooth(t, z, r)
    assert f.time == 10.0  # the filter itself is unchanged

    def phi(dt):
        return np.array([[1.0, dt, dt * dt / 2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])

    ok = ~np.isnan(z)
    rows = [phi(dt)[0] / math.sqrt(r) for dt in t[ok] - 10.0]
    prior = np.linalg.cholesky(np.linalg.inv(p0)).T
    a = np.vstack([prior, np.array(rows)])
    b = np.concatenate([prior @ x0, z[ok] / math.sqrt(r)])
    x_hat = np.linalg.lstsq(a, b, rcond=None)[0]
    cov0 = np.linalg.inv(a.T @ a)
    for k, tk in enumerate(t):
        want = phi(tk - 10.0) @ x_hat
        scale = np.sqrt(np.diag(covariances[k]))
        assert np.max(np.abs(states[k] - want) / scale) <= 1e-9
        want_cov = phi(tk - 10.0) @ cov0 @ phi(tk - 10.0).T
        np.testing.assert_allclose(covariances[k], want_cov, rtol=1e-8, atol=1e-12)


@pytest.mark.parametrize(
    "call,kind",
    [
        (lambda: ss.KalmanFilter(degree=1, x0=[0.0], P0=1.0), ss.InvalidInputError),
        (
            lambda: ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=np.ones((3, 3))),
            ss.InvalidInputError,
        ),
        (
            lambda: ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=[[1.0, 2.0], [0.0, 1.0]]),
            ss.ParameterError,
        ),
        (lambda: ss.KalmanFilter(degree=1, x0=[0.0, np.nan], P0=1.0), ss.InvalidInputError),
        (lambda: ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, q=-1.0), ss.ParameterError),
        (
            lambda: ss.KalmanFilter(
                degree=1, x0=[0.0, 0.0], P0=1.0, theta=0.9, tau=1.0, theta_per_update=0.9
            ),
            ss.ParameterError,
        ),
        (
            lambda: ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, theta_per_update=1.5),
            ss.ParameterError,
        ),
        (lambda: ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, axes=0), ss.ParameterError),
        # The library's model range: a degree beyond MAX_DEGREE (2**63 overflowed (m + 1) axes
        # into a two-state model that panicked on its first prediction).
        (lambda: ss.KalmanFilter(degree=2**63, x0=[0.0, 0.0], P0=1.0, axes=2), ss.ParameterError),
        (
            lambda: ss.KalmanFilter(degree=ss.MAX_DEGREE + 1, x0=[0.0] * 26, P0=1.0),
            ss.ParameterError,
        ),
        (lambda: ss.BayesFilter(degree=2**63, axes=2), ss.ParameterError),
    ],
)
def test_bad_settings(call, kind):
    with pytest.raises(kind):
        call()


def test_bad_measurements_name_their_index():
    f = ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=10.0)
    with pytest.raises(ss.SeqsmoothError) as e:
        f.update_many([1.0, 2.0, np.nan, 4.0], [1.0, 2.0, 3.0, 4.0], 1.0)
    assert e.value.index == 2
    assert f.time == 2.0  # the measurements before it are taken
    with pytest.raises(ss.SeqsmoothError) as e:
        f.update_many([3.0, 2.5], [1.0, 2.0], 1.0)
    assert e.value.index == 1
    with pytest.raises(ss.InvalidInputError):
        f.update_many([5.0, 6.0], [[1.0, 2.0], [3.0, 4.0]], 1.0)  # two components for one
    with pytest.raises(ss.InvalidInputError):
        f.update(7.0, [1.0, 2.0], 1.0)
    with pytest.raises(ss.SeqsmoothError):
        f.update(8.0, 1.0, -1.0)  # a negative variance
    with pytest.raises(ss.InvalidTypeError):
        f.update_many(["a"], [1.0], 1.0)


def test_kalman_and_bayes_equal_the_librarys_run_to_the_last_bit():
    """The library's own run (tests/fixtures/kalman_rust.txt, written and checked by
    crates/seqsmooth/tests/kalman_python_fixture.rs): two axes, a 3 × 4 observation, driving
    noise, missing components, Unix-epoch times; the Bayes filter from nothing with fading."""
    from pathlib import Path

    path = Path(__file__).parent / "fixtures" / "kalman_rust.txt"
    rows: dict[str, list] = {"input": [], "kalman": [], "bayes": []}
    for text in path.read_text().splitlines():
        tag, *cells = text.split(",")
        rows[tag].append([np.nan] * 20 if cells == ["-"] else [float(c) for c in cells])
    inputs = np.array(rows["input"])
    t, z = inputs[:, 0], inputs[:, 1:]
    m = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [1.0, 1.0, 0, 0]])
    r = [1.0, 2.0, 0.5]
    kf = ss.KalmanFilter(
        degree=1,
        axes=2,
        observation=m,
        x0=[1.0, 0.0, 0.3, 0.1],
        P0=[4.0, 4.0, 1.0, 1.0],
        t0=1.7e9 - 1.0,
        q=0.05,
    )
    x, p, nis = kf.update_many(t, z, r)
    got = np.column_stack([x, p.reshape(len(t), 16), nis])

    def same_bits(a, b):
        finite = np.isfinite(b)
        return np.array_equal(np.isnan(a), np.isnan(b)) and np.array_equal(
            a[finite].view(np.int64), b[finite].view(np.int64)
        )

    assert same_bits(got, np.array(rows["kalman"]))
    x, p = ss.BayesFilter(1, axes=2, observation=m, theta_per_update=0.9).update_many(t, z, r)
    got = np.column_stack([x, p.reshape(len(t), 16)])
    want = np.array(rows["bayes"])
    assert np.array_equal(
        got.view(np.int64)[np.isfinite(got)], want.view(np.int64)[np.isfinite(want)]
    )
    assert np.array_equal(np.isnan(got), np.isnan(want))


def test_old_discount_names_are_refused_with_the_new_ones():
    """``theta`` alone meant per update in the Kalman filters and per ``tau`` in ``FadingMemory``:
    it now means per ``tau`` everywhere, so a call without ``tau`` is refused naming
    ``theta_per_update``; ``beta`` (per unit of time) is refused naming ``theta``, ``tau=1.0``."""
    with pytest.raises(ss.ParameterError, match="theta_per_update"):
        ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, theta=0.9)
    with pytest.raises(ss.ParameterError, match=r"theta=0.9, tau=1.0"):
        ss.KalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, beta=0.9)
    with pytest.raises(ss.ParameterError, match="theta_per_update"):
        ss.BayesFilter(1, theta=0.9)
    with pytest.raises(ss.ParameterError, match="theta_per_update"):
        ss.RadarTracker("fading", sigma_range=10.0, sigma_angle=1e-3, theta=0.9)
    # FadingMemory's theta keeps its meaning (per tau, default 1): the same bits as before.
    t = np.cumsum(np.random.default_rng(5).uniform(0.2, 0.8, 50))
    a = ss.FadingMemory(2, 0.9).update_many(t, np.sin(t))
    b = ss.FadingMemory(2, theta=0.9, tau=1.0).update_many(t, np.sin(t))
    assert np.array_equal(a, b, equal_nan=True)
    for bad in [{}, {"theta": 0.9, "theta_per_update": 0.9}, {"tau": 2.0, "theta_per_update": 0.9}]:
        with pytest.raises(ss.ParameterError):
            ss.FadingMemory(2, **bad)


@pytest.mark.parametrize(
    "discount",
    [{"theta": 0.9, "tau": 0.5}, {"theta": 0.8, "tau": 2.0}, {"theta_per_update": 0.85}],
)
@pytest.mark.parametrize("degree", [0, 1, 2, 3])
def test_fading_kalman_equals_fading_memory_given_one_discount(degree, discount):
    """The same discount by the same names: the fading Kalman filter over the polynomial model
    and ``FadingMemory`` give the same estimates within 1e-10 relative (each component against
    its size plus its σ) on irregular times. The Kalman filter starts at the (m+1)-th sample
    from the interpolating polynomial with ``P0 = R⁻¹ diag(σ²/w) R⁻ᵀ`` (``R`` the Taylor rows,
    ``w`` the discount's weights, from its definition here), where ``FadingMemory``, started
    from nothing, holds the same fit."""
    rng = np.random.default_rng(31 + degree)
    m, sigma, n = degree, 0.3, 4 * degree + 80
    t = np.cumsum(rng.uniform(0.2, 0.8, n))
    y = 10.0 * np.sin(0.3 * t) + 2.0 * t + rng.uniform(-1.0, 1.0, n)
    poly = ss.FadingMemory(degree=m, engine="exact", sigma=sigma, **discount)
    d, s = poly.update_many(t, y, return_sigma=True)
    dt = t[: m + 1] - t[m]
    rows = np.array([[x**j / math.factorial(j) for j in range(m + 1)] for x in dt])
    if "tau" in discount:
        w = discount["theta"] ** ((t[m] - t[: m + 1]) / discount["tau"])
    else:
        w = discount["theta_per_update"] ** np.arange(m, -1, -1.0)
    r_inv = np.linalg.inv(rows)
    x0 = r_inv @ y[: m + 1]
    p0 = r_inv @ np.diag(sigma**2 / w) @ r_inv.T
    kf = ss.KalmanFilter(degree=m, x0=x0, P0=0.5 * (p0 + p0.T), t0=t[m], **discount)
    x, _, _ = kf.update_many(t[m + 1 :], y[m + 1 :], sigma**2)
    rel = np.abs(x - d[m + 1 :]) / (np.abs(d[m + 1 :]) + s[m + 1 :])
    assert rel.max() <= 1e-10, rel.max()


def test_an_indefinite_P0_is_refused_at_construction():
    """P0 symmetric with a positive diagonal but indefinite, or not finite, is refused by the
    library's rule at construction (as the covariance setter refuses it), for every class
    taking a P0."""
    indefinite = [[1.0, 2.0], [2.0, 1.0]]
    with pytest.raises(ss.ParameterError):
        ss.KalmanFilter(1, x0=[0.0, 0.0], P0=indefinite)
    with pytest.raises(ss.ParameterError):
        ss.UnscentedKalmanFilter(1, x0=[0.0, 0.0], P0=indefinite)
    with pytest.raises(ss.ParameterError):
        ss.ExtendedKalmanFilter([0.0, 0.0], indefinite, f=lambda x, t0, t1: x, h=lambda x, t: x[:1])
    with pytest.raises(ss.SeqsmoothError):
        ss.KalmanFilter(1, x0=[0.0, 0.0], P0=[[1.0, np.inf], [np.inf, 1.0]])
    ss.KalmanFilter(1, x0=[0.0, 0.0], P0=[[1.0, 1.0], [1.0, 1.0]])  # singular: a covariance


def test_smooth_returns_its_gains_and_predicted_covariances():
    """``smooth(..., return_gains=True)`` gives the backward pass's own gains and predicted
    covariances: ``K[k] Pp[k] = P[k] Φᵀ`` and ``Ps[k] = P[k] + K[k] (Ps[k+1] − Pp[k]) K[k]ᵀ``
    with the filter's own ``P[k]`` (``update_many``) and the model's ``Φ`` over each step; the
    last gain 0, the last ``Pp`` its own covariance; the first two outputs as without."""
    rng = np.random.default_rng(12)
    t = np.cumsum(rng.uniform(0.5, 1.5, 30))
    z = 2.0 + 0.3 * t + rng.normal(0, 0.5, 30)
    z[7] = np.nan

    def fresh():
        return ss.KalmanFilter(1, np.zeros(2), 100.0 * np.eye(2), t0=t[0], q=0.01)

    _, P, _ = fresh().update_many(t, z, 0.25)
    xs, Ps, K, Pp = fresh().smooth(t, z, 0.25, return_gains=True)
    plain = fresh().smooth(t, z, 0.25)
    assert np.array_equal(plain[0], xs) and np.array_equal(plain[1], Ps)
    for k in range(len(t) - 1):
        phi = np.array([[1.0, t[k + 1] - t[k]], [0.0, 1.0]])
        assert np.allclose(K[k] @ Pp[k], P[k] @ phi.T, rtol=1e-9, atol=1e-12), k
        again = P[k] + K[k] @ (Ps[k + 1] - Pp[k]) @ K[k].T
        assert np.allclose(Ps[k], again, rtol=1e-9, atol=1e-12), k
    assert not K[-1].any() and np.array_equal(Pp[-1], Ps[-1])
