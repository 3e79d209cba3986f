"""Times KalmanFilter.smooth (the Rauch-Tung-Striebel smoother: the filter, then the backward
pass) against KalmanFilter.update_many (the filter alone) on the same series, in the same run
(BENCHMARKS.md, "The Kalman filter and its smoother against their floors").

Run:  target/py-venv/bin/python crates/seqsmooth-py/bench/kalman_smooth.py
(the package installed in target/py-venv, as for the tests). The model: constant velocity
(degree 1, one axis), white-acceleration driving noise q = 0.1, the position observed with
variance 1, SERIES series of STEPS irregular steps each (steps U(0.5, 1.5)); each call on a
fresh filter, one series at a time in a Python loop (as the issue's figure: 1,000 series x
1,000 steps), timed by the calling thread's CPU time (time.thread_time) over all the series,
best of REPEATS, the two calls alternated. Checks before timing that the smoother's last
estimate is the filter's and that its variances are at most the filter's. Prints each call's
ns per step and the ratio smooth / update_many.
"""

from __future__ import annotations

import time

import numpy as np

import seqsmooth as ss

SERIES = 200
STEPS = 1_000
REPEATS = 7


def main() -> None:
    rng = np.random.default_rng(33)
    data = []
    for _ in range(SERIES):
        t = np.cumsum(rng.uniform(0.5, 1.5, STEPS))
        z = 0.3 * t + rng.normal(0.0, 1.0, STEPS)
        data.append((t, z))
    x0, p0 = np.zeros(2), np.eye(2) * 1e4

    def filtered(t: np.ndarray, z: np.ndarray) -> tuple:
        return ss.KalmanFilter(1, x0, p0, q=0.1).update_many(t, z, 1.0)

    def smoothed(t: np.ndarray, z: np.ndarray) -> tuple:
        return ss.KalmanFilter(1, x0, p0, q=0.1).smooth(t, z, 1.0)

    for t, z in data[:5]:
        (xf, pf, _), (xs, ps) = filtered(t, z), smoothed(t, z)
        assert np.array_equal(xs[-1], xf[-1]) and np.array_equal(ps[-1], pf[-1])
        assert np.all(
            np.diagonal(ps, axis1=1, axis2=2) <= np.diagonal(pf, axis1=1, axis2=2) * (1 + 1e-12)
        )

    best = {"update_many": np.inf, "smooth": np.inf}
    ratios = []
    for _ in range(REPEATS):
        times = {}
        for name, call in (("update_many", filtered), ("smooth", smoothed)):
            start = time.thread_time()
            for t, z in data:
                call(t, z)
            times[name] = time.thread_time() - start
            best[name] = min(best[name], times[name])
        ratios.append(times["smooth"] / times["update_many"])
    steps = SERIES * STEPS
    for name, seconds in best.items():
        print(f"{name}\t{seconds / steps * 1e9:.1f} ns per step")
    ratios.sort()
    median, low, high = ratios[len(ratios) // 2], ratios[0], ratios[-1]
    print(f"smooth / update_many\t{median:.2f} (min {low:.2f}, max {high:.2f})")


if __name__ == "__main__":
    main()
