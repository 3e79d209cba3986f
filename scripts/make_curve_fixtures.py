#!/usr/bin/env python3
"""Writes the scipy.optimize.least_squares fixtures that `seqsmooth`'s maximum-likelihood curve
fit (estimate::curve) is checked against (crates/seqsmooth/tests/fixtures/curve/).

Run:  python3 scripts/make_curve_fixtures.py
It creates (once) a private virtual environment in target/savgol-venv with numpy and scipy
(scripts/fixture_venv.py, shared with make_savgol_fixtures.py), re-runs itself there, and writes:
  demo.csv    - t,y,sigma: a test model h = a exp(b t) + c t (not in Villien & Ostertag),
                truth (1, 0.8, -0.5), 2000 samples on [0, 2], noise sigma 0.05 (1 + t)
  fit.csv     - name,value: scipy's Levenberg-Marquardt (MINPACK lmder) estimate from
                (0.5, 0, 0) with the analytic Jacobian and tolerances 1e-15, and the covariance
                (J^T J)^-1 of the whitened Jacobian at it (by numpy's SVD), row by row
  versions.txt - the numpy and scipy versions used
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fixture_venv import ROOT, reexec  # noqa: E402

reexec(__file__)
OUT = os.path.join(ROOT, "crates", "seqsmooth", "tests", "fixtures", "curve")

import numpy as np  # noqa: E402
import scipy  # noqa: E402
from scipy.optimize import least_squares  # noqa: E402

os.makedirs(OUT, exist_ok=True)
rng = np.random.default_rng(20261205)
n = 2000
t = np.linspace(0.0, 2.0, n)
sigma = 0.05 * (1.0 + t)
y = 1.0 * np.exp(0.8 * t) - 0.5 * t + sigma * rng.standard_normal(n)
# Round the inputs to their own 17-digit text so the Rust side reads back identical doubles.
t, y, sigma = (np.array([float(repr(float(v))) for v in a]) for a in (t, y, sigma))


def residuals(p):
    return (p[0] * np.exp(p[1] * t) + p[2] * t - y) / sigma


def jacobian(p):
    e = np.exp(p[1] * t)
    return np.stack([e, p[0] * t * e, t], axis=1) / sigma[:, None]


fit = least_squares(
    residuals, [0.5, 0.0, 0.0], jac=jacobian, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15
)
j = jacobian(fit.x)
u, s, vt = np.linalg.svd(j, full_matrices=False)
cov = (vt.T / s**2) @ vt
with open(os.path.join(OUT, "demo.csv"), "w") as f:
    f.write("t,y,sigma\n")
    for row in zip(t, y, sigma):
        f.write(",".join(repr(float(v)) for v in row) + "\n")
with open(os.path.join(OUT, "fit.csv"), "w") as f:
    f.write("name,value\n")
    for i, v in enumerate(fit.x):
        f.write(f"theta{i},{float(v)!r}\n")
    for i in range(3):
        for k in range(3):
            f.write(f"cov{i}{k},{float(cov[i, k])!r}\n")
    f.write(f"chi_squared,{float(2 * fit.cost)!r}\n")
with open(os.path.join(OUT, "versions.txt"), "w") as f:
    f.write(f"numpy {np.__version__}\nscipy {scipy.__version__}\n")
print("wrote", OUT, fit.x, fit.status)
