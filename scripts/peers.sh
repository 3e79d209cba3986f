#!/usr/bin/env bash
# Peer comparison (filterpy, scipy; scipy.optimize.least_squares for the radar Gauss–Newton fit;
# simdkalman and pykalman for the Kalman bank, scripts/peers_bank.py)
# in one command: builds the Rust side (release), then runs
# scripts/peers.py, which creates its own virtual environment (target/peers-venv, pinned
# filterpy/numpy/scipy from PyPI), generates the data, runs and times both sides, checks that
# their estimates agree and prints the table. Exits non-zero on any disagreement.
#
#   bash scripts/peers.sh            # full run: 10^6 even samples, 10^5 for the Kalman pairs,
#                                    # 400 radar windows for the Gauss–Newton fit
#   bash scripts/peers.sh --quick    # smoke run (50 radar windows)
#
# Needs python3 (3.11+, with the venv module) and network access to PyPI on the first run.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
cargo build --release --quiet -p seqsmooth --example peers --example bank_peers
cargo build --release --quiet -p seqsmooth-cli
if [ "$CARGO_TARGET_DIR" != "$PWD/target" ]; then
    mkdir -p target/release/examples
    ln -sf "$CARGO_TARGET_DIR/release/examples/peers" target/release/examples/peers
    ln -sf "$CARGO_TARGET_DIR/release/examples/bank_peers" target/release/examples/bank_peers
    ln -sf "$CARGO_TARGET_DIR/release/seqsmooth" target/release/seqsmooth
fi
python3 scripts/peers.py "$@"
if [ "${1:-}" = "--quick" ]; then
    exec python3 scripts/peers_bank.py --series 1000 --steps 200 --reps 1
fi
exec python3 scripts/peers_bank.py
