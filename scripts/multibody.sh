#!/usr/bin/env bash
# The paper's multibody example in one command: runs the ten-body simulation with
# analytical and with finite-difference Jacobians (core/examples/multibody.cpp:
# it prints the times, shares, steps, Jacobians, contacts and the checks),
# and draws the snapshots (scripts/plot_multibody.py).
#
#   scripts/multibody.sh [OUT_DIR] [idcol_multibody options...]
#
# OUT_DIR (default build/out) receives multibody.json and multibody.png.
# Exit status: the example's (1 when a check failed), or 2 when it cannot run.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out=${1:-build/out}
(($#)) && shift
exe="$build/core/idcol_multibody"
[[ -x "$exe" ]] || { echo "multibody.sh: $exe is not built (scripts/build.sh, or cmake --build $build --target idcol_multibody)" >&2; exit 2; }
mkdir -p "$out"
rc=0
"$exe" -o "$out/multibody.json" "$@" || rc=$?
[[ -f "$out/multibody.json" ]] && /usr/bin/python3 scripts/plot_multibody.py "$out/multibody.json" -o "$out/multibody.png"
exit $rc
