"""`seqsmooth.kalman_frame` against the Rust `KalmanBank` doing the same work: 10^4 series x
10^3 unit steps, constant velocity with white-noise driving (q = 0.01), the position observed
(r = 1), the filter (and the filter + RTS smoother). The Rust side is
`target/release/examples/bank_peers` (crates/seqsmooth/examples/bank_peers.rs) on the same data;
the Python side a pandas frame (`id`, `t`, `y`) through `kalman_frame`, best of REPS, each
call into new arrays as the Rust side's `filter` / `smooth` into new buffers. Prints the best
wall time of each and, beside it, the best CPU time of the process (every thread, user +
system: the bank runs on two threads), the steadier figure on a shared machine.

    target/py-venv/bin/python crates/seqsmooth-py/bench/kalman_frame.py [SERIES STEPS REPS]
"""

import os
import subprocess
import sys
import time

import numpy as np
import pandas as pd

import seqsmooth

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
series, steps, reps = (int(a) for a in (sys.argv[1:] + ["10000", "1000", "3"])[:3])
Q, R, P0 = 0.01, 1.0, 100.0
rng = np.random.default_rng(33)
t = np.tile(np.arange(steps, dtype=float), (series, 1))
z = rng.uniform(-2.0, 2.0, (series, 1)) * t + rng.standard_normal((series, steps))
d = os.path.join(ROOT, "target", "peers-bank")
os.makedirs(d, exist_ok=True)
with open(os.path.join(d, "bank.txt"), "w") as f:
    f.write(f"{series} {steps} {Q!r} {R!r} {P0!r}\n")
t.astype("<f8").tofile(os.path.join(d, "bank.t.f64"))
z.astype("<f8").tofile(os.path.join(d, "bank.z.f64"))
exe = os.path.join(ROOT, "target", "release", "examples", "bank_peers")
res = subprocess.run([exe, d, str(reps)], check=True, capture_output=True, text=True)
rust = {k: float(v) for k, v in (line.split(",") for line in res.stdout.split())}
rows = pd.DataFrame({"id": np.repeat(np.arange(series), steps), "t": t.ravel(), "y": z.ravel()})
settings = dict(by="id", degree=1, P0=P0, R=R, q=Q)
filtered = np.fromfile(os.path.join(d, "bank.filtered.f64"), "<f8").reshape(-1, 2)
for name, smoother, rust_name in [
    ("filter", "filter", "filter"),
    ("filter + RTS", "rts", "filter+rts"),
]:
    best = best_cpu = np.inf
    for _ in range(reps):
        start, start_cpu = time.perf_counter(), time.process_time()
        out = seqsmooth.kalman_frame(rows, smoother=smoother, **settings)
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - start_cpu)
    if smoother == "filter":
        assert np.array_equal(out[["d0", "d1"]].to_numpy(), filtered)
    print(
        f"{name}: kalman_frame {best:.3f} s, Rust KalmanBank {rust[rust_name]:.3f} s, "
        f"ratio {best / rust[rust_name]:.2f}x ({series * steps / best:.3e} updates/s); "
        f"CPU {best_cpu:.3f} s against {rust['cpu:' + rust_name]:.3f} s, "
        f"ratio {best_cpu / rust['cpu:' + rust_name]:.2f}x"
    )
