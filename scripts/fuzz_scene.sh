#!/usr/bin/env bash
# Builds the scene-parser fuzzer (clang-14, libFuzzer + ASan + UBSan) and runs
# it for a fixed time on a copy of the seed corpus.
#   scripts/fuzz_scene.sh [SECONDS]      (default 60)
# Output: build-fuzz/fuzz_scene, the log build-fuzz/fuzz_scene.log; crashes
# land in build-fuzz/artifacts/ (turn each into a test in harness/tests/).
# IDCOL_FUZZ_BUILD_ONLY=1 builds and stops (scripts/ci_fuzz.sh runs it).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh fuzz
SECONDS_TO_RUN="${1:-60}"
OUT=build-fuzz
mkdir -p "$OUT/obj" "$OUT/corpus" "$OUT/artifacts"
CXX="${CXX:-clang++-14}"
# toml++ header-only, so that the TOML parser itself is instrumented.
# -gline-tables-only: file:line in reports, for a fraction of -g's build time.
FLAGS=(-std=c++17 -O1 -gline-tables-only -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
  -DTOML_HEADER_ONLY=1 -I core/include -I harness/include -I /usr/include/eigen3
  '-DIDCOL_HARNESS_COMPILER="clang"' '-DIDCOL_HARNESS_CXX_FLAGS="fuzz"' '-DIDCOL_HARNESS_BUILD_TYPE="fuzz"'
  '-DIDCOL_HARNESS_GIT_REVISION="fuzz"' '-DIDCOL_HARNESS_SOURCE_DIR="."' -DIDCOL_HARNESS_NATIVE=0
  '-DIDCOL_HARNESS_VERSION="fuzz"' '-DIDCOL_HARNESS_LIBRARIES="fuzz=1"')
JOBS=${IDCOL_JOBS:-$(nproc)}
OBJS=()
pids=()
# The harness library as harness/CMakeLists.txt builds it without the baselines.
for src in core/src/shapes.cpp core/src/convex_hull.cpp core/src/options.cpp core/src/solver.cpp core/src/derivatives.cpp \
           core/src/shape_params.cpp \
           harness/src/poses.cpp harness/src/record.cpp harness/src/checks.cpp harness/src/study.cpp harness/src/scene.cpp \
           harness/src/solver_options.cpp harness/src/stats.cpp harness/src/runner.cpp harness/src/writers.cpp \
           harness/src/agreement.cpp harness/src/compare.cpp harness/src/stress.cpp harness/src/random_bodies.cpp \
           harness/src/random_bodies_stress.cpp harness/fuzz/fuzz_scene.cpp; do
  obj="$OUT/obj/$(echo "$src" | tr / _).o"
  OBJS+=("$obj")
  # Rebuild when the source or any project header is newer than the object.
  if [[ ! -f $obj || $src -nt $obj || -n $(find core/include harness/include -newer "$obj" -name '*.hpp' 2>/dev/null | head -1) ]]; then
    while (($(jobs -rp | wc -l) >= JOBS)); do wait -n; done
    echo "compiling $src"
    # Into a temporary name, so that an interrupted compile leaves no object.
    ($CXX "${FLAGS[@]}" -c "$src" -o "$obj.tmp" && mv "$obj.tmp" "$obj") &
    pids+=($!)
  fi
done
for p in "${pids[@]}"; do wait "$p"; done
$CXX -fsanitize=fuzzer,address,undefined "${OBJS[@]}" -o "$OUT/fuzz_scene" -lpthread
[[ -n ${IDCOL_FUZZ_BUILD_ONLY:-} ]] && exit 0
cp -n harness/fuzz/corpus/* "$OUT/corpus/" 2>/dev/null || true
"$OUT/fuzz_scene" -max_total_time="$SECONDS_TO_RUN" -max_len=16384 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$OUT/artifacts/" -print_final_stats=1 "$OUT/corpus" 2>&1 | tee "$OUT/fuzz_scene.log" | tail -25
