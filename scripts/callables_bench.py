#!/usr/bin/env python3
"""The extended and unscented Kalman filters over the user's own Python callables, seqsmooth
against filterpy 2.0.0, the same callables, same data, same run: a constant-velocity target on
two axes (4 states) seen in range and bearing (2 components), driving noise, 2,000 steps of 1.

- EKF: filterpy's ExtendedKalmanFilter, predict() + update(z, HJacobian, Hx) (its F and Q as
  matrices: it takes no f); seqsmooth.ExtendedKalmanFilter(f, h, F_jacobian, H_jacobian, Q),
  through update_many and through update one call a step.
- UKF: filterpy's UnscentedKalmanFilter with MerweScaledSigmaPoints(4, 1, 2, 0), predict() +
  update(z), fx(x, dt) and hx(x); seqsmooth.UnscentedKalmanFilter(f=, h=, Q=) with the same
  fx and hx, through update_many and update.

Best of REPEATS; microseconds per step.

Run in the Python test environment (filterpy installed):
  target/py-venv/bin/python scripts/callables_bench.py
"""

import math
import time

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter, MerweScaledSigmaPoints, UnscentedKalmanFilter

import seqsmooth as ss

STEPS, REPEATS = 2000, 5
F = np.array([[1, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1], [0, 0, 0, 1]], dtype=float)
Q = np.kron(np.eye(2), np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]]) * 0.05)
R = np.diag([4.0, 1e-4])
X0 = np.array([300.0, -4.0, 40.0, 2.0])
P0 = np.diag([100.0, 4.0, 100.0, 4.0])


def hx(x):
    return np.array([math.hypot(x[0], x[2]), math.atan2(x[2], x[0])])


def hj(x):
    r2 = x[0] * x[0] + x[2] * x[2]
    r = math.sqrt(r2)
    return np.array([[x[0] / r, 0, x[2] / r, 0], [-x[2] / r2, 0, x[0] / r2, 0]])


def fx(x, dt):
    return F @ x if dt == 1.0 else np.array([x[0] + dt * x[1], x[1], x[2] + dt * x[3], x[3]])


def data():
    rng = np.random.default_rng(1)
    x, zs = X0.copy(), []
    for _ in range(STEPS):
        x = F @ x
        zs.append(hx(x) + rng.normal(0, np.sqrt(np.diag(R))))
    return np.arange(1.0, STEPS + 1), np.array(zs)


def best(run):
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times) / STEPS * 1e6


def main():
    ts, zs = data()

    def filterpy_ekf():
        f = ExtendedKalmanFilter(4, 2)
        f.x, f.P, f.F, f.Q, f.R = X0.reshape(4, 1).copy(), P0.copy(), F, Q, R

        def h_col(x):
            return hx(np.ravel(x)).reshape(2, 1)

        def j_col(x):
            return hj(np.ravel(x))

        for z in zs:
            f.predict()
            f.update(z.reshape(2, 1), j_col, h_col)

    def ekf():
        return ss.ExtendedKalmanFilter(
            X0,
            P0,
            lambda x, a, b: fx(x, b - a),
            lambda x, t: hx(x),
            Q=Q,
            F_jacobian=lambda x, a, b: F,
            H_jacobian=lambda x, t: hj(x),
        )

    def ekf_many():
        ekf().update_many(ts, zs, R)

    def ekf_each():
        f = ekf()
        for t, z in zip(ts, zs):
            f.update(t, z, R)

    def filterpy_ukf():
        points = MerweScaledSigmaPoints(4, alpha=1.0, beta=2.0, kappa=0.0)
        f = UnscentedKalmanFilter(4, 2, 1.0, hx, fx, points)
        f.x, f.P, f.Q, f.R = X0.copy(), P0.copy(), Q, R
        for z in zs:
            f.predict()
            f.update(z)

    def ukf():
        return ss.UnscentedKalmanFilter(
            x0=X0, P0=P0, f=lambda x, a, b: fx(x, b - a), h=lambda x, t: hx(x), Q=Q
        )

    def ukf_many():
        ukf().update_many(ts, zs, R)

    def ukf_each():
        f = ukf()
        for t, z in zip(ts, zs):
            f.update(t, z, R)

    rows = [
        ("filterpy ExtendedKalmanFilter", best(filterpy_ekf)),
        ("ExtendedKalmanFilter.update_many", best(ekf_many)),
        ("ExtendedKalmanFilter.update", best(ekf_each)),
        ("filterpy UnscentedKalmanFilter", best(filterpy_ukf)),
        ("UnscentedKalmanFilter(f=, h=).update_many", best(ukf_many)),
        ("UnscentedKalmanFilter(f=, h=).update", best(ukf_each)),
    ]
    ref = {"Ext": rows[0][1], "Uns": rows[3][1]}
    for name, us in rows:
        base = ref["Ext" if "Extended" in name else "Uns"]
        print(f"{name:44s} {us:8.1f} us/step  {base / us:5.2f}x filterpy")


if __name__ == "__main__":
    main()
