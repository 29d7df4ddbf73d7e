#!/usr/bin/env bash
# Builds the libFuzzer targets with clang into ${IDCOL_FUZZ_BUILD_DIR:-build-fuzz}
# and runs each of core/fuzz for a fixed time on a scratch copy of its seed
# corpus (the scene reader's target, built here too, is run by fuzz_scene.sh).
#   scripts/fuzz.sh [seconds per target, default 60] [extra libFuzzer flags...]
# New interesting inputs land in build-fuzz/corpus/<target>/; merge the few
# worth keeping into core/fuzz/corpus/<target>/ with
#   fuzz_<target> -merge=1 core/fuzz/corpus/<target> build-fuzz/corpus/<target>
# Crashes are written to build-fuzz/artifacts/.
# The library itself is compiled with coverage instrumentation and ASan/UBSan
# (not only the fuzz target's own file), so that libFuzzer is guided by, and
# the sanitizers watch, the solver's code. IDCOL_FUZZ_BUILD_ONLY=1 builds and
# stops (scripts/fuzz_scene.sh builds through it; CI fuzzes from the sanitize
# stage's build, scripts/ci_fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh fuzz
SECONDS_PER_TARGET=${1:-60}
shift || true
BUILD_DIR=${IDCOL_FUZZ_BUILD_DIR:-build-fuzz}
CXX_COMPILER=${IDCOL_FUZZ_CXX:-$(command -v clang++-14 || command -v clang++)}
cmake -S . -B "$BUILD_DIR" -DCMAKE_CXX_COMPILER="$CXX_COMPILER" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
  -DIDCOL_BUILD_FUZZERS=ON -DIDCOL_BUILD_TESTS=OFF -DIDCOL_BUILD_BENCHMARKS=OFF \
  -DIDCOL_BUILD_BASELINES=OFF -DIDCOL_BUILD_PYTHON=OFF >/dev/null
# The core targets and the scene reader's (scripts/fuzz_scene.sh runs that one).
cmake --build "$BUILD_DIR" -j"${IDCOL_JOBS:-2}" --target $(cd core/fuzz && ls fuzz_*.cpp | sed 's/\.cpp$//') fuzz_scene
[[ -n ${IDCOL_FUZZ_BUILD_ONLY:-} ]] && exit 0
mkdir -p "$BUILD_DIR/artifacts"
status=0
for src in core/fuzz/fuzz_*.cpp; do
  name=$(basename "$src" .cpp)
  target=${name#fuzz_}
  mkdir -p "$BUILD_DIR/corpus/$target"
  seeds=core/fuzz/corpus/$target
  echo "== $name for ${SECONDS_PER_TARGET}s"
  "$BUILD_DIR/core/fuzz/$name" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$BUILD_DIR/artifacts/$name-" "$@" \
    "$BUILD_DIR/corpus/$target" "$seeds" || status=$?
done
exit $status
