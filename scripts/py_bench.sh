#!/usr/bin/env bash
# The Python package's speed against the Rust library and filterpy, in one run (BENCHMARKS.md,
# "Python"): the criterion group `one_call` (crates/seqsmooth/benches/bank.rs), then
# crates/seqsmooth-py/bench/update_many.py in target/py-venv (made by scripts/test.sh; the
# package is rebuilt and installed first). About 2 minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/py-venv
if [ ! -x "$venv/bin/python" ]; then
    echo "no $venv: run scripts/test.sh once first" >&2
    exit 1
fi
export PATH="$PWD/$venv/bin:$PATH"
"$venv/bin/python" -m pip install --quiet --no-build-isolation --force-reinstall --no-deps \
    ./crates/seqsmooth-py
cargo bench -p seqsmooth --bench bank -- one_call 2>&1 | grep -E "^one_call|thrpt"
"$venv/bin/python" crates/seqsmooth-py/bench/update_many.py
