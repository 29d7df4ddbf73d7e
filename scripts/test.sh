#!/usr/bin/env bash
# Fresh machine to passing tests: installs what is missing, builds, runs ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
ctest --test-dir "${IDCOL_BUILD_DIR:-build}" --output-on-failure -j"$(nproc)"
