"""Cost per measurement of fixed_lag_smoother(t, z, R, lag) on UnscentedKalmanFilter (radar,
6 states) and KalmanFilter (the same motion, positions observed) against update_many and
smooth: 4,000 irregular steps, best of 3. BENCHMARKS.md, "Fixed-lag smoothers of the Kalman
classes"."""

import time

import numpy as np

import seqsmooth as ss

N = 4000
rng = np.random.default_rng(6)
t = np.cumsum(rng.uniform(0.3, 1.7, size=N))
p0, v = np.array([8000.0, -6000.0, 3000.0]), np.array([-1.5, 1.2, 0.1])
pos = p0 + t[:, None] * v
r = np.linalg.norm(pos, axis=1)
z = np.column_stack([r, np.arctan2(pos[:, 1], pos[:, 0]), np.arcsin(pos[:, 2] / r)])
z += rng.normal(0, 1, size=z.shape) * [5.0, 1e-3, 1e-3]
R = [25.0, 1e-6, 1e-6]
zl = pos + rng.normal(0, 5, size=pos.shape)
x0, P0 = np.concatenate([p0, v]), np.diag([400.0] * 3 + [100.0] * 3)


def best(fn):
    """Microseconds per measurement, the best of 3 runs."""
    times = []
    for _ in range(3):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times) / N * 1e6


def ukf():
    return ss.UnscentedKalmanFilter(1, x0, P0, axes=3, q=0.05, observation="radar")


def kf():
    return ss.KalmanFilter(1, x0, P0, axes=3, q=0.05, observation=np.eye(3, 6))


print(f"unscented update_many {best(lambda: ukf().update_many(t, z, R)):.1f} us")
print(f"unscented smooth {best(lambda: ukf().smooth(t, z, R)):.1f} us")
for lag in (0, 10, 50, 200):
    cost = best(lambda lag=lag: ukf().fixed_lag_smoother(t, z, R, lag))
    print(f"unscented fixed_lag_smoother lag {lag} {cost:.1f} us")
print(f"kalman smooth {best(lambda: kf().smooth(t, zl, 25.0)):.1f} us")
for lag in (0, 10, 50, 200):
    cost = best(lambda lag=lag: kf().fixed_lag_smoother(t, zl, 25.0, lag))
    print(f"kalman fixed_lag_smoother lag {lag} {cost:.1f} us")
