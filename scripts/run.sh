#!/usr/bin/env bash
# Fresh machine to the main job: installs what is missing, builds, and solves
# one contact (the harness's quick scene once it exists).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
"${IDCOL_BUILD_DIR:-build}"/core/idcol_example
