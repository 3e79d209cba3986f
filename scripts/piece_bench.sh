#!/usr/bin/env bash
# The command's three former hand-written pieces (commit ca7c253: a CSV record splitter, an
# exact decimal float parser, a shortest-round-trip formatter), each ALONE in place of the crate
# it was replaced by, end to end on `seqsmooth filter`:
#
#   base      BASE_REV as it is (csv + fast-float2 + ryu)
#   shortest  base with io::write_f64 through the old shortest.rs formatter
#   decimal   base with the cell parser through the old decimal.rs parser (std fallback)
#   records   base with io::CsvIn over the old records.rs splitter and its line counting
#
# Each variant is BASE_REV exported with `git archive`, the old file copied unchanged from
# ca7c253 and the glue of scripts/piece_bench/<variant>.patch applied (the patches are against
# BASE_REV's io.rs). The script builds `seqsmooth` (release) from each tree into $OUT/bin/,
# generates the inputs, checks every variant's output is byte-identical to base's, then
# measures (a) instructions with callgrind on ROWS_IR rows and (b) wall clock (and the
# process's user+sys CPU) on ROWS_WALL rows, variants interleaved round by round, and prints a
# table (also written to $OUT/results.md). The rule it checks: a hand-written piece stays only
# if it is >= 1.3x faster end to end than the crate.
#
# Run from anywhere inside the repository (all settings optional):
#   bash scripts/piece_bench.sh
#   ROUNDS=15 OUT=/tmp/piece-bench PIECE_TARGET=/path/to/target bash scripts/piece_bench.sh
# SKIP_BUILD=1 reuses the binaries in $OUT/bin; SKIP_IR=1 skips callgrind (the table then
# shows the Ir of $OUT/ir.tsv from the last run). Results: $OUT/results.md, $OUT/raw.tsv
# (every round), $OUT/cg/*.out (callgrind_annotate them for the cost per function).
# Needs git, cargo, python3, valgrind, nm. Wall clock is only meaningful on a quiet machine:
# the command runs a reader thread beside the filtering/formatting (rayon), so on a loaded
# 2-core machine wall depends on who else holds the second core; Ir (deterministic to ~0.3%)
# and CPU (user+sys) are steadier.
set -euo pipefail

REPO=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
OUT=${OUT:-/tmp/piece-bench}
# One target directory for the four builds (the registry crates are built once; each exported
# tree's own crates are rebuilt, since their paths differ).
PIECE_TARGET=${PIECE_TARGET:-$OUT/target}
ROUNDS=${ROUNDS:-9}
ROWS_WALL=${ROWS_WALL:-1000000}
ROWS_IR=${ROWS_IR:-100000}
STEP=0.001

BASE_REV=${BASE_REV:-91b681c}
OLD_REV=ca7c253
VARIANTS=(base shortest decimal records)

# The three commands (options; the input and `-o` are added).
CMDS=(fading_gain fading_exact expanding_gain)
args_of() {
    case $1 in
    fading_gain) echo "--kind fading --degree 2 --theta 0.9 --tau $STEP --engine gain" ;;
    fading_exact) echo "--kind fading --degree 2 --theta 0.9 --tau $STEP --engine exact" ;;
    expanding_gain) echo "--kind expanding --degree 2 --engine gain" ;;
    esac
}

mkdir -p "$OUT"/{bin,src,out,cg}

