#!/usr/bin/env bash
# Builds the scene-reader fuzzer (scripts/fuzz.sh's build: clang-14, libFuzzer,
# ASan + UBSan over the library, the harness and toml++) and runs it for a
# fixed time on a copy of the seed corpus.
#   scripts/fuzz_scene.sh [SECONDS]      (default 60)
# Output: build-fuzz/harness/fuzz/fuzz_scene, the log build-fuzz/fuzz_scene.log;
# crashes land in build-fuzz/artifacts/ (turn each into a corpus entry of
# harness/fuzz/corpus/, which ctest replays).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_TO_RUN="${1:-60}"
OUT=${IDCOL_FUZZ_BUILD_DIR:-build-fuzz}
IDCOL_FUZZ_BUILD_ONLY=1 scripts/fuzz.sh
mkdir -p "$OUT/corpus/scene" "$OUT/artifacts"
cp -n harness/fuzz/corpus/* "$OUT/corpus/scene/" 2>/dev/null || true
"$OUT/harness/fuzz/fuzz_scene" -max_total_time="$SECONDS_TO_RUN" -max_len=16384 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$OUT/artifacts/" -print_final_stats=1 "$OUT/corpus/scene" 2>&1 | tee "$OUT/fuzz_scene.log" | tail -25
