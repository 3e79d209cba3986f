#!/usr/bin/env bash
# Peak resident memory of `seqsmooth filter` streaming standard input to standard output, for
# one series and for --id-col with many series: the filter cases of scripts/peak_memory.sh
# (which generates the rows with awk, pipes them in and measures with /usr/bin/time).
#
# Usage: scripts/cli_memory.sh [ROWS] [SERIES]     (defaults: 10000000 rows, 1000 series)
set -euo pipefail
cd "$(dirname "$0")/.."
SERIES=${2:-1000} exec scripts/peak_memory.sh "${1:-10000000}" \
    filter-fading filter-expanding filter-series filter-series-auto