# 1. Build.
if [[ ${SKIP_BUILD:-0} != 1 ]]; then
    for v in "${VARIANTS[@]}"; do
        rev=$(git -C "$REPO" rev-parse "$BASE_REV^{commit}")
        echo "== build $v (BASE_REV $rev)" >&2
        rm -rf "$OUT/src/$v"
        mkdir -p "$OUT/src/$v"
        git -C "$REPO" archive "$rev" | tar -x -C "$OUT/src/$v"
        if [[ $v != base ]]; then
            git -C "$REPO" show "$OLD_REV:crates/seqsmooth-cli/src/$v.rs" \
                >"$OUT/src/$v/crates/seqsmooth-cli/src/$v.rs"
            git -C "$OUT/src/$v" apply "$REPO/scripts/piece_bench/$v.patch" 2>/dev/null ||
                (cd "$OUT/src/$v" && patch -p1 -s <"$REPO/scripts/piece_bench/$v.patch")
        fi
        # Cargo names a workspace's units independently of its path, so the four trees share
        # fingerprints and the files `git archive` dates at their commit look older than the
        # last build: date them now so that cargo rebuilds (the symbol check below confirms).
        find "$OUT/src/$v" -type f -exec touch {} +
        CARGO_TARGET_DIR=$PIECE_TARGET cargo build --release -q \
            --manifest-path "$OUT/src/$v/Cargo.toml" -p seqsmooth-cli --bin seqsmooth
        cp "$PIECE_TARGET/release/seqsmooth" "$OUT/bin/seqsmooth-$v"
        echo "$rev" >"$OUT/bin/seqsmooth-$v.rev"
    done
fi
# Each binary holds its own piece and no other (and base none).
for v in "${VARIANTS[@]}"; do
    syms=$(nm -C "$OUT/bin/seqsmooth-$v")
    for p in shortest decimal records; do
        has=$(grep -c "seqsmooth_cli::$p::" <<<"$syms" || true)
        want=0 got=0
        [[ $v == "$p" ]] && want=1
        [[ $has -gt 0 ]] && got=1
        if [[ $want != "$got" ]]; then
            echo "error: seqsmooth-$v has $has symbols of seqsmooth_cli::$p (stale build?)" >&2
            exit 1
        fi
    done
done

# 2. Inputs: `t,y`, t = k·STEP, y = sin t + 0.1·(u − 0.5), numbers as Rust's `{}` prints them
# (the shape of crates/seqsmooth-cli/benches/filter_cli.rs's input; Python's RNG, fixed seed).
gen() {
    python3 - "$1" "$STEP" "$2" <<'EOF'
import math, os, random, sys
from decimal import Decimal

def rust(x):
    r = repr(x)
    if 'e' in r:
        r = format(Decimal(r), 'f')
    return r[:-2] if r.endswith('.0') else r

rows, step, out = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
rng = random.Random(0x9E3779B97F4A7C15)
with open(out + '.partial', 'w') as f:
    f.write('t,y\n')
    for k in range(rows):
        t = k * step
        f.write(f'{rust(t)},{rust(math.sin(t) + 0.1 * (rng.random() - 0.5))}\n')
os.replace(out + '.partial', out)
EOF
}
IN_WALL=$OUT/in_$ROWS_WALL.csv
IN_IR=$OUT/in_$ROWS_IR.csv
[[ -f $IN_WALL ]] || gen "$ROWS_WALL" "$IN_WALL"
[[ -f $IN_IR ]] || gen "$ROWS_IR" "$IN_IR"

# 3. Every variant's output byte-identical to base's.
for c in "${CMDS[@]}"; do
    for v in "${VARIANTS[@]}"; do
        # shellcheck disable=SC2046
        "$OUT/bin/seqsmooth-$v" filter $(args_of "$c") "$IN_WALL" -o "$OUT/out/$v.csv"
    done
    for v in "${VARIANTS[@]:1}"; do
        cmp "$OUT/out/base.csv" "$OUT/out/$v.csv"
    done
    echo "== $c: outputs identical ($(wc -l <"$OUT/out/base.csv") lines," \
        "md5 $(md5sum <"$OUT/out/base.csv" | cut -c1-12))" >&2
