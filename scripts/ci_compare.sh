#!/usr/bin/env bash
# Robustness regression check: runs, with the built harness, the sweep
# configs/ci.toml, the stress suite configs/stress.toml cut to its first
# $stress_poses poses per case, the random-body scene configs/random_bodies.toml
# cut to its first $random_poses poses per case, the smoothing grid
# configs/$smoothing.toml on $smoothing_poses poses, and the first shard of
# configs/paper_table2.toml and configs/uniform_so3.toml, the time-of-impact cut
# configs/ci_toi.toml, and compares each with its checked-in reference
# in results/baseline/ under results/baseline/thresholds.toml (one compare for
# every kind of results file). Exit 1 if a guarded metric regressed in any.
#
# Then the speed guard: instructions per solve counted by callgrind
# (scripts/ci_instructions.sh) against results/baseline/instructions.json.
#
#   scripts/ci_compare.sh              # run and compare (CI)
#   scripts/ci_compare.sh --refresh    # after a deliberate change: rewrite the references
#   scripts/ci_compare.sh --compare-only   # compare the results already in IDCOL_CI_OUT (no run)
#   scripts/ci_compare.sh --help       # this text
#
# Exit 0: every comparison passed; 1: a regression; 2: bad input (a results
# file missing or incomplete, runs that are not comparable) or an unknown
# argument (then nothing runs). Environment:
# IDCOL_BUILD_DIR (default build), IDCOL_CI_OUT (default build/ci; the new
# results and the comparisons land there), IDCOL_CI_REF (the references,
# default results/baseline), IDCOL_CI_CPU (CPU to pin to, default 0),
# IDCOL_CI_INSTRUCTIONS=0 (skip the instruction count).
set -euo pipefail
usage="usage: scripts/ci_compare.sh [--refresh | --compare-only | --help]"
case $# in
  0) ;;
  1) case $1 in
       --refresh | --compare-only) ;;
       -h | --help)
         # The header above, without its '#' marks, is the help.
         sed -n '2,/^set -euo/{/^#/s/^# \{0,1\}//p}' "$0"
         exit 0 ;;
       *) echo "ci_compare.sh: unknown argument '$1' (nothing run); $usage" >&2; exit 2 ;;
     esac ;;
  *) echo "ci_compare.sh: expected at most one argument, got $# (nothing run); $usage" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out="${IDCOL_CI_OUT:-$build/ci}"
cpu="${IDCOL_CI_CPU:-0}"
harness="$build/harness/idcol_harness"
ref="${IDCOL_CI_REF:-results/baseline}"
stress_poses=1000
# The random-body cut: N poses per case, each solved 4 times (cold, warm,
# both again swapped), in 2 parameter ranges: 8 N solves per ordered family
# pair, each checked (witness points on both surfaces, opposite normals). A
# pair failing at rate p shows with probability 1 - (1 - p)^(8 N); p = 1e-4
# at 95% needs (1 - 1e-4)^(8 N) <= 0.05, N >= 3745 (29,960 solves per pair,
# 1.08 million in all). The support-function bracket, the costly oracle,
# runs on every 40th pose (94 per case). Cost: about 170 s of CPU, on both
# cores (harness/README.md, "Sizing the random-body cut").
random_poses=3745
random_oracle_every=40
random_threads=2
smoothing=smoothing_polytope
smoothing_poses=2000
table2_shard=0/100   # 10^4 poses of each of its 3 pairs, every baseline on every pose (about 12 s of CPU)
so3_shard=0/10       # 10^4 poses of each of its 10 pairs, convergence (under a second)
mkdir -p "$out"
pin=(taskset -c "$cpu")
command -v taskset > /dev/null || pin=()

