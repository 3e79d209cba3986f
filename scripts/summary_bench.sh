#!/usr/bin/env bash
# The benchmarks behind BENCHMARKS.md's summary table, for an earlier commit and the working
# tree in one run: the earlier commit's criterion benches first (saved as baseline `before`),
# then the working tree's, each compared with its own, and a table of the two and their ratio.
#
#   bash scripts/summary_bench.sh BEFORE_COMMIT      # ≈ 12 min on the 2-vCPU VM (measured)
#
# BEFORE_TARGET (default: a fresh target/ beside the earlier commit's worktree) is the cargo
# target directory of the earlier build; seed it with a copy of target/ to skip building the
# dependencies again. The table goes to standard output; criterion's own report to stderr.
set -euo pipefail
before=${1:?usage: summary_bench.sh BEFORE_COMMIT}
root=$(git rev-parse --show-toplevel)
work=$(mktemp -d)
git -C "$root" worktree add -q --detach "$work/before" "$before"
trap 'git -C "$root" worktree remove --force "$work/before"; rm -rf "$work"' EXIT
export CRITERION_HOME="$work/criterion"
before_target=${BEFORE_TARGET:-$work/before/target}

# crate, bench, criterion filter (a regular expression over the benchmark ids)
benches=(
  "seqsmooth bank ^single_stream/(fading_gain_many|fading_gain|fading_exact|expanding_exact)/2$"
  "seqsmooth bank ^bank/"
  "seqsmooth fixed_memory ^sliding_update/"
  "seqsmooth gauss_newton ^radar60/bootstrap_and_fit$"
  "seqsmooth kalman ."
  "seqsmooth paml ^paml/online_push_all/5$|^paml_fit/"
  "seqsmooth automatic ."
  "seqsmooth batch_sigma /m2/"
  "seqsmooth-cli filter_cli ^filter_cli/(fading_exact|fading_gain)$"
  "seqsmooth-cli track_cli ^track_cli/(kalman|fading)$"
)

run() { # side dir target baseline-flag
  local dir=$2 target=$3 flag=$4
  for b in "${benches[@]}"; do
    read -r krate bench filter <<<"$b"
    (cd "$dir" && CARGO_TARGET_DIR="$target" cargo bench -q -p "$krate" --bench "$bench" \
      -- "$filter" "$flag" before) >&2
  done
}
run before "$work/before" "$before_target" --save-baseline
run after "$root" "${CARGO_TARGET_DIR:-$root/target}" --baseline

python3 - "$CRITERION_HOME" "$before" <<'EOF'
import json, pathlib, sys
home, before = pathlib.Path(sys.argv[1]), sys.argv[2]
def mean(p):
    return json.loads(p.read_text())["mean"]["point_estimate"]
print(f"| benchmark | {before[:7]} (ns) | working tree (ns) | after / before |")
print("|---|---:|---:|---:|")
for b in sorted(home.rglob("before/estimates.json")):
    a = b.parent.parent / "new" / "estimates.json"
    if not a.exists():
        continue
    name = str(b.parent.parent.relative_to(home))
    x, y = mean(b), mean(a)
    print(f"| {name} | {x:,.0f} | {y:,.0f} | {y / x:.3f} |")
EOF
