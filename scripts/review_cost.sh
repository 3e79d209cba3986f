#!/usr/bin/env bash
# The automatic filter's review (its final outlier decision by interpolation) in
# instructions (valgrind's callgrind: repeatable whatever else the machine runs):
# `seqsmooth filter --kind auto` with the review (the default, --review-window M+4) and
# without it (--review-window 0), for BENCHMARKS.md.
# Usage: bash scripts/review_cost.sh   (builds the release binary first)
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib_callgrind.sh
. scripts/lib_callgrind.sh
cargo build --release -q -p seqsmooth-cli
bin=target/release/seqsmooth
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
landing=crates/seqsmooth/tests/data/landing.csv
# The 6,070-row 100 Hz series of scripts/gain_vs_exact.sh.
make_acc "$work/acc.csv"
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
