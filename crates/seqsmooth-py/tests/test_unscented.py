"""UnscentedKalmanFilter: against filterpy's UnscentedKalmanFilter with MerweScaledSigmaPoints
and its unscented RTS smoother, live, within 1e-10 (a linear model with a negative central
weight, and a radar crossing azimuth pi with missing components); update against update_many;
the defaults; and its errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from filterpy.kalman import MerweScaledSigmaPoints
from filterpy.kalman import UnscentedKalmanFilter as FilterpyUKF

import seqsmooth as ss

TOL = 1e-10


def transition(m, d, dt):
    """Phi(dt) of the degree-m polynomial model on d axes (derivative, then axis)."""
    f = np.zeros(((m + 1) * d, (m + 1) * d))
    for i in range(m + 1):
        for j in range(i, m + 1):
            for a in range(d):
                f[i * d + a, j * d + a] = dt ** (j - i) / math.factorial(j - i)
    return f


def process_noise(m, d, q, dt):
    """Q(dt) of white noise of density q on the highest derivative (Morrison (15.2.23))."""
    out = np.zeros(((m + 1) * d, (m + 1) * d))
    for i in range(m + 1):
        for j in range(m + 1):
            p = 2 * m + 1 - i - j
            v = q * abs(dt) ** p / (math.factorial(m - i) * math.factorial(m - j) * p)
            for a in range(d):
                out[i * d + a, j * d + a] = v
    return out


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def radar_of(site):
    def h(x):
        dx, dy, dz = x[0] - site[0], x[1] - site[1], x[2] - site[2]
        return np.array(
            [
                math.sqrt(dx * dx + dy * dy + dz * dz),
                math.atan2(dy, dx),
                math.atan2(dz, math.hypot(dx, dy)),
            ]
        )

    return h


def filterpy_run(m, d, q, t0, x0, p0, R, h, angles, points, t, z):
    """filterpy's filter over (t, z) (NaN: missing) and its smoother one backward step at a
    time, each with its own Q (its rts_smoother uses self.Q for every step): the filtered x, P,
    NIS and the smoothed x, P."""
    n, k = (m + 1) * d, R.shape[0]
    present = []

    def residual_z(a, b):
        y = np.subtract(a, b)
        for c, comp in enumerate(present):
            if comp in angles:
                y[c] = wrap(y[c])
        return y

    def z_mean(sigmas, wm):
        return sigmas[0] + sum(w * residual_z(row, sigmas[0]) for w, row in zip(wm[1:], sigmas[1:]))

    ukf = FilterpyUKF(
        dim_x=n,
        dim_z=k,
        dt=1.0,
        hx=h,
        fx=lambda x, dt: transition(m, d, dt) @ x,
        points=points,
        residual_z=residual_z,
        z_mean_fn=z_mean,
    )
    ukf.x, ukf.P = np.array(x0, dtype=float), np.array(p0, dtype=float)
    xs, ps, nis, previous = [], [], [], t0
    for tk, zk in zip(t, z):
        ukf.Q = process_noise(m, d, q, tk - previous)
        ukf.predict(dt=tk - previous)
        previous = tk
        present[:] = [c for c in range(k) if not np.isnan(zk[c])]
        if present:
            idx = list(present)
            ukf.update(zk[idx], R=R[np.ix_(idx, idx)], hx=lambda x, idx=idx: h(x)[idx])
            nis.append(float(ukf.y @ np.linalg.inv(ukf.S) @ ukf.y))
        else:
            nis.append(float("nan"))
        xs.append(ukf.x.copy())
        ps.append(ukf.P.copy())
    sx, sp = list(xs), list(ps)
    for s in reversed(range(len(t) - 1)):
        dt = t[s + 1] - t[s]
        ukf.Q = process_noise(m, d, q, dt)
        out_x, out_p, _ = ukf.rts_smoother(
            np.array([xs[s], sx[s + 1]]), np.array([ps[s], sp[s + 1]]), dts=[dt, dt]
        )
        sx[s], sp[s] = out_x[0], out_p[0]
    return np.array(xs), np.array(ps), np.array(nis), np.array(sx), np.array(sp)


def worst(x, p, want_x, want_p):
    """States relative to max(|x_i|, σ_i), covariances to σ_i σ_j (filterpy's x and σ)."""
    sigma = np.sqrt(np.einsum("kii->ki", want_p))
    return (
        np.max(np.abs(x - want_x) / np.maximum(np.abs(want_x), sigma)),
        np.max(np.abs(p - want_p) / (sigma[:, :, None] * sigma[:, None, :])),
    )


def linear_problem(seed=7, steps=120):
    rng = np.random.default_rng(seed)
    t = 2.0 + np.cumsum(rng.uniform(0.3, 1.7, steps))
    truth_x = 10.0 - 0.8 * (t - 2.0)
    truth_y = -4.0 + 1.5 * (t - 2.0)
    z = np.column_stack([truth_x, truth_y]) + rng.normal(0.0, 0.7, (steps, 2))
    z[rng.random((steps, 2)) < 0.1] = np.nan
    z[[0, steps // 2, steps // 2 + 1]] = np.nan
    return t, z


def test_linear_model_equals_filterpy():
    t, z = linear_problem()
    x0 = [10.0, -4.0, 0.0, 0.0]
    p0 = np.kron(np.array([[9.0, 1.0], [1.0, 4.0]]), np.eye(2))
    R = np.array([[0.5, 0.2], [0.2, 0.8]])
    f = ss.UnscentedKalmanFilter(
        degree=1, axes=2, q=0.2, t0=2.0, x0=x0, P0=p0, sigma_points=(0.5, 2.0, 1.0)
    )
    points = MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=1.0)
    want = filterpy_run(1, 2, 0.2, 2.0, x0, p0, R, lambda x: x[:2], [], points, t, z)
    sx, sp = f.smooth(t, z, R)
    x, p, nis = f.update_many(t, z, R)
    assert max(worst(x, p, want[0], want[1])) <= TOL
    assert max(worst(sx, sp, want[3], want[4])) <= TOL
    assert np.array_equal(np.isnan(nis), np.isnan(want[2]))
    ok = ~np.isnan(nis)
    assert np.max(np.abs(nis[ok] - want[2][ok]) / np.maximum(want[2][ok], 1.0)) <= TOL


def test_radar_through_azimuth_pi_equals_filterpy():
    rng = np.random.default_rng(11)
    site = (300.0, -200.0, 10.0)
    h = radar_of(site)
    steps = 120
    t = 100.0 + np.cumsum(rng.uniform(0.3, 1.7, steps))
    start = np.array([-7700.0, 2300.0, 2010.0, 30.0, -40.0, 2.0])
    truth = [start[:3] + start[3:] * (tk - 100.0) for tk in t]
    sd = np.array([5.0, 2e-3, 2e-3])
    z = np.array([h(p) for p in truth]) + rng.normal(0.0, 1.0, (steps, 3)) * sd
    z[:, 1] = [wrap(a) for a in z[:, 1]]
    z[rng.random((steps, 3)) < 0.1] = np.nan
    z[[0, 60]] = np.nan
    assert (z[:, 1] > 3.0).any() and (z[:, 1] < -3.0).any()  # it crosses azimuth pi
    x0 = start
    p0 = np.kron(np.array([[400.0, 20.0], [20.0, 25.0]]), np.eye(3))
    R = np.diag(sd**2)
    f = ss.UnscentedKalmanFilter(
        degree=1, axes=3, q=2.0, t0=100.0, x0=x0, P0=p0, observation="radar", site=site
    )
    points = MerweScaledSigmaPoints(6, alpha=1.0, beta=2.0, kappa=0.0)
    want = filterpy_run(1, 3, 2.0, 100.0, x0, p0, R, h, [1], points, t, z)
    sx, sp = f.smooth(t, z, R)
    x, p, nis = f.update_many(t, z, R)
    assert max(worst(x, p, want[0], want[1])) <= TOL
    assert max(worst(sx, sp, want[3], want[4])) <= TOL
    ok = ~np.isnan(nis)
    assert np.max(np.abs(nis[ok] - want[2][ok]) / np.maximum(want[2][ok], 1.0)) <= TOL


def test_update_equals_update_many_bit_for_bit():
    t, z = linear_problem(seed=3, steps=40)
    R = [0.5, 0.8]

    def make():
        return ss.UnscentedKalmanFilter(
            degree=1, axes=2, q=0.2, t0=2.0, x0=[10, -4, 0, 0], P0=[9, 9, 4, 4]
        )

    a, b = make(), make()
    x, p, nis = a.update_many(t, z, R)
    for k in range(len(t)):
        i = b.update(t[k], z[k], R)
        assert (i is None) == np.isnan(nis[k])
        if i is not None:
            assert i.nis == nis[k] and len(i.components) == int((~np.isnan(z[k])).sum())
        assert np.array_equal(b.state, x[k]) and np.array_equal(b.covariance, p[k])
        assert np.array_equal(b.std_devs, np.sqrt(np.diag(p[k])))
    assert b.time == t[-1] == a.time


def test_defaults_and_repr():
    f = ss.UnscentedKalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0)
    assert f.sigma_points == (1.0, 2.0, 0.0)
    assert "UnscentedKalmanFilter(states=2" in repr(f)
    f.predict(2.0)
    assert f.time == 2.0 and np.allclose(f.covariance, [[5.0, 2.0], [2.0, 1.0]], rtol=1e-14, atol=0)


@pytest.mark.parametrize(
    "call,kind,word",
    [
        (
            lambda: ss.UnscentedKalmanFilter(
                degree=1, x0=[0.0, 0.0], P0=1.0, sigma_points=(0.0, 2.0, 0.0)
            ),
            ss.ParameterError,
            "alpha",
        ),
        (
            lambda: ss.UnscentedKalmanFilter(
                degree=1, x0=[0.0, 0.0], P0=1.0, sigma_points=(1.0, math.inf, 0.0)
            ),
            ss.ParameterError,
            "beta",
        ),
        (
            lambda: ss.UnscentedKalmanFilter(
                degree=1, x0=[0.0, 0.0], P0=1.0, sigma_points=(1.0, 2.0, -2.0)
            ),
            ss.ParameterError,
            "kappa",
        ),
        (
            lambda: ss.UnscentedKalmanFilter(degree=1, x0=[0.0, 0.0], P0=[[1.0, 2.0], [2.0, 1.0]]),
            ss.ParameterError,
            "positive (semi)?definite",
        ),
        (lambda: ss.UnscentedKalmanFilter(degree=1, x0=[0.0], P0=1.0), ss.InvalidInputError, "x0"),
        (
            lambda: ss.UnscentedKalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, observation="sonar"),
            ss.ParameterError,
            "radar",
        ),
        (
            lambda: ss.UnscentedKalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, site=(0.0, 0.0, 0.0)),
            ss.ParameterError,
            "site",
        ),
        (
            lambda: ss.UnscentedKalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, observation="radar"),
            ss.ParameterError,
            "position",
        ),
        # On one axis the radar would read (x, x', x'') as (x, y, z): refused, not built.
        (
            lambda: ss.UnscentedKalmanFilter(
                degree=2, x0=[10.0, 1.0, 0.0], P0=1.0, observation="radar"
            ),
            ss.ParameterError,
            "axes 1 is invalid: a radar observes the position",
        ),
        (
            lambda: ss.UnscentedKalmanFilter(degree=2**63, x0=[0.0, 0.0], P0=1.0, axes=2),
            ss.ParameterError,
            "degree",
        ),
        # One tuple of sigma-point settings: beta (once a fading discount) is no keyword.
        (
            lambda: ss.UnscentedKalmanFilter(degree=1, x0=[0.0, 0.0], P0=1.0, beta=0.9),
            TypeError,
            "beta",
        ),
    ],
)
def test_bad_settings(call, kind, word):
    with pytest.raises(kind, match=word):
        call()


