"""Per-step time and dxdt calls of the filters over a Python dxdt (BENCHMARKS.md, "Filters
over a Python dxdt"): constant velocity on two axes written as dxdt = A x, positions observed,
200 steps of 0.5; best of 3."""

import time

import numpy as np

import seqsmooth as ss

A = np.array([[0.0, 1.0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1.0], [0, 0, 0, 0]])
t = np.cumsum(np.full(200, 0.5))
z = np.column_stack([t, 2 * t])
calls = {"n": 0}


def h(x, t):
    return np.array([x[0], x[2]])


def dxdt(x, t):
    calls["n"] += 1
    return A @ x


def f(x, t0, t1):
    return x + (t1 - t0) * (A @ x)


FILTERS = {
    "ExtendedKalmanFilter(dxdt=)": lambda: ss.ExtendedKalmanFilter(
        np.zeros(4), 10.0, h=h, dxdt=dxdt, Q=1e-3
    ),
    "ExtendedKalmanFilter(dxdt=, dxdt_jacobian=)": lambda: ss.ExtendedKalmanFilter(
        np.zeros(4), 10.0, h=h, dxdt=dxdt, dxdt_jacobian=lambda x, t: A, Q=1e-3
    ),
    "UnscentedKalmanFilter(dxdt=)": lambda: ss.UnscentedKalmanFilter(
        x0=np.zeros(4), P0=10.0, h=h, dxdt=dxdt, Q=1e-3 * np.eye(4)
    ),
    "ExtendedKalmanFilter(f=) (no integration)": lambda: ss.ExtendedKalmanFilter(
        np.zeros(4), 10.0, f, h, Q=1e-3
    ),
}

for name, make in FILTERS.items():
    best = np.inf
    for _ in range(3):
        flt = make()
        calls["n"] = 0
        start = time.perf_counter()
        flt.update_many(t, z, 1.0)
        best = min(best, time.perf_counter() - start)
    print(f"{name}: {best / 200 * 1e6:.0f} us/step, {calls['n'] / 200:.0f} dxdt calls/step")
