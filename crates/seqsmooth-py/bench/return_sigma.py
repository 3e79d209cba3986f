"""`update_many(t, y, return_sigma=True)` against `update_many(t, y)` on 10⁷ unit-step samples
(BENCHMARKS.md, "The batch σ path"): each filter constructed with a noise ``sigma`` (the plain
call then also keeps its covariance), degree 2 (or ``--degree M``), best of 2 calls on fresh
filters (or ``--repeat K``), in seconds of wall time and of the calling thread's CPU time (the
figure that a busy machine disturbs least), and their ratios; ``--exact`` runs the exact
engine's filters only; ``--out`` gives each call an ``out=`` array made (and written) once
before the timed calls, so that the new memory's page faults and clearing are left out of both
figures; ``--no-huge-pages`` turns transparent huge pages off for the process (Linux
``prctl(PR_SET_THP_DISABLE)``), so that new arrays are cleared 4 KiB at a time. Run in
target/py-venv after installing the package:

    target/py-venv/bin/python crates/seqsmooth-py/bench/return_sigma.py
    target/py-venv/bin/python crates/seqsmooth-py/bench/return_sigma.py --exact --degree 8
    target/py-venv/bin/python crates/seqsmooth-py/bench/return_sigma.py --exact --degree 8 --out
"""

from __future__ import annotations

import argparse
import ctypes
import time

import numpy as np

import seqsmooth as ss

N = 10_000_000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--degree", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--exact", action="store_true", help="the exact engine's filters only")
    parser.add_argument("--out", action="store_true", help="reuse one written out= array per path")
    parser.add_argument("--no-huge-pages", action="store_true", help="THP off (Linux prctl)")
    args = parser.parse_args()
    if args.no_huge_pages and ctypes.CDLL(None).prctl(41, 1, 0, 0, 0) != 0:  # PR_SET_THP_DISABLE
        raise SystemExit("prctl(PR_SET_THP_DISABLE) failed")
    m = args.degree
    rng = np.random.default_rng(1)
    t = np.arange(N, dtype=np.float64)
    y = 10 * np.sin(t * 1e-3) + rng.uniform(-0.5, 0.5, N)
    makers = {
        "fading gain": lambda: ss.FadingMemory(m, 0.9, 1.0, engine="gain", sigma=0.3),
        "fading exact": lambda: ss.FadingMemory(m, 0.9, 1.0, engine="exact", sigma=0.3),
        "expanding gain": lambda: ss.ExpandingMemory(m, engine="gain", sigma=0.3),
        "expanding exact": lambda: ss.ExpandingMemory(m, engine="exact", sigma=0.3),
        "fixed adaptive W=21": lambda: ss.FixedMemory(m, 21, sigma=0.3),
    }
    if args.exact:
        makers = {name: make for name, make in makers.items() if name.endswith("exact")}
    buffers = {s: np.ones((N, (m + 1) * (1 + s))) if args.out else None for s in (False, True)}
    pages = ", out= arrays written before timing" if args.out else ""
    pages += ", no huge pages" if args.no_huge_pages else ""
    print(f"degree {m}, {N} samples, best of {args.repeat}{pages}", flush=True)
    for name, make in makers.items():
        wall, cpu = {}, {}
        for sigma in (False, True):
            wall[sigma] = cpu[sigma] = float("inf")
            for _ in range(args.repeat):
                f = make()
                start, start_cpu = time.perf_counter(), time.thread_time()
                f.update_many(t, y, return_sigma=sigma, out=buffers[sigma])
                wall[sigma] = min(wall[sigma], time.perf_counter() - start)
                cpu[sigma] = min(cpu[sigma], time.thread_time() - start_cpu)
        print(
            f"{name:20s} plain {wall[False]:.3f} s  return_sigma {wall[True]:.3f} s  "
            f"ratio {wall[True] / wall[False]:.2f}  |  CPU {cpu[False]:.3f} s  {cpu[True]:.3f} s  "
            f"ratio {cpu[True] / cpu[False]:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
