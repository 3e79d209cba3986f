#!/usr/bin/env bash
# Installs a wheel of the Python package into a new virtual environment with no Rust toolchain
# on PATH and runs the README's Python quick start there (the ```python block under "## Python
# quick start", read from README.md, not a copy); prints the installed wheel's platform tag.
#
# Usage: scripts/wheel_test.sh WHEEL     (scripts/wheel.sh makes one; scripts/test.sh runs both)
#
# Everything runs under `env -i` with PATH = the new environment's bin, /usr/bin and /bin:
# no ~/.cargo/bin, no CARGO_* or RUSTUP_* variables; HOME is kept so pip can use its cache.
# numpy comes from the index as a wheel (--only-binary :all:: nothing is compiled).
set -euo pipefail
cd "$(dirname "$0")/.."

wheel=$(realpath "$1")
python=$(python3 -c 'import sys; print(sys.executable)')
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
venv="$tmp/venv"
clean=(env -i HOME="$HOME" LANG=C.UTF-8 PATH="$venv/bin:/usr/bin:/bin")

"${clean[@]}" "$python" -m venv "$venv"
for tool in cargo rustc rustup maturin; do
    if "${clean[@]}" sh -c "command -v $tool" >/dev/null; then
        echo "wheel_test.sh: $tool is on the clean PATH" >&2
        exit 1
    fi
done
"${clean[@]}" pip install --quiet --disable-pip-version-check --only-binary :all: "$wheel"

awk '/^## Python quick start/ { section = 1 }
     section && /^```python/ { block = 1; next }
     block && /^```/ { exit }
     block { print }' README.md >"$tmp/quick_start.py"
if [ ! -s "$tmp/quick_start.py" ]; then
    echo "wheel_test.sh: no python block under README.md's '## Python quick start'" >&2
    exit 1
fi
cat >"$tmp/check.py" <<'PY'
import importlib.metadata
import sys

import seqsmooth

# The package imported is the installed wheel, not a source tree.
assert seqsmooth.__file__.startswith(sys.prefix), seqsmooth.__file__
wheel = importlib.metadata.distribution("seqsmooth").read_text("WHEEL")
tags = [line.split(": ", 1)[1] for line in wheel.splitlines() if line.startswith("Tag: ")]
print(f"wheel platform tag: {', '.join(tags)} (seqsmooth {seqsmooth.__version__})")
PY
(
    cd "$tmp"
    "${clean[@]}" python quick_start.py
    "${clean[@]}" python check.py
)
echo "wheel test: README quick start ran from $(basename "$wheel") without Rust on PATH"
