#!/usr/bin/env python3
"""The Joseph-form update of seqsmooth's LinearKalmanFilter (gain by an L D Lᵀ factorisation of
H P Hᵀ + R) and of filterpy 2.0.0's KalmanFilter (the same form, the gain by an explicit
inverse) against the exact filter in rational arithmetic (fractions.Fraction), on priors from
well to badly conditioned (ACCURACY.md, "Linear Kalman filter: Joseph's form against filterpy's").

Run:  target/py-venv/bin/python scripts/linear_kalman_conditioning.py
(the package and filterpy 2.0.0 installed in target/py-venv, as for the tests). Constant
acceleration, unit steps, the position observed, 25 steps; prints each filter's largest error,
relative to each step's largest exact entry, or seqsmooth's refusal.
"""

from fractions import Fraction as Fr

import numpy as np
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import KalmanFilter

import seqsmooth as ss

rng = np.random.default_rng(5)
F = np.array([[1, 1, 0.5], [0, 1, 1], [0, 0, 1.0]])
H = np.array([[1.0, 0, 0]])


def exact(p0, r, Q, zs):
    Fq = [[Fr(v) for v in row] for row in F]
    Qq = [[Fr(v) for v in row] for row in Q]
    x = [Fr(0)] * 3
    P = [[Fr(p0) if i == j else Fr(0) for j in range(3)] for i in range(3)]

    def mm(A, B):
        return [
            [sum(A[i][k] * B[k][j] for k in range(len(B))) for j in range(len(B[0]))]
            for i in range(len(A))
        ]

    def T(A):
        return [list(c) for c in zip(*A)]

    out = []
    for z in zs:
        x = [sum(Fq[i][k] * x[k] for k in range(3)) for i in range(3)]
        P = [[a + b for a, b in zip(r1, r2)] for r1, r2 in zip(mm(mm(Fq, P), T(Fq)), Qq)]
        S = P[0][0] + Fr(r)
        K = [P[i][0] / S for i in range(3)]
        y = Fr(float(z)) - x[0]
        x = [x[i] + K[i] * y for i in range(3)]
        P = [[P[i][j] - K[i] * P[0][j] for j in range(3)] for i in range(3)]
        out.append(([float(v) for v in x], [[float(v) for v in row] for row in P]))
    return out


for p0, r, q in [(1e2, 1.0, 1e-2), (1e8, 1.0, 1e-2), (1e12, 1e-2, 1e-6), (1e14, 1e-4, 1e-8)]:
    Q = Q_discrete_white_noise(3, 1.0, q)
    zs = np.cumsum(rng.normal(size=25))[:, None]
    ex = exact(p0, r, Q, zs[:, 0])
    kf = KalmanFilter(3, 1)
    kf.x = np.zeros(3)
    kf.P = np.eye(3) * p0
    kf.F = F
    kf.H = H
    kf.Q = Q
    kf.R = np.array([[r]])
    m, c, _, _ = kf.batch_filter(zs)
    try:
        lm, lc, _, _ = ss.LinearKalmanFilter(np.zeros(3), np.eye(3) * p0, F, H, Q, r).update_many(
            zs
        )
    except Exception as e:
        lm = None
        print("  seqsmooth:", str(e)[:90])
    ex_x = np.array([e[0] for e in ex])
    ex_P = np.array([e[1] for e in ex])

    def err(a, b):
        return max(np.max(np.abs(a[k] - b[k])) / np.max(np.abs(b[k])) for k in range(len(b)))

    print(
        f"P0={p0:g} R={r:g}: filterpy vs exact: x {err(m, ex_x):.1e} P {err(c, ex_P):.1e}", end=""
    )
    if lm is not None:
        print(f"; seqsmooth vs exact: x {err(lm, ex_x):.1e} P {err(lc, ex_P):.1e}")
    else:
        print()
