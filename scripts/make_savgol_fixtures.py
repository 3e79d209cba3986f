#!/usr/bin/env python3
"""Writes the scipy.signal.savgol_filter fixtures that `seqsmooth`'s whole-series smoothing is
checked against (crates/seqsmooth/tests/fixtures/savgol/).

Run:  python3 scripts/make_savgol_fixtures.py
It creates (once) a private virtual environment in target/savgol-venv with numpy and scipy,
re-runs itself there, and writes:
  input.csv  - t,y: 400 evenly spaced samples (step 0.05) of a smooth signal plus noise
  cases.csv  - degree,window,deriv,index,value: savgol_filter(y, window, degree, deriv=deriv,
               delta=0.05, mode="interp") for degrees 0-5, windows 5..201, derivatives 0-2
  versions.txt - the numpy and scipy versions used
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fixture_venv import ROOT, reexec  # noqa: E402

reexec(__file__)
OUT = os.path.join(ROOT, "crates", "seqsmooth", "tests", "fixtures", "savgol")

import numpy as np  # noqa: E402
import scipy  # noqa: E402
from scipy.signal import savgol_filter  # noqa: E402

os.makedirs(OUT, exist_ok=True)
rng = np.random.default_rng(20261124)
n, dt = 400, 0.05
t = np.arange(n) * dt
y = np.sin(1.3 * t) + 0.4 * np.cos(3.1 * t + 0.5) + 0.05 * t * t + 0.1 * rng.standard_normal(n)
# Round the inputs to their own 17-digit text so the Rust side reads back identical doubles.
with open(os.path.join(OUT, "input.csv"), "w") as f:
    f.write("t,y\n")
    for ti, yi in zip(t, y):
        f.write(f"{float(ti)!r},{float(yi)!r}\n")
with open(os.path.join(OUT, "cases.csv"), "w") as f:
    f.write("degree,window,deriv,index,value\n")
    for degree in range(0, 6):
        for window in [5, 11, 21, 51, 101, 201]:
            if window <= degree:
                continue
            for deriv in range(0, 3):
                out = savgol_filter(y, window, degree, deriv=deriv, delta=dt, mode="interp")
                for i, v in enumerate(out):
                    f.write(f"{degree},{window},{deriv},{i},{float(v)!r}\n")
with open(os.path.join(OUT, "versions.txt"), "w") as f:
    f.write(f"numpy {np.__version__}\nscipy {scipy.__version__}\n")
print("wrote", OUT)
