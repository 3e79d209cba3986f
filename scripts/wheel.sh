#!/usr/bin/env bash
# Builds the Python package's wheel for any Linux x86_64 with glibc >= 2.17 (manylinux2014,
# abi3: one wheel for CPython >= 3.9) and checks it; prints the wheel's path on the last line.
#
# Usage: scripts/wheel.sh [OUT_DIR]     (default target/wheels; the wheels there are replaced)
#
# A wheel linked on this machine needs the glibc it was linked against (2.35-2.36 here: Rust's
# std takes pthread_* at GLIBC_2.34, libm's hypot at GLIBC_2.35). Zig, installed from PyPI
# (ziglang) into the tools' environment target/wheel-venv, links against glibc 2.17's symbol
# versions instead, the oldest Rust's std supports on x86_64-unknown-linux-gnu, so no old
# sysroot or container is needed. The tag is then checked two ways: `auditwheel show` must
# accept manylinux_2_17, and the newest GLIBC_ version the extension imports (objdump -T) must
# be at most 2.17. The build goes to target/x86_64-unknown-linux-gnu (maturin names the
# target for zig), apart from the host build in target/release.
set -euo pipefail
cd "$(dirname "$0")/.."

out=${1:-target/wheels}
tools=target/wheel-venv
requirements=crates/seqsmooth-py/requirements-wheel.txt
if [ ! -x "$tools/bin/python" ]; then
    python3 -m venv "$tools"
fi
if ! cmp -s "$requirements" "$tools/requirements-wheel.txt"; then
    "$tools/bin/python" -m pip install --quiet -r "$requirements"
    cp "$requirements" "$tools/requirements-wheel.txt"
fi

mkdir -p "$out"
rm -f "$out"/seqsmooth-*.whl
# maturin finds zig (python -m ziglang) through the tools' environment on PATH.
PATH="$PWD/$tools/bin:$PATH" maturin build --quiet --release --zig --compatibility manylinux2014 \
    --manifest-path crates/seqsmooth-py/Cargo.toml --out "$out" >&2
wheel=$(ls "$out"/seqsmooth-*.whl)

# What the extension actually imports from glibc: the newest GLIBC_x.y among its dynamic symbols.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$tools/bin/python" -m zipfile -e "$wheel" "$tmp"
newest=$(objdump -T "$tmp"/seqsmooth/_seqsmooth*.so | grep -o 'GLIBC_[0-9.]*' | sort -uV | tail -1)
echo "newest glibc symbol version imported: $newest" >&2
if [ "$(printf '%s\n' "$newest" GLIBC_2.17 | sort -V | tail -1)" != GLIBC_2.17 ]; then
    echo "wheel.sh: the extension needs $newest, newer than manylinux2014's GLIBC_2.17" >&2
    exit 1
fi
"$tools/bin/auditwheel" show "$wheel" >"$tmp/show.txt"
cat "$tmp/show.txt" >&2
if ! tr -s ' \n' ' ' <"$tmp/show.txt" | grep -q 'consistent with the following platform tag: "manylinux_2_17_x86_64"'; then
    echo "wheel.sh: auditwheel does not accept manylinux_2_17_x86_64" >&2
    exit 1
fi
echo "$wheel"
