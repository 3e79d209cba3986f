#!/usr/bin/env bash
# The whole test suite (the README's test command; .ci/run runs it): the Rust workspace and its
# API docs (every warning an error: a broken or ambiguous intra-doc link fails), then the
# Python package, built and installed into its own virtual environment (target/py-venv,
# made from crates/seqsmooth-py/requirements-test.txt on first use), linted and tested with
# pytest against the `seqsmooth` binary built here. The suite runs on the release wheel
# (scripts/wheel.sh: manylinux2014, abi3), which scripts/wheel_test.sh first installs into a
# clean environment with no Rust toolchain on PATH to run the README's Python quick start.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo test --workspace --release
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps
cargo build --release -p seqsmooth-cli

venv=target/py-venv
requirements=crates/seqsmooth-py/requirements-test.txt
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if ! cmp -s "$requirements" "$venv/requirements-test.txt"; then
    "$venv/bin/python" -m pip install --quiet --upgrade pip
    "$venv/bin/python" -m pip install --quiet -r "$requirements"
    cp "$requirements" "$venv/requirements-test.txt"
fi
# The README's install line (pip builds the wheel with maturin from PyPI in an isolated
# environment), then the import it promises.
"$venv/bin/python" -m pip install --quiet --force-reinstall --no-deps ./crates/seqsmooth-py
"$venv/bin/python" -c "import seqsmooth"
# The wheel (its platform tag printed), then the suite on it.
wheel=$(bash scripts/wheel.sh)
bash scripts/wheel_test.sh "$wheel"
"$venv/bin/python" -m pip install --quiet --force-reinstall --no-deps "$wheel"
(
    cd crates/seqsmooth-py
    "../../$venv/bin/ruff" check .
    "../../$venv/bin/ruff" format --check .
    # The scripts that make fixtures and run the peers, under the package's rules.
    "../../$venv/bin/ruff" check --config pyproject.toml ../../scripts
    "../../$venv/bin/ruff" format --check --config pyproject.toml ../../scripts
    SEQSMOOTH_CLI="$PWD/../../target/release/seqsmooth" "../../$venv/bin/python" -m pytest -q
)
