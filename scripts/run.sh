#!/usr/bin/env bash
# Fresh machine to the main job: installs what is missing, builds, and runs
# the harness's quick scene (the paper's four shapes, 10^4 poses per pair,
# cold and warm). The build's output goes to the terminal; the last screen is
# the verdict: did every pair converge, median and p99 time per solve, and
# where the files went.
#   IDCOL_BUILD_DIR  build directory (default build)
#   IDCOL_OUT_DIR    where the results go (default $IDCOL_BUILD_DIR/out)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
BUILD_DIR=${IDCOL_BUILD_DIR:-build}
OUT_DIR=${IDCOL_OUT_DIR:-$BUILD_DIR/out}
mkdir -p "$OUT_DIR"
harness=$BUILD_DIR/harness/idcol_harness
"$harness" run configs/quick.toml -o "$OUT_DIR"/quick.json --no-progress > "$OUT_DIR"/quick.log
"$harness" table "$OUT_DIR"/quick.json -o "$OUT_DIR"/quick.md
echo
echo "================ configs/quick.toml: 10^4 poses of the paper's sweep per pair, cold and warm ================"
"$harness" info "$OUT_DIR"/quick.json | sed -n '3,$p'
echo
echo "Files (IDCOL_OUT_DIR=$OUT_DIR):"
echo "  results   $OUT_DIR/quick.json"
echo "  failures  $OUT_DIR/quick.failures.json"
echo "  table     $OUT_DIR/quick.md   (every figure: mean, median, p99, descheduled time, iterations)"
echo "  log       $OUT_DIR/quick.log"
echo "Times are one run on this machine, unpinned; for timing figures pin a core (core/README.md, Benchmarks)."
