"""Times LinearKalmanFilter.update_many against filterpy 2.0.0's KalmanFilter.batch_filter on the
same data, in the same run (BENCHMARKS.md, "Linear Kalman filter with your matrices against
filterpy").

Run:  target/py-venv/bin/python crates/seqsmooth-py/bench/linear_kalman.py
(the package installed in target/py-venv, as for the tests). The model: constant velocity on two
axes (n = 4, state x, x', y, y'), dt = 1, Q from filterpy's Q_discrete_white_noise per axis,
both positions observed with a full 2 x 2 R; constant matrices; measurements from numpy
(float64), in batches of SHORT steps (best of SHORT_REPEATS: the output arrays' memory comes
back from the allocator) and of STEPS (best of REPEATS: each call's 64 MB of new output is
fresh memory, paid for in page faults). Each call on a fresh filter, timed by the calling
thread's CPU time (time.thread_time: both run in that one thread; on a shared machine the wall time
counts the other processes too) and by the wall clock; filterpy's batch_filter on the
first PEER_STEPS measurements (its cost per step does not depend on the length). Both return
every step's updated and predicted state and covariance. Checks that both give the same
states (to 1e-9 relative) before timing. Prints `name<TAB>ns per step` and the ratio.
"""

from __future__ import annotations

import time

import numpy as np
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import KalmanFilter
from scipy.linalg import block_diag

import seqsmooth as ss

STEPS = 200_000
SHORT = 2_000
SHORT_REPEATS = 200
PEER_STEPS = 20_000
REPEATS = 5

F = np.array([[1, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1], [0, 0, 0, 1]], float)
Q = block_diag(*[Q_discrete_white_noise(dim=2, dt=1.0, var=0.01)] * 2)
H = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
R = np.array([[1.0, 0.2], [0.2, 0.5]])
X0, P0 = np.zeros(4), np.eye(4) * 100.0


def data(steps):
    rng = np.random.default_rng(1)
    t = np.arange(steps, dtype=float)
    return np.column_stack([0.5 * t, 3.0 - 0.2 * t]) + rng.normal(0, 1, (steps, 2))


def seqsmooth_run(zs):
    kf = ss.LinearKalmanFilter(X0, P0, F, H, Q, R)
    return kf.update_many(zs)


def filterpy_run(zs):
    kf = KalmanFilter(dim_x=4, dim_z=2)
    kf.x, kf.P, kf.F, kf.H, kf.Q, kf.R = X0.copy(), P0.copy(), F, H, Q, R
    return kf.batch_filter(zs)


def best(run, zs, clock, repeats):
    out = float("inf")
    for _ in range(repeats):
        start = clock()
        run(zs)
        out = min(out, clock() - start)
    return out / len(zs) * 1e9


def main():
    zs = data(STEPS)
    ours = seqsmooth_run(zs[:PEER_STEPS])[0]
    theirs = filterpy_run(zs[:PEER_STEPS])[0]
    worst = np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs))
    assert worst < 1e-9, worst
    for steps, repeats in [(SHORT, SHORT_REPEATS), (STEPS, REPEATS)]:
        for clock, what in [(time.thread_time, "CPU"), (time.perf_counter, "wall")]:
            a = best(seqsmooth_run, zs[:steps], clock, repeats)
            b = best(filterpy_run, zs[: min(steps, PEER_STEPS)], clock, REPEATS)
            print(f"{steps} steps, LinearKalmanFilter.update_many ({what})\t{a:.1f}")
            print(f"{steps} steps, filterpy KalmanFilter.batch_filter ({what})\t{b:.1f}")
            print(f"{steps} steps, ratio ({what})\t{b / a:.1f}")
    print(f"largest relative difference of the states\t{worst:.1e}")


main()
