#!/usr/bin/env bash
# CPU and wall time of `seqsmooth filter --kind auto` against `--kind fading` (with and without
# --sigma) on ROWS rows of one series, for BENCHMARKS.md ("The automatic filter's speed").
#
# The input (a noisy manoeuvring track: steps 1 s ± 40%, σ = 10 m, 2% outliers of 5-10σ) is
# written once to a temporary file, so that every run reads the same bytes; the output goes to
# /dev/null. Prints each command's CPU time (user + sys), wall time, peak RSS and its CPU time's
# ratio to the fading filter's with σ.
#
# Usage: scripts/auto_speed.sh [ROWS]     (default 10000000; builds the release binary first)
# With AUTO_SPEED_INPUT=PATH the input is also copied to PATH (for callgrind on its first rows).
set -euo pipefail
cd "$(dirname "$0")/.."
rows=${1:-10000000}
cargo build --release -q -p seqsmooth-cli
bin="${CARGO_TARGET_DIR:-target}/release/seqsmooth"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
awk -v n="$rows" 'BEGIN {
    srand(7); print "t,y"; t = 0; x = 0; v = 50; a = 0; next_t = 100;
    for (i = 0; i < n; i++) {
        dt = 1 + 0.4 * (2 * rand() - 1); x += v * dt + 0.5 * a * dt * dt; v += a * dt; t += dt;
        if (t > next_t) { a = 6 * rand() - 3; next_t += 40 + 120 * rand() }
        if (v > 400 || v < -400) a = -a;
        e = 10 * sqrt(-2 * log(1 - rand())) * cos(6.283185307179586 * rand());
        if (rand() < 0.02) e += (rand() < 0.5 ? -1 : 1) * (50 + 50 * rand());
        printf "%.4f,%.4f\n", t, x + e
    }
}' > "$work/in.csv"
if [ -n "${AUTO_SPEED_INPUT:-}" ]; then cp "$work/in.csv" "$AUTO_SPEED_INPUT"; fi
run() {
    local label=$1; shift
    /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$bin" filter "$work/in.csv" "$@" > /dev/null
    read -r secs user sys kb < "$work/time"
    echo "$label $secs $(echo "$user + $sys" | bc -l) $kb"
}
# CPU time (user + sys) is the measure on a shared machine; wall time as well. Ratios are to the
# fading filter with its σ (`--sigma 10`), CPU against CPU.
base=$(run fading --kind fading --degree 2 --theta 0.95 --sigma 10 | awk '{print $3}')
printf '| command (%s rows) | CPU s | wall s | peak RSS MB | ÷ fading with σ (CPU) |\n|---|---:|---:|---:|---:|\n' "$rows"
for args in "--kind fading --degree 2 --theta 0.95" \
            "--kind fading --degree 2 --theta 0.95 --sigma 10" \
            "--kind auto --degree 2 --theta 0.95"; do
    # shellcheck disable=SC2086
    read -r _ secs cpu kb <<< "$(run x $args)"
    printf '| `seqsmooth filter in.csv %s` | %.2f | %s | %.0f | %.1f |\n' "$args" "$cpu" "$secs" \
        "$(echo "$kb / 1024" | bc -l)" "$(echo "$cpu / $base" | bc -l)"
done
