#!/usr/bin/env bash
# The gain engine's cost against the exact engine's on the same input, in instructions
# (valgrind's callgrind: repeatable whatever else the machine runs), for the cases of
# RELIABILITY.md ("gain engine no more than 10x slower than exact").
# Usage: bash scripts/gain_vs_exact.sh   (builds the release binary first)
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib_callgrind.sh
. scripts/lib_callgrind.sh
cargo build --release -q -p seqsmooth-cli
bin=target/release/seqsmooth
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
landing=crates/seqsmooth/tests/data/landing.csv
head -61 "$landing" > "$work/l60.csv"
# A 6,070-row 100 Hz series at Unix-time seconds (an accelerometer-like log).
make_acc "$work/acc.csv"
printf '| input | filter | gain (Ir) | exact (Ir) | gain/exact |\n|---|---|---:|---:|---:|\n'
while read -r name file args; do
  g=$(ir $bin filter "$file" $args --engine gain)
  x=$(ir $bin filter "$file" $args --engine exact)
  printf '| %s | %s | %s | %s | %.2f |\n' "$name" "$args" "$g" "$x" "$(echo "$g / $x" | bc -l)"
done <<CASES
landing.csv $landing --kind fading --degree 2 --theta 0.9 --time-col time --value-col east
landing.csv $landing --kind fading --degree 6 --theta 0.9 --time-col time --value-col east
landing.csv $landing --kind fading --degree 10 --theta 0.9 --time-col time --value-col east
landing.csv $landing --kind expanding --degree 10 --time-col time --value-col east
landing.csv $landing --kind auto --degree 2 --theta 0.95 --time-col time --value-col east
landing.csv $landing --kind auto --degree 6 --theta 0.95 --time-col time --value-col east
landing.csv $landing --kind auto --degree 10 --theta 0.95 --time-col time --value-col east
landing.csv[:60] $work/l60.csv --kind auto --degree 10 --theta 0.95 --time-col time --value-col east
acc.csv $work/acc.csv --kind auto --degree 2 --theta 0.95
acc.csv $work/acc.csv --kind auto --degree 6 --theta 0.95
acc.csv $work/acc.csv --kind auto --degree 10 --theta 0.95
CASES
