#!/bin/sh
# Builds the scene-parser fuzzer (clang-14, libFuzzer + ASan + UBSan) and runs
# it for a fixed time on a copy of the seed corpus.
#   scripts/fuzz_scene.sh [SECONDS]      (default 60)
# Output: build-fuzz/fuzz_scene, the log build-fuzz/fuzz_scene.log; crashes
# land in build-fuzz/artifacts/ (turn each into a test in harness/tests/).
set -eu
cd "$(dirname "$0")/.."
scripts/setup.sh fuzz
SECONDS_TO_RUN="${1:-60}"
OUT=build-fuzz
mkdir -p "$OUT/obj" "$OUT/corpus" "$OUT/artifacts"
CXX="${CXX:-clang++-14}"
# toml++ header-only, so that the TOML parser itself is instrumented.
FLAGS="-std=c++17 -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
  -DTOML_HEADER_ONLY=1 -I core/include -I harness/include -I /usr/include/eigen3
  -DIDCOL_HARNESS_COMPILER=\"clang\" -DIDCOL_HARNESS_CXX_FLAGS=\"fuzz\" -DIDCOL_HARNESS_BUILD_TYPE=\"fuzz\"
  -DIDCOL_HARNESS_GIT_REVISION=\"fuzz\" -DIDCOL_HARNESS_SOURCE_DIR=\".\" -DIDCOL_HARNESS_NATIVE=0"
OBJS=""
for src in core/src/shapes.cpp core/src/convex_hull.cpp core/src/solver.cpp core/src/derivatives.cpp \
           harness/src/scene.cpp harness/src/poses.cpp harness/src/stats.cpp harness/src/runner.cpp \
           harness/src/writers.cpp harness/src/stress.cpp harness/src/agreement.cpp harness/fuzz/fuzz_scene.cpp; do
  obj="$OUT/obj/$(echo "$src" | tr / _).o"
  # Rebuild when the source or any project header is newer than the object.
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ -n "$(find core/include harness/include -newer "$obj" -name '*.hpp' 2>/dev/null | head -1)" ]; then
    echo "compiling $src"
    # shellcheck disable=SC2086
    $CXX $FLAGS -c "$src" -o "$obj"
  fi
  OBJS="$OBJS $obj"
done
# shellcheck disable=SC2086
$CXX -fsanitize=fuzzer,address,undefined $OBJS -o "$OUT/fuzz_scene" -lpthread
cp -n harness/fuzz/corpus/* "$OUT/corpus/" 2>/dev/null || true
"$OUT/fuzz_scene" -max_total_time="$SECONDS_TO_RUN" -max_len=16384 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$OUT/artifacts/" -print_final_stats=1 "$OUT/corpus" 2>&1 | tee "$OUT/fuzz_scene.log" | tail -25
