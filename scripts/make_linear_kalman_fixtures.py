#!/usr/bin/env python3
"""Writes the filterpy fixtures that seqsmooth's LinearKalmanFilter (Python,
`seqsmooth.LinearKalmanFilter`; the library's `kalman::discrete`) is checked against:
crates/seqsmooth-py/tests/fixtures/filterpy_linear.json, read by
crates/seqsmooth-py/tests/test_linear_kalman.py.

Run:  python3 scripts/make_linear_kalman_fixtures.py
It uses the pinned virtual environment of scripts/peers_venv.py (target/peers-venv: filterpy
2.0.0, numpy, scipy at its PINS), re-runs itself there, and writes four problems (seed SEED):
  cv_qdwn      - constant velocity on two axes (x, x', y, y'), dt = 0.5, Q from filterpy's
                 Q_discrete_white_noise per axis, both positions observed with a full R, some
                 measurements missing (None);
  control_diag - three states, a diagonal Q, a scalar observation (R a number), a control input
                 B u with one u per step;
  per_step     - three states, a full Q; F, Q, H and R given per step (time-varying);
  fixed_lag    - cv_qdwn's model and data through filterpy's FixedLagSmoother (N = LAG), and the
                 exact fixed-lag estimates from filterpy's own KalmanFilter: batch_filter and
                 rts_smoother over the measurements 0..k+LAG, read at k.
Each holds the inputs (x0, P0, F/Fs, H/Hs, Q/Qs, R/Rs, B, us, zs with null for missing) and
filterpy's batch_filter outputs (means, covariances, means_p, covariances_p) and rts_smoother
outputs (x, P, K, Pp; with Fs and Qs, and without B u: filterpy's smoother predicts F x alone).

filterpy 2.0.0's KalmanFilter.update uses Joseph's form P = (I - K H) P (I - K H)' + K R K' with
K = P H' inv(S), S = H P H' + R (an explicit inverse); its FixedLagSmoother.smooth is Simon's
augmented-state recursion as coded there (it starts each smoothed gain from the updated P).

Numbers are written by json (repr: round-trip exact doubles).
"""

import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peers_venv  # noqa: E402

OUT = os.path.join(ROOT, "crates", "seqsmooth-py", "tests", "fixtures", "filterpy_linear.json")
SEED = 20261206
LAG = 5
peers_venv.enter(__file__)

import filterpy  # noqa: E402
import numpy as np  # noqa: E402
from filterpy.common import Q_discrete_white_noise  # noqa: E402
from filterpy.kalman import FixedLagSmoother, KalmanFilter  # noqa: E402
from scipy.linalg import block_diag  # noqa: E402


def lst(a):
    if a is None:
        return None
    if isinstance(a, list):
        return [lst(v) for v in a]
    return np.asarray(a, dtype=float).tolist()


def run(x0, P0, F, H, Q, R, zs, B=None, Fs=None, Qs=None, Hs=None, Rs=None, Bs=None, us=None):
    n, p = len(x0), np.atleast_2d(H).shape[0]
    kf = KalmanFilter(dim_x=n, dim_z=p, dim_u=0 if B is None else B.shape[1])
    kf.x, kf.P, kf.F, kf.H, kf.Q, kf.R = x0.copy(), P0.copy(), F, H, Q, R
    if B is not None:
        kf.B = B
    means, covs, means_p, covs_p = kf.batch_filter(zs, Fs=Fs, Qs=Qs, Hs=Hs, Rs=Rs, Bs=Bs, us=us)
    x, P, K, Pp = kf.rts_smoother(means, covs, Fs=Fs, Qs=Qs)
    return {
        "means": lst(means),
        "covariances": lst(covs),
        "means_p": lst(means_p),
        "covariances_p": lst(covs_p),
        "rts_x": lst(x),
        "rts_P": lst(P),
        "rts_K": lst(K),
        "rts_Pp": lst(Pp),
    }


def truth_cv(rng, steps, dt):
    x = np.array([0.0, 1.0, 5.0, -0.5])
    out = []
    for _ in range(steps):
        x = np.array(
            [
                x[0] + dt * x[1],
                x[1] + rng.normal(0, 0.1),
                x[2] + dt * x[3],
                x[3] + rng.normal(0, 0.1),
            ]
        )
        out.append(x.copy())
    return out


