"""Ctrl-C stops a long update_many: a child process filtering 10⁸ samples gets SIGINT and
raises KeyboardInterrupt within a second, the samples before the interrupted block taken."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

CHILD = r"""
import sys, numpy as np, seqsmooth
n = 100_000_000
t = np.arange(n, dtype=np.float64)
y = np.zeros(n)
f = seqsmooth.FadingMemory(degree=2, theta=0.9, engine="exact")
print("ready", flush=True)
try:
    f.update_many(t, y)
    print("finished", flush=True)
except KeyboardInterrupt:
    print(f"interrupted {f.samples}", flush=True)
"""


def test_ctrl_c_stops_update_many():
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    line = child.stdout.readline().strip()
    waited = time.monotonic() - sent
    child.wait(timeout=30)
    assert line.startswith("interrupted"), line
    samples = int(line.split()[1])
    assert 0 < samples < 100_000_000 and samples % 65_536 == 0
    assert waited < 1.0, waited
