#!/usr/bin/env python3
"""The unscented Kalman filter's time per step, seqsmooth against filterpy 2.0.0, same data,
same run: a constant-velocity target on three axes seen by a radar in range, azimuth and
elevation (6 states, 3 components, driving noise, irregular steps), MerweScaledSigmaPoints
(alpha 1, beta 2, kappa 0) on both sides. filterpy: predict(dt) + update(z) per step with
numpy fx/hx (its Q set per step); seqsmooth: UnscentedKalmanFilter(observation="radar")
through update_many, and through update one call a step. Best of REPEATS.

Run in the Python test environment (filterpy installed):
  target/py-venv/bin/python scripts/unscented_bench.py
"""

import math
import time

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

import seqsmooth as ss

STEPS, REPEATS, Q = 2000, 5, 2.0


def transition(dt):
    f = np.eye(6)
    f[:3, 3:] = dt * np.eye(3)
    return f


def noise(dt):
    return np.kron(np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]) * Q, np.eye(3))


def radar(x):
    dx, dy, dz = x[0], x[1], x[2]
    return np.array(
        [
            math.sqrt(dx * dx + dy * dy + dz * dz),
            math.atan2(dy, dx),
            math.atan2(dz, math.hypot(dx, dy)),
        ]
    )


def main():
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.5, 1.5, STEPS))
    start = np.array([20e3, 10e3, 3e3, -100.0, 50.0, 1.0])
    truth = [start[:3] + start[3:] * tk for tk in t]
    sd = np.array([10.0, 1e-3, 1e-3])
    z = np.array([radar(p) for p in truth]) + rng.normal(0.0, 1.0, (STEPS, 3)) * sd
    R = np.diag(sd**2)
    p0 = np.kron(np.array([[400.0, 20.0], [20.0, 25.0]]), np.eye(3))
    best = {"filterpy": math.inf, "update_many": math.inf, "update": math.inf}
    for _ in range(REPEATS):
        ukf = UnscentedKalmanFilter(
            dim_x=6,
            dim_z=3,
            dt=1.0,
            hx=radar,
            fx=lambda x, dt: transition(dt) @ x,
            points=MerweScaledSigmaPoints(6, alpha=1.0, beta=2.0, kappa=0.0),
        )
        ukf.x, ukf.P, ukf.R = start.copy(), p0.copy(), R
        previous = 0.0
        t0 = time.perf_counter()
        for tk, zk in zip(t, z):
            ukf.Q = noise(tk - previous)
            ukf.predict(dt=tk - previous)
            ukf.update(zk)
            previous = tk
        best["filterpy"] = min(best["filterpy"], time.perf_counter() - t0)
        f = ss.UnscentedKalmanFilter(degree=1, axes=3, q=Q, x0=start, P0=p0, observation="radar")
        t0 = time.perf_counter()
        x, _, _ = f.update_many(t, z, R)
        best["update_many"] = min(best["update_many"], time.perf_counter() - t0)
        g = ss.UnscentedKalmanFilter(degree=1, axes=3, q=Q, x0=start, P0=p0, observation="radar")
        t0 = time.perf_counter()
        for tk, zk in zip(t, z):
            g.update(tk, zk, R)
        best["update"] = min(best["update"], time.perf_counter() - t0)
        assert np.max(np.abs(g.state - ukf.x) / np.sqrt(np.diag(ukf.P))) < 1e-6
    for name, s in best.items():
        print(f"{name:12s} {s / STEPS * 1e6:8.2f} us/step  ({best['filterpy'] / s:6.1f}x filterpy)")


if __name__ == "__main__":
    main()
