"""`update_many(t, y, return_sigma=True)` against `update_many(t, y)` on 10⁷ unit-step samples
(BENCHMARKS.md, "The batch σ path"): each filter constructed with a noise ``sigma`` (the plain
call then also keeps its covariance), degree 2, best of 2 calls on fresh filters, in seconds,
and the ratio. Run in target/py-venv after installing the package:

    target/py-venv/bin/python crates/seqsmooth-py/bench/return_sigma.py
"""

from __future__ import annotations

import time

import numpy as np

import seqsmooth as ss

N = 10_000_000


def main() -> None:
    rng = np.random.default_rng(1)
    t = np.arange(N, dtype=np.float64)
    y = 10 * np.sin(t * 1e-3) + rng.uniform(-0.5, 0.5, N)
    makers = {
        "fading gain": lambda: ss.FadingMemory(2, 0.9, 1.0, engine="gain", sigma=0.3),
        "fading exact": lambda: ss.FadingMemory(2, 0.9, 1.0, engine="exact", sigma=0.3),
        "expanding gain": lambda: ss.ExpandingMemory(2, engine="gain", sigma=0.3),
        "expanding exact": lambda: ss.ExpandingMemory(2, engine="exact", sigma=0.3),
        "fixed adaptive W=21": lambda: ss.FixedMemory(2, 21, sigma=0.3),
    }
    for name, make in makers.items():
        best = {}
        for sigma in (False, True):
            best[sigma] = float("inf")
            for _ in range(2):
                f = make()
                start = time.perf_counter()
                f.update_many(t, y, return_sigma=sigma)
                best[sigma] = min(best[sigma], time.perf_counter() - start)
        print(
            f"{name:20s} plain {best[False]:.3f} s  return_sigma {best[True]:.3f} s  "
            f"ratio {best[True] / best[False]:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
