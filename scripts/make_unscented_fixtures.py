#!/usr/bin/env python3
"""Writes the filterpy.kalman.UnscentedKalmanFilter fixtures that seqsmooth's unscented filter
and smoother (`seqsmooth::kalman::UnscentedKalmanFilter`, `kalman::unscented_smoother`) are
checked against: crates/seqsmooth/tests/fixtures/unscented/, read by
crates/seqsmooth/tests/kalman_unscented.rs.

Run:  python3 scripts/make_unscented_fixtures.py
It uses the pinned virtual environment of scripts/peers_venv.py (target/peers-venv: filterpy
2.0.0, numpy, scipy; created the same way if missing), re-runs itself there, and writes two
problems on irregular steps, with driving noise and some measurements missing (whole rows, and
single components):
  linear.csv - constant velocity on two axes observed in both positions with a full R
               (dim_x = 4 in seqsmooth's PolynomialDynamics order (x, y, x', y'), dim_z = 2),
               MerweScaledSigmaPoints(4, alpha=0.5, beta=2, kappa=1);
  radar.csv  - constant velocity on three axes (x, y, z, x', y', z') seen by a radar at SITE in
               range, azimuth and elevation (seqsmooth's model::radar conventions: azimuth
               atan2(dy, dx), elevation atan2(dz, sqrt(dx^2 + dy^2))), the target crossing
               azimuth pi; the azimuth residual wrapped to (-pi, pi] and the predicted
               measurement's mean taken about the central sigma point with wrapped differences
               (filterpy's residual_z and z_mean_fn, as its documentation suggests for angles);
               MerweScaledSigmaPoints(6, alpha=1, beta=2, kappa=0).
Each file: '#' lines first (what made it, then the setup as '# key,values...'), then the header
and one row per step: t, z (NaN where missing), filterpy's x and P (row-major) after the update
(or after the prediction alone where every component is missing), the update's NIS y' S^-1 y
(NaN without an update), and the unscented RTS smoother's x and P.

How filterpy is driven:
- predict(dt) with fx(x, dt) = F(dt) x and Q = Q(dt) of the step (Morrison (15.2.23) in closed
  form, computed here independently of seqsmooth); filterpy redraws its sigma points from the
  predicted (x, P) before the update (UKF.predict).
- A row with some components missing: update(z_present, R=R_present, hx=h restricted to the
  present components), the residual function wrapping the azimuth where it is present.
- The smoother: filterpy's UnscentedKalmanFilter.rts_smoother (the urts smoother) uses self.Q
  for every step whatever its Qs argument, so it is called once per backward step, on the pair
  (filtered x_k, smoothed x_{k+1}) with Q and dt of the step k -> k+1: its own code, one step at
  a time, each step with its own Q.

Every number is written with repr (round-trip exact).
"""

import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peers_venv  # noqa: E402

OUT = os.path.join(ROOT, "crates", "seqsmooth", "tests", "fixtures", "unscented")
SEED = 20261206
SITE = [300.0, -200.0, 10.0]
peers_venv.enter(__file__)

import filterpy  # noqa: E402
import numpy as np  # noqa: E402
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter  # noqa: E402


def transition(m, d, dt):
    """Phi(dt) of the degree-m polynomial model on d axes, state ordered derivative then axis."""
    f = np.zeros(((m + 1) * d, (m + 1) * d))
    for i in range(m + 1):
        for j in range(i, m + 1):
            for a in range(d):
                f[i * d + a, j * d + a] = dt ** (j - i) / math.factorial(j - i)
    return f


def process_noise(m, d, q, dt):
    """Q over a step dt for white noise of spectral density q on the highest derivative of
    each axis (Morrison (15.2.23) in closed form):
    q |dt|^(2m+1-i-j) / ((m-i)! (m-j)! (2m+1-i-j))."""
    z = abs(dt)
    out = np.zeros(((m + 1) * d, (m + 1) * d))
    for i in range(m + 1):
        for j in range(m + 1):
            p = 2 * m + 1 - i - j
            v = q * z**p / (math.factorial(m - i) * math.factorial(m - j) * p)
            for a in range(d):
                out[i * d + a, j * d + a] = v
    return out


def wrap(a):
    """An angle to (-pi, pi]."""
    a = math.fmod(a, 2 * math.pi)
    if a > math.pi:
        a -= 2 * math.pi
    elif a <= -math.pi:
        a += 2 * math.pi
    return a


def radar(x):
    dx, dy, dz = x[0] - SITE[0], x[1] - SITE[1], x[2] - SITE[2]
    horizontal = math.hypot(dx, dy)
    return np.array(
        [math.sqrt(dx * dx + dy * dy + dz * dz), math.atan2(dy, dx), math.atan2(dz, horizontal)]
    )


