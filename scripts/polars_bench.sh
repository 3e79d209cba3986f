#!/usr/bin/env bash
# seqsmooth.polars' expression in a lazy streaming query against filter_frame, on one Parquet
# file of ROWS rows of SERIES interleaved series with string ids (BENCHMARKS.md, "Polars
# expressions"): each case in its own process under /usr/bin/time (wall time, peak resident set).
#
# Usage: [IDS=int] [CASES="..."] [PY=python] [TRACE=1] scripts/polars_bench.sh [ROWS] [SERIES]
#        (defaults 10000000 and 100; all cases)
#   IDS=int: integer ids (Int64) instead of strings ("sensor-0042")
#   TRACE=1: each case also prints its resident set every 2 s (to stderr), to see whether
#            it grows with the rows or stays on a plateau
#   copy           pl.scan_parquet → sink_parquet: Polars' own streaming copy of the file, no
#                  filter (the floor of any streaming query over it)
#   filter_frame   pl.read_parquet → seqsmooth.filter_frame(by="id") → write_parquet
#   batches        pl.scan_parquet → ssp.filter_batches(by="id") → ssp.sink_parquet (the
#                  streaming engine's batches through one filter per series)
#   expr-stream    pl.scan_parquet → with_columns(ssp.filter(...).over("id")) → unnest →
#                  sink_parquet (the streaming engine)
#   expr-lazy      the same query, collect() in memory → write_parquet
# Each line: rows, wall time, rows/s, user + system CPU seconds, peak RSS. Settings: fading
# memory, degree 2, θ = 0.9, τ = 1 s, σ = 0.3. Uses target/py-venv (made by scripts/test.sh)
# with the package installed there, or PY.
set -euo pipefail
cd "$(dirname "$0")/.."
rows=${1:-10000000}
series=${2:-100}
py=${PY:-target/py-venv/bin/python}
cases=${CASES:-copy filter_frame batches expr-stream expr-lazy}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$py" - "$tmp/in.parquet" "$rows" "$series" "${IDS:-str}" <<'PY'
import sys

import numpy as np
import polars as pl

path, rows, series, kind = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
rng = np.random.default_rng(1)
ids = rng.integers(0, series, rows)
t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, rows) / series)  # a log sorted by time
y = np.sin(t / 50.0) * 10 + ids + 0.3 * rng.standard_normal(rows)
names = ids if kind == "int" else np.array([f"sensor-{k:04d}" for k in range(series)])[ids]
pl.DataFrame({"id": names, "t": t, "y": y}).write_parquet(path)
PY
echo "input: $rows rows, $series series (${IDS:-str} ids), $(du -m "$tmp/in.parquet" | cut -f1) MB of Parquet"

cat >"$tmp/case.py" <<'PY'
import os
import sys
import threading
import time

import polars as pl

import seqsmooth
import seqsmooth.polars as ssp

case, source, out = sys.argv[1:4]
if os.environ.get("TRACE"):

    def watch():
        start = time.time()
        while True:
            time.sleep(2.0)
            with open("/proc/self/status") as f:
                rss = next(int(line.split()[1]) for line in f if line.startswith("VmRSS"))
            print(f"{case}: {time.time() - start:5.1f} s  RSS {rss // 1024} MB", file=sys.stderr)

    threading.Thread(target=watch, daemon=True).start()
settings = dict(kind="fading", degree=2, theta=0.9, tau=1.0, sigma=0.3)
if case == "copy":
    pl.scan_parquet(source).sink_parquet(out)
elif case == "filter_frame":
    seqsmooth.filter_frame(pl.read_parquet(source), by="id", **settings).write_parquet(out)
elif case == "batches":
    ssp.sink_parquet(ssp.filter_batches(pl.scan_parquet(source), by="id", **settings), out)
else:
    query = (
        pl.scan_parquet(source)
        .with_columns(f=ssp.filter("y", time="t", **settings).over("id"))
        .unnest("f")
    )
    if case == "expr-stream":
        query.sink_parquet(out)
    else:
        query.collect().write_parquet(out)
print(pl.scan_parquet(out).select(pl.len()).collect().item(), end=" ")
PY
for case in $cases; do
    /usr/bin/time -f "%e %U %S %M" -o "$tmp/time" "$py" "$tmp/case.py" "$case" "$tmp/in.parquet" \
        "$tmp/out-$case.parquet" >"$tmp/rows"
    read -r seconds user sys kb <"$tmp/time"
    awk -v c="$case" -v s="$seconds" -v u="$user" -v y="$sys" -v kb="$kb" -v n="$(cat "$tmp/rows")" 'BEGIN {
        printf "%-13s %d rows  %6.1f s  %5.2e rows/s  CPU %6.1f s  peak RSS %5d MB\n", c, n, s, n / s, u + y, kb / 1024 }'
done
"$py" - "$tmp" $cases <<'PY'
import os
import sys

import polars as pl

if not os.path.exists(f"{sys.argv[1]}/out-filter_frame.parquet"):
    sys.exit(0)  # nothing to compare with
a = pl.read_parquet(f"{sys.argv[1]}/out-filter_frame.parquet")
checked = []
for case in sys.argv[2:]:
    if case in ("copy", "filter_frame"):
        continue
    b = pl.read_parquet(f"{sys.argv[1]}/out-{case}.parquet")
    if case == "batches":  # filter_frame's columns; the expression keeps the input's too
        assert a.equals(b), case
    else:
        assert a.equals(b.select(a.columns)), case
    checked.append(case)
print(f"rows equal filter_frame's: {', '.join(checked)}")
PY
