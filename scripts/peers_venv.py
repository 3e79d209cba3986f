"""The peer scripts' pinned virtual environment (target/peers-venv): filterpy, numpy, scipy,
simdkalman and pykalman
at the versions below, created once from PyPI. `enter(__file__)` re-runs the calling script in
that environment (with the same arguments) unless it already runs there; scripts/peers.py and
scripts/make_kalman_fixtures.py share it, so the peer timings and the stored fixtures come from
the same versions."""

import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "peers-venv")
PINS = ["filterpy==2.0.0", "numpy==2.4.6", "scipy==1.17.1", "simdkalman==1.0.4", "pykalman==0.11.2"]
STAMP = os.path.join(VENV, "peers-pins.txt")


def in_venv():
    return os.path.realpath(sys.prefix) == os.path.realpath(VENV)


def enter(script):
    """Re-runs `script` in the pinned environment (installing it first if its pins changed)
    and exits with its status; returns at once when already inside it."""
    if in_venv():
        return
    py = os.path.join(VENV, "bin", "python")
    have = open(STAMP).read() if os.path.exists(STAMP) else None
    if have != "\n".join(PINS):
        if not os.path.exists(py):
            subprocess.check_call([sys.executable, "-m", "venv", VENV])
        subprocess.check_call([py, "-m", "pip", "install", "--quiet", "--upgrade", "pip"])
        subprocess.check_call([py, "-m", "pip", "install", "--quiet"] + PINS)
        with open(STAMP, "w") as f:
            f.write("\n".join(PINS))
    sys.exit(subprocess.call([py, os.path.abspath(script)] + sys.argv[1:]))