def problem(name, m, d, q, t0, x0, p0, r, h, angles, points, steps, rng):
    n, k = (m + 1) * d, len(r)
    dts = rng.uniform(0.3, 1.7, steps)
    t = [t0]
    for dt in dts:
        t.append(t[-1] + float(dt))
    whole = rng.random(steps) < 0.08
    whole[[0, steps // 2, steps // 2 + 1]] = True
    single = rng.random((steps, k)) < 0.08
    truth = rng.multivariate_normal(x0, p0)
    present = list(range(k))  # the components of the update in progress

    def residual_z(a, b):
        y = np.subtract(a, b)
        for c, comp in enumerate(present):
            if comp in angles:
                y[c] = wrap(y[c])
        return y

    def z_mean(sigmas, wm):
        # About the central point, each angle's differences wrapped: sum(wm) = 1, so for the
        # other components this is np.dot(wm, sigmas) up to rounding.
        return sigmas[0] + sum(w * residual_z(row, sigmas[0]) for w, row in zip(wm[1:], sigmas[1:]))

    ukf = UnscentedKalmanFilter(
        dim_x=n,
        dim_z=k,
        dt=1.0,
        hx=h,
        fx=lambda x, dt: transition(m, d, dt) @ x,
        points=points,
        residual_z=residual_z,
        z_mean_fn=z_mean,
    )
    ukf.x = np.array(x0, dtype=float)
    ukf.P = np.array(p0, dtype=float)
    rows, xs, ps = [], [], []
    for s in range(steps):
        dt = t[s + 1] - t[s]
        f, qm = transition(m, d, dt), process_noise(m, d, q, dt)
        truth = f @ truth + rng.multivariate_normal(np.zeros(n), qm)
        y = h(truth) + rng.multivariate_normal(np.zeros(k), r)
        ukf.Q = qm
        ukf.predict(dt=dt)
        present[:] = [] if whole[s] else [c for c in range(k) if not single[s, c]]
        z = [float(y[c]) if c in present else float("nan") for c in range(k)]
        nis = float("nan")
        if present:
            idx = list(present)
            ukf.update(
                np.array([z[c] for c in idx]),
                R=r[np.ix_(idx, idx)],
                hx=lambda x, idx=idx: h(x)[idx],
            )
            nis = float(ukf.y @ np.linalg.inv(ukf.S) @ ukf.y)
        xs.append(ukf.x.copy())
        ps.append(ukf.P.copy())
        rows.append(
            [t[s + 1]] + z + [float(v) for v in ukf.x] + [float(v) for v in ukf.P.ravel()] + [nis]
        )
    # The smoother, one backward step at a time (each with its own Q, see the docstring).
    sx, sp = [None] * steps, [None] * steps
    sx[-1], sp[-1] = xs[-1].copy(), ps[-1].copy()
    for s in reversed(range(steps - 1)):
        dt = t[s + 2] - t[s + 1]
        ukf.Q = process_noise(m, d, q, dt)
        out_x, out_p, _ = ukf.rts_smoother(
            np.array([xs[s], sx[s + 1]]), np.array([ps[s], sp[s + 1]]), dts=[dt, dt]
        )
        sx[s], sp[s] = out_x[0], out_p[0]
    for s in range(steps):
        rows[s] += [float(v) for v in sx[s]] + [float(v) for v in sp[s].ravel()]
    header = (
        ["t"]
        + [f"z{i}" for i in range(k)]
        + [f"x{i}" for i in range(n)]
        + [f"P{i}_{j}" for i in range(n) for j in range(n)]
        + ["nis"]
        + [f"xs{i}" for i in range(n)]
        + [f"Ps{i}_{j}" for i in range(n) for j in range(n)]
    )

    def num(v):
        return "NaN" if math.isnan(v) else repr(float(v))

    path = os.path.join(OUT, f"{name}.csv")
    with open(path, "w") as out:
        out.write(
            f"# made by scripts/make_unscented_fixtures.py: filterpy {filterpy.__version__} "
            f"UnscentedKalmanFilter, MerweScaledSigmaPoints, rts_smoother; numpy "
            f"{np.__version__}; seed {SEED}; {steps} steps; {int(whole.sum())} rows "
            f"missing\n"
        )
        setup = [
            ("degree", [m]),
            ("axes", [d]),
            ("q", [q]),
            ("t0", [t0]),
            ("x0", list(x0)),
            ("P0", list(np.ravel(p0))),
            ("R", list(np.ravel(r))),
            ("sigma", [points.alpha, points.beta, points.kappa]),
            ("site", SITE),
        ]
        for key, vals in setup:
            cells = (num(v) if isinstance(v, float) else str(v) for v in vals)
            out.write(f"# {key}," + ",".join(cells) + "\n")
        out.write(",".join(header) + "\n")
        for row in rows:
            out.write(",".join(num(v) for v in row) + "\n")
    print("wrote", path)


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(SEED)
    # (a) linear: constant velocity on two axes, both positions observed (full R).
    per_axis = np.array([[9.0, 1.0], [1.0, 4.0]])
    problem(
        "linear",
        1,
        2,
        0.2,
        5.0,
        [10.0, -4.0, 1.5, 0.5],
        np.kron(per_axis, np.eye(2)),
        np.array([[0.5, 0.2], [0.2, 0.8]]),
        lambda x: np.array([x[0], x[1]]),
        [],
        MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=1.0),
        150,
        rng,
    )
    # (b) radar: constant velocity on three axes, range, azimuth, elevation.
    per_axis = np.array([[400.0, 20.0], [20.0, 25.0]])
    # From azimuth 2.84 rad through pi (at about t = 160) to -2.9: the wrapped residuals.
    problem(
        "radar",
        1,
        3,
        2.0,
        100.0,
        [-7700.0, 2300.0, 2010.0, 30.0, -40.0, 2.0],
        np.kron(per_axis, np.eye(3)),
        np.diag([25.0, 4e-6, 4e-6]),
        radar,
        [1],
        MerweScaledSigmaPoints(6, alpha=1.0, beta=2.0, kappa=0.0),
        150,
        rng,
    )


if __name__ == "__main__":
    main()