done
rm -f "$OUT"/out/*.csv

# 4a. Instructions (callgrind; all threads counted), ROWS_IR rows, output to /dev/null.
IR_FILE=$OUT/ir.tsv
if [[ ${SKIP_IR:-0} != 1 ]]; then
    : >"$IR_FILE"
    for c in "${CMDS[@]}"; do
        for v in "${VARIANTS[@]}"; do
            f=$OUT/cg/$c.$v.out
            # shellcheck disable=SC2046
            valgrind --tool=callgrind --callgrind-out-file="$f" -q \
                "$OUT/bin/seqsmooth-$v" filter $(args_of "$c") "$IN_IR" -o /dev/null
            # The totals of every thread's part (callgrind writes one file per thread only
            # with --separate-threads; without it, one file, one "summary:" line).
            ir=$(awk '/^summary:/ {s += $2} END {print s}' "$f"*)
            printf '%s\t%s\t%s\n' "$c" "$v" "$ir" >>"$IR_FILE"
            echo "== Ir $c $v: $ir" >&2
        done
    done
fi

# 4b. Wall clock (and user+sys CPU from wait4), ROWS_WALL rows, output to /dev/null: one
# warm-up run each, then ROUNDS rounds of base, shortest, decimal, records for each command.
# 5. The table.
python3 - "$OUT" "$ROUNDS" "$IN_WALL" "$IR_FILE" "$ROWS_IR" "$ROWS_WALL" "${VARIANTS[*]}" \
    "$(for c in "${CMDS[@]}"; do printf '%s=%s;' "$c" "$(args_of "$c")"; done)" <<'EOF'
import os, statistics, subprocess, sys, time
out, rounds, inp, ir_file, rows_ir, rows_wall, variants, cmds = sys.argv[1:]
rounds, variants = int(rounds), variants.split()
cmds = [c.split('=', 1) for c in cmds.split(';') if c]

def run(v, args):
    argv = [f'{out}/bin/seqsmooth-{v}', 'filter', *args.split(), inp, '-o', '/dev/null']
    t0 = time.perf_counter()
    p = subprocess.Popen(argv)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    assert p.returncode == 0, argv
    return wall, ru.ru_utime + ru.ru_stime

wall = {(c, v): [] for c, _ in cmds for v in variants}
cpu = {(c, v): [] for c, _ in cmds for v in variants}
for c, a in cmds:
    for v in variants:
        run(v, a)
for r in range(rounds):
    for c, a in cmds:
        for v in variants:
            w, u = run(v, a)
            wall[c, v].append(w)
            cpu[c, v].append(u)
    print(f'== wall round {r + 1}/{rounds} done', file=sys.stderr)

ir = {}
if os.path.exists(ir_file):
    for line in open(ir_file):
        c, v, n = line.split()
        ir[c, v] = int(n)

med = statistics.median
lines = [f'rows: Ir on {rows_ir}, wall/CPU on {rows_wall}; {rounds} interleaved rounds; '
         f'load average at the end: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores',
         'v/b = variant/base (below 1: the old piece is faster); speedup = base/variant '
         '(Ir, wall best, wall median, CPU median); CPU = user+sys of the process, all threads',
         '']
for c, a in cmds:
    lines += [f'### {c}: seqsmooth filter {a} IN -o /dev/null', '',
              '| variant | Ir | v/b | wall best s | v/b | wall median s | v/b | CPU best s | '
              'CPU median s | v/b | speedup Ir / wall best / wall median / CPU median |',
              '|---|---|---|---|---|---|---|---|---|---|---|']
    bw, bc = wall[c, 'base'], cpu[c, 'base']
    for v in variants:
        w, u = wall[c, v], cpu[c, v]
        if (c, v) in ir:
            n, b = ir[c, v], ir[c, 'base']
            irc, irs = f'{n:,} | {n / b:.3f}', f'{b / n:.3f}×'
        else:
            irc, irs = '- | -', '-'
        lines.append(
            f'| {v} | {irc} | {min(w):.3f} | {min(w) / min(bw):.3f} | {med(w):.3f} | '
            f'{med(w) / med(bw):.3f} | {min(u):.3f} | {med(u):.3f} | {med(u) / med(bc):.3f} | '
            f'{irs} / {min(bw) / min(w):.3f}× / {med(bw) / med(w):.3f}× / '
            f'{med(bc) / med(u):.3f}× |')
    lines.append('')
text = '\n'.join(lines)
print(text)
open(f'{out}/results.md', 'w').write(text + '\n')
with open(f'{out}/raw.tsv', 'w') as raw:
    raw.write('command\tvariant\tmeasure\tseconds by round\n')
    for (c, v), w in wall.items():
        raw.write('\t'.join([c, v, 'wall', *(f'{x:.4f}' for x in w)]) + '\n')
        raw.write('\t'.join([c, v, 'cpu', *(f'{x:.4f}' for x in cpu[c, v])]) + '\n')
EOF