# run_all DIR: writes ci.json, stress.json, random_bodies.json and
# $smoothing.json (with their failure files) into DIR.
run_all() {
  local dir=$1
  "${pin[@]}" "$harness" run configs/ci.toml -o "$dir/ci.json" --failures "$dir/ci.failures.json" --pin "$cpu" --no-progress
  "${pin[@]}" "$harness" stress configs/stress.toml -o "$dir/stress.json" --failures "$dir/stress.failures.json" \
    --max-poses "$stress_poses" --max-failures 20 --no-progress > /dev/null
  # Not pinned: it runs on both cores, and none of its times is guarded.
  "$harness" stress configs/random_bodies.toml -o "$dir/random_bodies.json" --failures "$dir/random_bodies.failures.json" \
    --max-poses "$random_poses" --oracle-every "$random_oracle_every" --threads "$random_threads" --max-failures 20 --no-progress > /dev/null
  "${pin[@]}" "$harness" smoothing "configs/$smoothing.toml" -o "$dir/$smoothing.json" --failures "$dir/$smoothing.failures.json" \
    --poses "$smoothing_poses" --pin "$cpu" > /dev/null
  # The paper's Table 2 (agreement with FCL, libccd and the exact oracles)
  # and the uniform SO(3) sweep, each cut to its first shard.
  "${pin[@]}" "$harness" run configs/paper_table2.toml -o "$dir/paper_table2.json" --failures "$dir/paper_table2.failures.json" \
    --shard "$table2_shard" --pin "$cpu" --no-progress > /dev/null 2>&1
  "${pin[@]}" "$harness" run configs/uniform_so3.toml -o "$dir/uniform_so3.json" --failures "$dir/uniform_so3.failures.json" \
    --shard "$so3_shard" --no-progress > /dev/null
  "${pin[@]}" "$harness" run configs/ci_toi.toml -o "$dir/ci_toi.json" --failures "$dir/ci_toi.failures.json" --pin "$cpu" --no-progress > /dev/null
}

if [[ "${1:-}" == "--refresh" ]]; then
  run_all "$ref"
  "$harness" table "$ref/ci.json" -o "$ref/ci.md"
  "$harness" table "$ref/stress.json" -o "$ref/stress.md"
  "$harness" table "$ref/random_bodies.json" -o "$ref/random_bodies.md"
  "$harness" table "$ref/ci_toi.json" -o "$ref/ci_toi.md"
  [[ "${IDCOL_CI_INSTRUCTIONS:-1}" == 0 ]] || scripts/ci_instructions.sh --refresh
  # What the reference moved from stays in the history (harness/README.md, "History").
  "$harness" history add "$ref/ci.json" --into results/history.jsonl --thresholds "$ref/thresholds.toml"
  echo "references refreshed: review with 'git diff --stat results/baseline' and commit them"
  exit 0
fi

[[ "${1:-}" == "--compare-only" ]] || run_all "$out"
status=0
for name in ci stress random_bodies "$smoothing" paper_table2 uniform_so3 ci_toi; do
  set +e
  "$harness" compare "$ref/$name.json" "$out/$name.json" --thresholds "$ref/thresholds.toml" > "$out/compare_$name.txt"
  rc=$?
  set -e
  # The FAIL and WARN rows with their pair (case, point), the notes and the count.
  awk -v name="$name" '/^[^ ]/ && !/^note|^compare|^OLD |^NEW |^MISMATCH|metrics compared/ {pair = $0}
                       /^  / && / (FAIL|WARN)/ {sub(/^  /, ""); print name ": " pair ": " $0}
                       /^note|^MISMATCH|metrics compared/ {print name ": " $0}' "$out/compare_$name.txt"
  if [[ $rc -eq 1 ]]; then
    echo "ci_compare: $name regressed against $ref/$name.json (rows marked FAIL; full table in $out/compare_$name.txt)" >&2
  elif [[ $rc -ne 0 ]]; then
    # Bad input: compare's message is on stderr (above); never read as a pass.
    echo "ci_compare: $name could not be compared with $ref/$name.json (exit $rc: bad input)" >&2
  fi
  (( rc > status )) && status=$rc
done
if [[ "${IDCOL_CI_INSTRUCTIONS:-1}" != 0 ]]; then
  set +e
  if [[ "${1:-}" == "--compare-only" ]]; then
    IDCOL_INSTRUCTIONS_REF="$ref/instructions.json" IDCOL_CI_OUT="$out" scripts/ci_instructions.sh --compare "$out/instructions.json" > "$out/compare_instructions.txt"
  else
    IDCOL_INSTRUCTIONS_REF="$ref/instructions.json" IDCOL_CI_OUT="$out" scripts/ci_instructions.sh > "$out/compare_instructions.txt"
  fi
  rc=$?
  set -e
  grep -E "FAIL|^instructions per solve|^note" "$out/compare_instructions.txt" | sed 's/^/instructions: /' || true
  [[ $rc -eq 1 ]] && echo "ci_compare: instructions per solve rose (full table in $out/compare_instructions.txt)" >&2
  (( rc > status )) && status=$rc
fi
exit $status
