#!/usr/bin/env bash
# Fresh machine to the main job: installs what is missing, builds, and runs
# the harness's quick scene (the paper's four shapes, 10^4 poses per pair,
# cold and warm), then prints its table.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
BUILD_DIR=${IDCOL_BUILD_DIR:-build}
OUT_DIR=${IDCOL_OUT_DIR:-$BUILD_DIR/out}
mkdir -p "$OUT_DIR"
"$BUILD_DIR"/harness/idcol_harness run configs/quick.toml -o "$OUT_DIR"/quick.json --no-progress
"$BUILD_DIR"/harness/idcol_harness table "$OUT_DIR"/quick.json
