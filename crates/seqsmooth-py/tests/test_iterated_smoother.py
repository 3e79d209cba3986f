"""The iterated extended Kalman filter's Rauch–Tung–Striebel smoother
(ExtendedKalmanFilter(iterations > 1).smooth, the library's Smoother with the iterated forward
update, Morrison §12.5): on a linear model (where iterated = plain) against a dense batch solve
of every state at once; on range and bearing its forward pass is the iterated filter's."""

import math

import numpy as np

import seqsmooth as ss


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def F(dt):
    return np.array([[1.0, dt, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1]])


def Q(dt, q=0.3):
    one = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    out = np.zeros((4, 4))
    out[np.ix_([0, 1], [0, 1])] = one
    out[np.ix_([2, 3], [2, 3])] = one
    return out


def dense_smoother(x0, P0, t0, t, z, H, R):
    """Every state (the prior's and each measurement's) from one dense solve of the normal
    equations of the prior, the driving noise between steps and the measurements; the
    covariances the diagonal blocks of the inverse information matrix."""
    n, N = len(x0), len(t)
    J = np.zeros(((N + 1) * n, (N + 1) * n))
    b = np.zeros((N + 1) * n)
    blk = lambda k: slice(k * n, (k + 1) * n)  # noqa: E731
    J[blk(0), blk(0)] += np.linalg.inv(P0)
    b[blk(0)] += np.linalg.solve(P0, x0)
    times = np.concatenate([[t0], t])
    Ri = np.linalg.inv(R)
    for k in range(1, N + 1):
        dt = times[k] - times[k - 1]
        Qi = np.linalg.inv(Q(dt))
        G = np.hstack([-F(dt), np.eye(n)])
        rows = np.r_[blk(k - 1), blk(k)]
        J[np.ix_(rows, rows)] += G.T @ Qi @ G
        J[blk(k), blk(k)] += H.T @ Ri @ H
        b[blk(k)] += H.T @ Ri @ z[k - 1]
    cov = np.linalg.inv(J)
    x = cov @ b
    return (
        np.array([x[blk(k)] for k in range(1, N + 1)]),
        np.array([cov[blk(k), blk(k)] for k in range(1, N + 1)]),
    )


def test_iterated_smoother_on_a_linear_model_equals_the_dense_batch_solve():
    """Linear f and h (iterated = plain): the smoothed states and covariances of
    ExtendedKalmanFilter(iterations=4).smooth equal the dense solve within 1e-9."""
    rng = np.random.default_rng(12)
    t = np.cumsum(rng.uniform(0.2, 2.0, size=30))
    H = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
    R = np.diag([4.0, 9.0])
    z = np.column_stack([2.0 * t, 50 - t]) + rng.normal(0, 2.5, size=(30, 2))
    x0, P0 = np.array([0.0, 1.0, 50.0, 0.0]), np.diag([100.0, 10.0, 100.0, 10.0])
    ekf = ss.ExtendedKalmanFilter(
        x0,
        P0,
        f=lambda x, a, b: F(b - a) @ x,
        h=lambda x, t: H @ x,
        Q=lambda a, b: Q(b - a),
        iterations=4,
    )
    xs, Ps = ekf.smooth(t, z, R)
    want_x, want_P = dense_smoother(x0, P0, 0.0, t, z, H, R)
    assert rel(xs, want_x) < 1e-9, rel(xs, want_x)
    assert rel(Ps, want_P) < 1e-9, rel(Ps, want_P)


def test_iterated_smoothers_forward_pass_is_the_iterated_filter():
    """Range and bearing from a vague prior (where iterating matters): the smoothed estimate
    at the last measurement is the iterated filter's own (update_many with the same
    iterations) to 1e-12, and not the plain filter's."""
    rng = np.random.default_rng(13)
    t = np.cumsum(rng.uniform(0.5, 1.5, size=20))
    truth = np.array([300.0, -4.0, 40.0, 2.0])
    pos = np.array([F(tk) @ truth for tk in t])[:, [0, 2]]
    z = np.column_stack([np.hypot(pos[:, 0], pos[:, 1]), np.arctan2(pos[:, 1], pos[:, 0])])
    z += rng.normal(0, 1, size=z.shape) * [2.0, 0.01]
    R = np.diag([4.0, 1e-4])

    def h(x, t):
        return np.array([math.hypot(x[0], x[2]), math.atan2(x[2], x[0])])

    def make(iterations):
        return ss.ExtendedKalmanFilter(
            [250.0, 0.0, 80.0, 0.0],
            np.diag([400.0, 25.0, 400.0, 25.0]),
            f=lambda x, a, b: F(b - a) @ x,
            h=h,
            Q=lambda a, b: Q(b - a, 0.01),
            angles=[1],
            iterations=iterations,
        )

    iterated = make(20).update_many(t, z, R)
    plain = make(1).update_many(t, z, R)
    xs, Ps = make(20).smooth(t, z, R)
    assert rel(xs[-1], iterated[0][-1]) < 1e-12 and rel(Ps[-1], iterated[1][-1]) < 1e-12
    assert rel(xs[-1], plain[0][-1]) > 1e-9
