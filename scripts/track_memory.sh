#!/usr/bin/env bash
# Wall time and peak resident memory of `seqsmooth track`, standard input to standard output.
#
# The input is generated on the fly by awk and piped in (nothing is kept on disk): the
# straight pass of benches/track_cli.rs (from (20, -15, 3) km at (-40, 25, -1) m/s, seen from
# the origin at steps U(0.05, 0.15) s, range noise sigma 10 m, angle noise 1 mrad by
# Box-Muller; awk's srand(1), so the same digits for the same awk), columns
# t,range,azimuth,elevation. The output goes to /dev/null. Prints, per method, the rows, the
# wall time (generation included: awk writes about 5e5 rows/s, slower than the filters, so the
# wall is awk's for kalman and fading), rows/s and the peak resident set size of seqsmooth.
#
# Usage: scripts/track_memory.sh [ROWS] [METHOD...]
#   ROWS defaults to 200000; METHODs (kalman, fading, smooth, window) default to
#   kalman fading smooth.
# Builds the release binary first (CARGO_TARGET_DIR is honoured).
set -euo pipefail
cd "$(dirname "$0")/.."

rows=${1:-200000}
shift || true
methods=("$@")
[ ${#methods[@]} -eq 0 ] && methods=(kalman fading smooth)
cargo build --release -q -p seqsmooth-cli
bin="${CARGO_TARGET_DIR:-target}/release/seqsmooth"

generate() {
    awk -v n="$rows" 'BEGIN {
        srand(1);
        print "t,range,azimuth,elevation";
        t = 0;
        for (i = 0; i < n; i++) {
            x = 2e4 - 40 * t; y = -1.5e4 + 25 * t; z = 3e3 - t;
            u = 1 - rand(); v = rand(); w = 1 - rand(); s = rand();
            g1 = sqrt(-2 * log(u)) * cos(6.283185307179586 * v);
            g2 = sqrt(-2 * log(u)) * sin(6.283185307179586 * v);
            g3 = sqrt(-2 * log(w)) * cos(6.283185307179586 * s);
            r = sqrt(x * x + y * y + z * z) + 10 * g1;
            printf "%.17g,%.17g,%.17g,%.17g\n", t, r, atan2(y, x) + 1e-3 * g2,
                atan2(z, sqrt(x * x + y * y)) + 1e-3 * g3;
            t += 0.05 + 0.1 * rand();
        }
    }'
}

settings() {
    case $1 in
        kalman) echo "--method kalman --q 1" ;;
        fading) echo "--method fading --beta 0.9" ;;
        smooth) echo "--method smooth --q 1" ;;
        window) echo "--method window --window 60" ;;
        *) echo "unknown method $1" >&2; exit 2 ;;
    esac
}

echo "seqsmooth track, $rows rows from standard input to /dev/null"
for m in "${methods[@]}"; do
    log=$(mktemp)
    # shellcheck disable=SC2046
    if ! generate | /usr/bin/time -f "%e %M" -o "$log" "$bin" track $(settings "$m") \
        --sigma-range 10 --sigma-angle 1e-3 > /dev/null; then
        cat "$log" >&2
        exit 1
    fi
    read -r wall kb < "$log"
    rm -f "$log"
    awk -v m="$m" -v n="$rows" -v w="$wall" -v kb="$kb" 'BEGIN {
        printf "%-8s %10d rows  %7.2f s  %9.3g rows/s  max RSS %8.1f MB\n", m, n, w, n / w, kb / 1024
    }'
done
