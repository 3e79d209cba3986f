"""`seqsmooth.kalman_frame` against the Rust `KalmanBank` doing the same work: 10^4 series x
10^3 unit steps, constant velocity with white-noise driving (q = 0.01), the position observed
(r = 1), the filter (and the filter + RTS smoother). The Rust side is
`target/release/examples/bank_peers` (crates/seqsmooth/examples/bank_peers.rs) on the same data;
the Python side a pandas frame (`id`, `t`, `y`) through `kalman_frame`, each call into new
arrays as the Rust side's `filter` / `smooth` into new buffers. The two sides alternate, REPS
rounds of one Rust run then one Python call each, so that a spell of a slow machine (a busy
neighbour, the VM's first touch of pages handed back to its host) falls on both. Prints each
side's best wall time and, beside it, the best CPU time of the process (every thread, user +
system: the bank runs on two threads), the steadier figure on a shared machine, and the
median and range of the rounds' wall-time ratios.

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
rows = pd.DataFrame({"id": np.repeat(np.arange(series), steps), "t": t.ravel(), "y": z.ravel()})
settings = dict(by="id", degree=1, P0=P0, R=R, q=Q)
cases = [("filter", "filter", "filter"), ("filter + RTS", "rts", "filter+rts")]
wall = {name: ([], []) for name, _, _ in cases}  # (Rust, Python) per round
cpu = {name: ([], []) for name, _, _ in cases}
for _ in range(reps):
    res = subprocess.run([exe, d, "1"], check=True, capture_output=True, text=True)
    rust = {k: float(v) for k, v in (line.split(",") for line in res.stdout.split())}
    for name, smoother, rust_name in cases:
        start, start_cpu = time.perf_counter(), time.process_time()
        out = seqsmooth.kalman_frame(rows, smoother=smoother, **settings)
        wall[name][1].append(time.perf_counter() - start)
        cpu[name][1].append(time.process_time() - start_cpu)
        wall[name][0].append(rust[rust_name])
        cpu[name][0].append(rust["cpu:" + rust_name])
        # The Rust run's estimates, written by bank_peers: the same numbers.
        kept = "filtered" if smoother == "filter" else "smoothed"
        rust_state = np.fromfile(os.path.join(d, f"bank.{kept}.f64"), "<f8").reshape(-1, 2)
        assert np.array_equal(out[["d0", "d1"]].to_numpy(), rust_state), name
        del out
for name, _, _ in cases:
    (rw, pw), (rc, pc) = wall[name], cpu[name]
    ratios = sorted(p / r for r, p in zip(rw, pw))
    print(
        f"{name}: kalman_frame {min(pw):.3f} s, Rust KalmanBank {min(rw):.3f} s, "
        f"ratio {min(pw) / min(rw):.2f}x ({series * steps / min(pw):.3e} updates/s); "
        f"CPU {min(pc):.3f} s against {min(rc):.3f} s, ratio {min(pc) / min(rc):.2f}x; "
        f"rounds' wall ratios median {ratios[len(ratios) // 2]:.2f}x "
        f"[{ratios[0]:.2f}, {ratios[-1]:.2f}] over {reps}"
    )
