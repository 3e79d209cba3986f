#!/usr/bin/env bash
# Peak resident memory of the streaming Kalman bank (kalman::bank::BankStream) on SERIES
# series (default 10^6) at two numbers of steps (default 20 and 200): if the stream holds
# memory in proportion to the series and not to the steps, the two peaks are the same.
# Each run under /usr/bin/time (its "maximum resident set size"), as scripts/peak_memory.sh.
#
# Usage: scripts/bank_memory.sh [SERIES] [STEPS...]
set -euo pipefail
cd "$(dirname "$0")/.."
series=${1:-1000000}
shift || true
steps=("$@")
[ ${#steps[@]} -eq 0 ] && steps=(20 200)
cargo build --release -q -p seqsmooth --example bank_stream_memory
bin="${CARGO_TARGET_DIR:-target}/release/examples/bank_stream_memory"
for k in "${steps[@]}"; do
    log=$(mktemp)
    start=$(date +%s.%N)
    /usr/bin/time -v "$bin" "$series" "$k" 2>"$log" >"$log.out"
    end=$(date +%s.%N)
    kb=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$log")
    printf '%s series, %s steps: peak %.1f MB, %.1f s (%s)\n' "$series" "$k" \
        "$(echo "$kb / 1024" | bc -l)" "$(echo "$end - $start" | bc -l)" "$(cat "$log.out")"
    rm -f "$log" "$log.out"
done