def test_bad_measurements_name_their_index_and_leave_the_filter():
    f = ss.UnscentedKalmanFilter(degree=0, x0=[0.0], P0=1.0)
    # A perfect measurement (R = 0) would leave P = 0, a covariance without sigma points: the
    # update that makes it is refused (the first), the filter left as it was.
    with pytest.raises(ss.SeqsmoothError, match="positive definite") as e:
        f.update_many([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], 0.0)
    assert e.value.index == 0
    assert f.time == 0.0 and f.covariance[0, 0] == 1.0
    g = ss.UnscentedKalmanFilter(degree=0, x0=[0.0], P0=1.0)
    g.update(1.0, 1.0, 1.0)
    before = (g.state.copy(), g.covariance.copy(), g.time)
    with pytest.raises(ss.InvalidInputError):
        g.update(2.0, [1.0, 2.0], 1.0)  # two values for one component
    with pytest.raises(ss.SeqsmoothError):
        g.update(2.0, math.inf, 1.0)
    with pytest.raises(ss.SeqsmoothError):
        g.update(2.0, 1.0, -1.0)  # a negative variance
    with pytest.raises(ss.InvalidInputError):
        g.update(0.5, 1.0, 1.0)  # before the filter's time
    assert np.array_equal(g.state, before[0]) and np.array_equal(g.covariance, before[1])
    assert g.time == before[2]
    with pytest.raises(ss.SeqsmoothError) as e:
        g.update_many([2.0, 3.0, 2.5], [1.0, 1.0, 1.0], 1.0)
    assert e.value.index == 2 and g.time == 3.0  # the ones before it taken
