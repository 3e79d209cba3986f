#!/usr/bin/env bash
# Peak resident memory of `seqsmooth filter` streaming standard input to standard output.
#
# The input is generated on the fly by awk and piped in (nothing is kept on disk); the output
# goes to /dev/null. Prints the maximum resident set size (VmHWM) of the seqsmooth process, for
# one series and for --id-col with many series.
#
# Usage: scripts/cli_memory.sh [ROWS] [SERIES]     (defaults: 10000000 rows, 1000 series)
# Builds the release binary first (CARGO_TARGET_DIR is honoured).
set -euo pipefail
cd "$(dirname "$0")/.."

rows=${1:-10000000}
series=${2:-1000}
cargo build --release -q -p seqsmooth-cli
bin="${CARGO_TARGET_DIR:-target}/release/seqsmooth"

# Rows "t,y" (one series) or "id,t,y" (SERIES series in turn), a noisy sine.
generate() {
    awk -v n="$rows" -v k="$1" 'BEGIN {
        srand(1);
        if (k == 0) print "t,y"; else print "id,t,y";
        for (i = 0; i < n; i++) {
            if (k == 0) { t = i * 0.01; printf "%.2f,%.17g\n", t, sin(t) + 0.1 * rand() }
            else { s = i % k; t = int(i / k) * 0.01; printf "s%d,%.2f,%.17g\n", s, t, sin(t + s) + 0.1 * rand() }
        }
    }'
}

# Prints LABEL, the peak RSS from KB and the wall time from START to END (seconds).
report() {
    awk -v l="$1" -v kb="$2" -v s="$3" -v e="$4" \
        'BEGIN { printf "%-44s max RSS %7.1f MB   (%.1f s)\n", l, kb / 1024, e - s }'
}

# Runs seqsmooth with the generated input and prints its peak RSS. /usr/bin/time -v when
# present; otherwise VmHWM from /proc, sampled until the process ends.
measure() {
    local label=$1 k=$2
    shift 2
    local start end
    start=$(date +%s.%N)
    if [ -x /usr/bin/time ]; then
        local log
        log=$(mktemp)
        if ! generate "$k" | /usr/bin/time -v "$bin" filter "$@" > /dev/null 2> "$log"; then
            cat "$log" >&2
            exit 1
        fi
        end=$(date +%s.%N)
        local kb
        kb=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$log")
        rm -f "$log"
        report "$label" "$kb" "$start" "$end"
    else
        generate "$k" | "$bin" filter "$@" > /dev/null &
        local pid=$! hwm=0 v
        while kill -0 "$pid" 2> /dev/null; do
            v=$(awk '/VmHWM/ {print $2}' "/proc/$pid/status" 2> /dev/null || true)
            [ -n "$v" ] && hwm=$v
            sleep 0.2
        done
        wait "$pid"
        end=$(date +%s.%N)
        report "$label" "$hwm" "$start" "$end"
    fi
}

echo "seqsmooth filter, $rows rows from standard input to standard output"
measure "one series, fading degree 2" 0 --kind fading --degree 2 --theta 0.9
measure "one series, expanding degree 2" 0 --kind expanding --degree 2
measure "$series series (--id-col), fading degree 2" "$series" \
    --kind fading --degree 2 --theta 0.9 --id-col id
measure "$series series (--id-col), auto degree 2" "$series" \
    --kind auto --degree 2 --theta 0.9 --id-col id
