#!/usr/bin/env bash
# The automatic filter's review (its final outlier decision by interpolation) in
# instructions (valgrind's callgrind: repeatable whatever else the machine runs):
# `seqsmooth filter --kind auto` with the review (the default, --review-window M+4) and
# without it (--review-window 0), for BENCHMARKS.md.
# Usage: bash scripts/review_cost.sh   (builds the release binary first)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p seqsmooth-cli
bin=target/release/seqsmooth
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
landing=crates/seqsmooth/tests/data/landing.csv
# The 6,070-row 100 Hz series of scripts/gain_vs_exact.sh.
python3 - "$work/acc.csv" <<'PY'
import math, random, sys
random.seed(1)
with open(sys.argv[1], "w") as f:
    f.write("t,y\n")
    for i in range(6070):
        s = i * 0.01
        f.write(f"{1.7e9 + s:.2f},{9.81 + 2 * math.sin(3 * s) + 0.5 * math.sin(17 * s) + random.gauss(0, 0.05)}\n")
PY
ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$@" 2>&1 >/dev/null | sed -n 's/.*Collected : //p'; }
printf '| input | filter | with the review (Ir) | without (Ir) | ratio |\n|---|---|---:|---:|---:|\n'
while read -r name file args; do
  with=$(ir $bin filter "$file" $args)
  without=$(ir $bin filter "$file" $args --review-window 0)
  printf '| %s | %s | %s | %s | %.2f |\n' "$name" "$args" "$with" "$without" "$(echo "$with / $without" | bc -l)"
done <<CASES
landing.csv $landing --kind auto --degree 2 --theta 0.95 --time-col time --value-col east
landing.csv $landing --kind auto --degree 6 --theta 0.95 --time-col time --value-col east
landing.csv $landing --kind auto --degree 10 --theta 0.95 --time-col time --value-col east
acc.csv $work/acc.csv --kind auto --degree 2 --theta 0.95
CASES
