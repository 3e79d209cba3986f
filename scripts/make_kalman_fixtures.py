#!/usr/bin/env python3
"""Writes the filterpy.kalman.KalmanFilter fixtures that seqsmooth's Kalman filter
(`seqsmooth::kalman::KalmanFilter`) is checked against: crates/seqsmooth/tests/fixtures/kalman/,
read by crates/seqsmooth/tests/kalman_filterpy.rs.

Run:  python3 scripts/make_kalman_fixtures.py
It uses the pinned virtual environment of scripts/peers_venv.py (target/peers-venv, its PINS and
stamp file; created the same way if missing), re-runs itself there, and writes two problems, each
on STEPS irregular steps (dt ~ U(0.2, 1.8), seed SEED) with driving noise (Q != 0) and some
measurements missing:
  cv1.csv - constant velocity on one axis, observed in position (dim_x = 2, dim_z = 1);
  ca2.csv - constant acceleration on two axes, observed in both positions (dim_x = 6, dim_z = 2,
            full R), state in seqsmooth's PolynomialDynamics order: derivative, then axis,
            (x, y, x', y', x'', y'').
Each file: '#' lines first (what made it, then the setup as '# key,values...': degree, axes, q,
t0, x0, P0 and R row-major), then the header and one row per step: t, z (NaN where the
measurement is missing), and filterpy's x and P (row-major) after the update, or after the
prediction alone where z is missing.

filterpy 2.0.0's KalmanFilter.update always uses Joseph's form,
P = (I - K H) P (I - K H)' + K R K' (kalman_filter.py, KalmanFilter.update), with the gain by an
explicit inverse K = P H' inv(H P H' + R); it has no option for another form.

Every number is written with repr (17 significant digits at most, round-trip exact), so the Rust
side reads back the same doubles.
"""

import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peers_venv  # noqa: E402

VENV, PINS = peers_venv.VENV, peers_venv.PINS
OUT = os.path.join(ROOT, "crates", "seqsmooth", "tests", "fixtures", "kalman")
SEED = 20260416
STEPS = 200
peers_venv.enter(__file__)

import filterpy  # noqa: E402
import numpy as np  # noqa: E402
from filterpy.kalman import KalmanFilter  # noqa: E402


def transition(m, d, dt):
    """Phi(dt) of the degree-m polynomial model on d axes, state ordered derivative then axis:
    [Phi]_{i d + a, j d + a} = dt^(j-i) / (j-i)! for j >= i (Psi(dt) kron I_d)."""
    f = np.zeros(((m + 1) * d, (m + 1) * d))
    for i in range(m + 1):
        for j in range(i, m + 1):
            for a in range(d):
                f[i * d + a, j * d + a] = dt ** (j - i) / math.factorial(j - i)
    return f


def process_noise(m, d, q, dt):
    """Q over a step of length dt for white noise of spectral density q on the highest (m-th)
    derivative of each axis. This is Morrison (15.2.23), Q = int_0^dt Phi(s) D K D' Phi(s)' ds
    with D = e_m kron I_d and K = q I_d, integrated in closed form for this model:
    Q_ij = q |dt|^(2m+1-i-j) / ((m-i)! (m-j)! (2m+1-i-j)) per axis, derivatives i, j <= m
    (computed here on its own, not taken from seqsmooth)."""
    z = abs(dt)
    out = np.zeros(((m + 1) * d, (m + 1) * d))
    for i in range(m + 1):
        for j in range(m + 1):
            p = 2 * m + 1 - i - j
            v = q * z**p / (math.factorial(m - i) * math.factorial(m - j) * p)
            for a in range(d):
                out[i * d + a, j * d + a] = v
    return out


def problem(name, m, d, q, t0, x0, p0, r, rng, forced_missing):
    n, k = (m + 1) * d, d
    h = np.zeros((k, n))
    h[:, :d] = np.eye(d)  # the positions: the first d states
    dts = rng.uniform(0.2, 1.8, STEPS)
    t = [t0]
    for dt in dts:
        t.append(t[-1] + float(dt))
    missing = rng.random(STEPS) < 0.1
    missing[list(forced_missing)] = True
    # A truth with the same driving noise, seen with noise of covariance R.
    truth = rng.multivariate_normal(x0, p0)
    kf = KalmanFilter(dim_x=n, dim_z=k)
    kf.x = np.array(x0, dtype=float).reshape(n, 1)
    kf.P = np.array(p0, dtype=float)
    kf.R = np.array(r, dtype=float)
    kf.H = h
    rows = []
    for s in range(STEPS):
        dt = t[s + 1] - t[s]  # the step both sides compute from the stored times
        f, qm = transition(m, d, dt), process_noise(m, d, q, dt)
        truth = f @ truth + rng.multivariate_normal(np.zeros(n), qm)
        y = h @ truth + rng.multivariate_normal(np.zeros(k), r)
        kf.F, kf.Q = f, qm
        kf.predict()
        if missing[s]:
            z = [float("nan")] * k
        else:
            z = [float(v) for v in y]
            kf.update(np.array(z).reshape(k, 1))
        rows.append(
            [t[s + 1]] + z + [float(v) for v in kf.x.ravel()] + [float(v) for v in kf.P.ravel()]
        )
    header = (
        ["t"]
        + [f"z{i}" for i in range(k)]
        + [f"x{i}" for i in range(n)]
        + [f"P{i}_{j}" for i in range(n) for j in range(n)]
    )

    def num(v):
        return "NaN" if math.isnan(v) else repr(float(v))

    path = os.path.join(OUT, f"{name}.csv")
    with open(path, "w") as f:
        f.write(
            f"# made by scripts/make_kalman_fixtures.py: filterpy {filterpy.__version__} "
            f"KalmanFilter (Joseph-form update); numpy {np.__version__}; seed {SEED}; "
            f"{STEPS} steps; {int(missing.sum())} measurements missing\n"
        )
        setup = [
            ("degree", [m]),
            ("axes", [d]),
            ("q", [q]),
            ("t0", [t0]),
            ("x0", list(x0)),
            ("P0", list(np.ravel(p0))),
            ("R", list(np.ravel(r))),
        ]
        for key, vals in setup:
            cells = (num(v) if isinstance(v, float) else str(v) for v in vals)
            f.write(f"# {key}," + ",".join(cells) + "\n")
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(num(v) for v in row) + "\n")
    print("wrote", path, f"({int(missing.sum())} missing)")


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(SEED)
    # (a) constant velocity, one axis, position observed; the first step and a run of three missing.
    problem(
        "cv1",
        1,
        1,
        0.05,
        100.0,
        [2.0, 1.0],
        np.array([[4.0, 0.5], [0.5, 1.0]]),
        np.array([[0.25]]),
        rng,
        [0, 60, 61, 62],
    )
    # (b) constant acceleration, two axes, both positions observed with correlated noise.
    per_axis = np.array([[25.0, 5.0, 0.5], [5.0, 4.0, 0.4], [0.5, 0.4, 1.0]])
    p0 = np.kron(per_axis, np.eye(2))  # derivative then axis
    problem(
        "ca2",
        2,
        2,
        0.01,
        -3.5,
        [10.0, -5.0, 2.0, 1.0, 0.1, -0.2],
        p0,
        np.array([[0.5, 0.15], [0.15, 0.3]]),
        rng,
        [0, 100, 101, 102, 199],
    )


if __name__ == "__main__":
    main()