def main():
    rng = np.random.default_rng(SEED)
    problems = {}

    # cv_qdwn
    dt, steps = 0.5, 80
    F = np.array([[1, dt, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1]], float)
    q1 = Q_discrete_white_noise(dim=2, dt=dt, var=0.1)
    Q = block_diag(q1, q1)
    H = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
    R = np.array([[0.5, 0.1], [0.1, 0.3]])
    x0, P0 = np.array([0.0, 0.0, 0.0, 0.0]), np.eye(4) * 10.0
    zs = []
    for k, x in enumerate(truth_cv(rng, steps, dt)):
        z = H @ x + rng.multivariate_normal([0, 0], R)
        zs.append(None if k % 9 == 4 else z)
    cv = {
        "x0": lst(x0),
        "P0": lst(P0),
        "F": lst(F),
        "H": lst(H),
        "Q": lst(Q),
        "R": lst(R),
        "zs": [lst(z) for z in zs],
    }
    cv.update(run(x0, P0, F, H, Q, R, zs))
    problems["cv_qdwn"] = cv

    # control_diag
    steps = 60
    F3 = np.array([[1.0, 0.2, 0.0], [0.0, 0.95, 0.1], [0.0, 0.0, 0.9]])
    Q3 = np.diag([0.01, 0.02, 0.05])
    H3 = np.array([[1.0, 0.0, 0.5]])
    R3 = 0.4
    B3 = np.array([[0.0], [0.1], [1.0]])
    us = [np.array([np.sin(0.3 * k)]) for k in range(steps)]
    x0, P0 = np.array([1.0, 0.0, 0.0]), np.diag([1.0, 2.0, 3.0])
    zs3 = [np.array([np.cos(0.2 * k) + rng.normal(0, 0.6)]) for k in range(steps)]
    c = {
        "x0": lst(x0),
        "P0": lst(P0),
        "F": lst(F3),
        "H": lst(H3),
        "Q": lst(Q3),
        "R": R3,
        "B": lst(B3),
        "us": lst(us),
        "zs": lst(zs3),
    }
    c.update(run(x0, P0, F3, H3, Q3, np.array([[R3]]), zs3, B=B3, Bs=[B3] * steps, us=us))
    problems["control_diag"] = c

    # per_step
    steps = 50
    A = rng.normal(size=(3, 3))
    Qfull = A @ A.T * 0.05
    Fs = [
        np.array([[1.0, 0.1 + 0.01 * k, 0.0], [0.0, 1.0, 0.05], [0.02 * np.sin(k), 0.0, 0.98]])
        for k in range(steps)
    ]
    Qs = [Qfull * (1.0 + 0.5 * np.sin(0.4 * k)) for k in range(steps)]
    Hs = [np.array([[1.0, 0.0, 0.1 * (k % 3)], [0.0, 1.0, 0.5]]) for k in range(steps)]
    Rs = []
    for _ in range(steps):
        a = rng.normal(size=(2, 2))
        Rs.append(a @ a.T * 0.1 + np.eye(2) * 0.2)
    x0, P0 = np.array([0.5, -0.5, 0.0]), np.eye(3) * 4.0
    zs4 = [
        np.array([np.sin(0.1 * k), 0.3 * np.cos(0.2 * k)]) + rng.normal(0, 0.3, 2)
        for k in range(steps)
    ]
    ps = {
        "x0": lst(x0),
        "P0": lst(P0),
        "F": lst(Fs[0]),
        "H": lst(Hs[0]),
        "Q": lst(Qfull),
        "R": lst(Rs[0]),
        "Fs": lst(Fs),
        "Qs": lst(Qs),
        "Hs": lst(Hs),
        "Rs": lst(Rs),
        "zs": lst(zs4),
    }
    ps.update(run(x0, P0, Fs[0], Hs[0], Qfull, Rs[0], zs4, Fs=Fs, Qs=Qs, Hs=Hs, Rs=Rs))
    problems["per_step"] = ps

    # fixed_lag: cv's model on complete data (filterpy's smoother takes no missing z).
    zs5 = [np.asarray(z) if z is not None else H @ truth_cv(rng, 1, dt)[0] for z in zs][:60]
    fls = FixedLagSmoother(dim_x=4, dim_z=2, N=LAG)
    fls.x, fls.P, fls.F, fls.H, fls.Q, fls.R = np.zeros(4), np.eye(4) * 10.0, F, H, Q, R
    smoothed, filtered = fls.smooth_batch(np.array(zs5), N=LAG)
    exact = []
    for k in range(len(zs5)):
        end = min(k + LAG + 1, len(zs5))
        r = run(np.zeros(4), np.eye(4) * 10.0, F, H, Q, R, zs5[:end])
        exact.append((r["rts_x"][k], r["rts_P"][k]))
    problems["fixed_lag"] = {
        "x0": lst(np.zeros(4)),
        "P0": lst(np.eye(4) * 10.0),
        "F": lst(F),
        "H": lst(H),
        "Q": lst(Q),
        "R": lst(R),
        "zs": lst(zs5),
        "lag": LAG,
        "filterpy_fls_x": lst(smoothed),
        "filterpy_fls_filtered": lst(filtered),
        "exact_x": [e[0] for e in exact],
        "exact_P": [e[1] for e in exact],
    }

    meta = {
        "made_by": "scripts/make_linear_kalman_fixtures.py",
        "filterpy": filterpy.__version__,
        "numpy": np.__version__,
        "seed": SEED,
    }
    with open(OUT, "w") as f:
        json.dump({"meta": meta, "problems": problems}, f, indent=None)
        f.write("\n")
    print("wrote", OUT)


main()
