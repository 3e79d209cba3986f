"""The private virtual environment the fixture scripts run in (target/savgol-venv, numpy and
scipy): `reexec(script)` re-runs `script` there, creating the environment on first use, and
returns only when already inside it."""

import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "savgol-venv")


def reexec(script):
    if os.path.realpath(sys.prefix) == os.path.realpath(VENV):
        return
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", VENV])
        subprocess.check_call([py, "-m", "pip", "install", "--quiet", "numpy", "scipy"])
    sys.exit(subprocess.call([py, os.path.abspath(script)]))
