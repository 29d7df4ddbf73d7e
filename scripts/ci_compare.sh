#!/usr/bin/env bash
# Robustness regression check: runs, with the built harness, the sweep
# configs/ci.toml, the stress suite configs/stress.toml cut to its first
# $stress_poses poses per case, the random-body scene configs/random_bodies.toml
# cut to its first $random_poses poses per case, and the smoothing grid
# configs/$smoothing.toml on $smoothing_poses poses, and the time-of-impact cut
# configs/ci_toi.toml, and compares each with its checked-in reference
# in results/baseline/ under results/baseline/thresholds.toml (one compare for
# every kind of results file). Exit 1 if a guarded metric regressed in any.
#
#   scripts/ci_compare.sh              # run and compare (CI)
#   scripts/ci_compare.sh --refresh    # after a deliberate change: rewrite the references
#
# Environment: IDCOL_BUILD_DIR (default build), IDCOL_CI_OUT (default
# build/ci; the new results and the comparisons land there), IDCOL_CI_CPU
# (CPU to pin to, default 0).
set -euo pipefail
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out="${IDCOL_CI_OUT:-$build/ci}"
cpu="${IDCOL_CI_CPU:-0}"
harness="$build/harness/idcol_harness"
ref=results/baseline
stress_poses=1000
random_poses=20
smoothing=smoothing_polytope
smoothing_poses=2000
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
  "${pin[@]}" "$harness" stress configs/random_bodies.toml -o "$dir/random_bodies.json" --failures "$dir/random_bodies.failures.json" \
    --max-poses "$random_poses" --max-failures 20 --no-progress > /dev/null
  "${pin[@]}" "$harness" smoothing "configs/$smoothing.toml" -o "$dir/$smoothing.json" --failures "$dir/$smoothing.failures.json" \
    --poses "$smoothing_poses" --pin "$cpu" > /dev/null
  "${pin[@]}" "$harness" run configs/ci_toi.toml -o "$dir/ci_toi.json" --failures "$dir/ci_toi.failures.json" --pin "$cpu" --no-progress > /dev/null
}

if [[ "${1:-}" == "--refresh" ]]; then
  run_all "$ref"
  "$harness" table "$ref/ci.json" -o "$ref/ci.md"
  "$harness" table "$ref/stress.json" -o "$ref/stress.md"
  "$harness" table "$ref/random_bodies.json" -o "$ref/random_bodies.md"
  "$harness" table "$ref/ci_toi.json" -o "$ref/ci_toi.md"
  echo "references refreshed: review with 'git diff --stat results/baseline' and commit them"
  exit 0
fi

run_all "$out"
status=0
for name in ci stress random_bodies "$smoothing" ci_toi; do
  set +e
  "$harness" compare "$ref/$name.json" "$out/$name.json" --thresholds "$ref/thresholds.toml" > "$out/compare_$name.txt"
  rc=$?
  set -e
  # The FAIL and WARN rows with their pair (case, point), the notes and the count.
  awk -v name="$name" '/^[^ ]/ && !/^note|^compare|metrics compared/ {pair = $0}
                       /^  / && / (FAIL|WARN)/ {sub(/^  /, ""); print name ": " pair ": " $0}
                       /^note|metrics compared/ {print name ": " $0}' "$out/compare_$name.txt"
  if [[ $rc -ne 0 ]]; then
    echo "ci_compare: $name regressed against $ref/$name.json (rows marked FAIL; full table in $out/compare_$name.txt)" >&2
    status=1
  fi
done
exit $status
