#!/usr/bin/env bash
# Robustness regression check: runs configs/ci.toml with the built harness and
# compares it with the checked-in reference results/baseline/ci.json under
# results/baseline/thresholds.toml. Exit 1 if a guarded metric regressed.
#
#   scripts/ci_compare.sh              # run and compare (CI)
#   scripts/ci_compare.sh --refresh    # after a deliberate change: rewrite the reference
#
# Environment: IDCOL_BUILD_DIR (default build), IDCOL_CI_OUT (default
# build/ci; the new results and the comparison land there), IDCOL_CI_CPU
# (CPU to pin to, default 0).
set -euo pipefail
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out="${IDCOL_CI_OUT:-$build/ci}"
cpu="${IDCOL_CI_CPU:-0}"
harness="$build/harness/idcol_harness"
ref=results/baseline/ci.json
mkdir -p "$out"
pin=(taskset -c "$cpu")
command -v taskset > /dev/null || pin=()

if [[ "${1:-}" == "--refresh" ]]; then
  "${pin[@]}" "$harness" run configs/ci.toml -o "$ref" --failures results/baseline/ci.failures.json --pin "$cpu" --no-progress
  "$harness" table "$ref" -o results/baseline/ci.md
  echo "reference refreshed: review with 'git diff --stat results/baseline' and commit it"
  exit 0
fi

"${pin[@]}" "$harness" run configs/ci.toml -o "$out/ci.json" --pin "$cpu" --no-progress
set +e
"$harness" compare "$ref" "$out/ci.json" --thresholds results/baseline/thresholds.toml | tee "$out/compare.txt"
rc=${PIPESTATUS[0]}
set -e
if [[ $rc -ne 0 ]]; then
  echo "ci_compare: regression against $ref (rows marked FAIL above; full table in $out/compare.txt)" >&2
fi
exit $rc
