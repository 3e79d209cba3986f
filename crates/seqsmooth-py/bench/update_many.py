"""Times the Python package against the Rust library and filterpy (BENCHMARKS.md, "Python").

Run through scripts/py_bench.sh, which first runs the criterion group `one_call` of
crates/seqsmooth/benches/bank.rs (the Rust figure: a fresh degree-2 filter given 10⁶
unit-step samples in one `update_many_into` call) and then this script in target/py-venv:

- `update_many` of the same filters on 10⁶ samples from numpy (float64, contiguous): best of
  REPEATS calls, each on a fresh filter, in samples/s;
- `filter_frame` on 10⁴ series × 10³ samples (a pandas DataFrame, integer ids, the rows
  interleaved as in the Rust bench `one_call/stream_fading_exact_10000x1000/2`): best of 3;
- filterpy 2.0.0's `FadingMemoryFilter` (order 2, beta 0.9) fed the same samples one
  `update` at a time (the way its users run it), on the first PEER_SAMPLES samples: best of 3;
  and the ratio of the two fading-memory rates.

Prints one line per figure: `name<TAB>samples/s`.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd
from filterpy.memory import FadingMemoryFilter

import seqsmooth as ss

LEN = 1_000_000
REPEATS = 7
PEER_SAMPLES = 100_000


def best_rate(make, t, y, repeats=REPEATS):
    best = float("inf")
    for _ in range(repeats):
        f = make()
        start = time.perf_counter()
        f.update_many(t, y)
        best = min(best, time.perf_counter() - start)
    return len(t) / best


def main() -> None:
    rng = np.random.default_rng(20261204)
    t = np.arange(LEN, dtype=np.float64)
    y = 10.0 * np.sin(t * 1e-3) + rng.uniform(-0.5, 0.5, LEN)
    rates = {
        "python/fading_gain_update_many/2": best_rate(
            lambda: ss.FadingMemory(degree=2, theta=0.9, tau=1.0, engine="gain"), t, y
        ),
        "python/fading_exact_update_many/2": best_rate(
            lambda: ss.FadingMemory(degree=2, theta=0.9, tau=1.0, engine="exact"), t, y
        ),
        "python/expanding_gain_update_many/2": best_rate(
            lambda: ss.ExpandingMemory(degree=2, engine="gain"), t, y
        ),
    }
    # filter_frame on 10⁴ series × 10³ samples, interleaved as in the Rust bench, from a
    # pandas DataFrame with integer ids (best of 3).
    series, each = 10_000, 1_000
    rows = series * each
    ids = np.tile(np.arange(series), each)
    times = np.repeat(np.arange(each, dtype=np.float64), series) + ids * 1e-3
    frame = pd.DataFrame({"id": ids, "t": times, "y": rng.standard_normal(rows)})
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        ss.filter_frame(frame, by="id", kind="fading", degree=2, theta=0.9, tau=1.0)
        best = min(best, time.perf_counter() - start)
    rates["python/filter_frame_fading_exact_10000x1000/2"] = rows / best
    del frame
    best = float("inf")
    for _ in range(3):
        f = FadingMemoryFilter(x0=np.zeros(3), dt=1.0, order=2, beta=0.9)
        start = time.perf_counter()
        for z in y[:PEER_SAMPLES]:
            f.update(z)
        best = min(best, time.perf_counter() - start)
    rates["filterpy/FadingMemoryFilter.update/2"] = PEER_SAMPLES / best
    for name, rate in rates.items():
        print(f"{name}\t{rate:.3e}")
    ratio = (
        rates["python/fading_gain_update_many/2"] / rates["filterpy/FadingMemoryFilter.update/2"]
    )
    print(f"ratio fading update_many / filterpy\t{ratio:.0f}")


if __name__ == "__main__":
    main()
