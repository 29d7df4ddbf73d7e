#!/usr/bin/env bash
# CI fuzz stage (.ci/run): builds both libFuzzer targets in the sanitize
# stage's build (scripts/sanitize.sh --ci: clang-14, libFuzzer, ASan + UBSan
# over the library, the harness and toml++; nothing to compile when that stage
# ran first), replays both committed
# corpora through them, then fuzzes each target for IDCOL_FUZZ_SECONDS (60)
# from a scratch copy of its corpus, the two targets side by side. Fails on
# any crash, sanitizer report, leak, timeout (-timeout=10 s per input) or
# out-of-memory; a new failing input is saved in the checkout as a named
# corpus entry, and the message says how to commit it as a regression (and,
# for a CI machine whose checkout is thrown away, prints it as base64).
#
#   scripts/ci_fuzz.sh            # what CI runs
#   IDCOL_FUZZ_SECONDS=600 scripts/ci_fuzz.sh
#   IDCOL_FUZZ_FLAGS="-max_len=512" scripts/ci_fuzz.sh   # extra libFuzzer flags for the fuzzing runs
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${IDCOL_FUZZ_SECONDS:-60}
[[ $seconds =~ ^[1-9][0-9]*$ ]] || { echo "ci_fuzz: IDCOL_FUZZ_SECONDS='$seconds': expected a positive number of seconds" >&2; exit 2; }
build=${IDCOL_SANITIZE_BUILD_DIR:-build-sanitize-ci}
IDCOL_SANITIZE_BUILD_ONLY=1 scripts/sanitize.sh --ci
out=$build/fuzz-ci

# target name, executable, committed corpus, name prefix and suffix of a new regression entry, extra flags
targets=(
  "solve|$build/core/fuzz/fuzz_solve|core/fuzz/corpus/solve|regression_ci_|"
  "scene|$build/harness/fuzz/fuzz_scene|harness/fuzz/corpus|regress_ci_|.toml|-max_len=16384"
)
common=(-timeout=10 -rss_limit_mb=2048)
rm -rf "$out"
mkdir -p "$out"

# Saves each failing input of target $1 into its corpus and explains.
report() {
  local name=$1 exe=$2 corpus=$3 prefix=$4 suffix=$5 log=$6 f kind entry
  shopt -s nullglob
  local found=0
  for f in "$out/artifacts-$name/"*; do
    found=1
    kind=$(basename "$f" | cut -d- -f1)  # crash, leak, timeout, oom, slow-unit
    entry="$corpus/$prefix${kind}_$(sha1sum "$f" | cut -c1-12)$suffix"
    cp "$f" "$entry"
    echo "ci_fuzz: fuzz_$name: $kind; the input is saved as the corpus entry $entry" >&2
    echo "  reproduce: $exe $entry" >&2
    echo "  commit it as a regression (git add $entry; ctest replays the corpus), after the fix." >&2
    echo "  On a machine whose checkout is gone, recreate it with:" >&2
    echo "    base64 -d > $entry << 'B64'" >&2
    base64 "$f" >&2
    echo "B64" >&2
  done
  if ((!found)); then
    echo "ci_fuzz: fuzz_$name failed without leaving an input (see $log)" >&2
  fi
  shopt -u nullglob
}

status=0
echo "== replay the committed corpora"
for t in "${targets[@]}"; do
  IFS='|' read -r name exe corpus prefix suffix extra <<< "$t"
  mkdir -p "$out/artifacts-$name"
  # With files as arguments, libFuzzer runs each once and stops at the first
  # failure.
  files=("$corpus"/*)
  if ! "$exe" "${common[@]}" $extra -artifact_prefix="$out/artifacts-$name/" "${files[@]}" \
      > "$out/replay-$name.log" 2>&1; then
    tail -40 "$out/replay-$name.log" >&2
    echo "ci_fuzz: replaying $corpus through fuzz_$name failed (full log $out/replay-$name.log)" >&2
    status=1
  else
    echo "fuzz_$name: ${#files[@]} corpus entries replayed, no report"
  fi
done
((status == 0)) || exit 1

echo "== fuzz each target for ${seconds} s from its corpus"
pids=()
for t in "${targets[@]}"; do
  IFS='|' read -r name exe corpus prefix suffix extra <<< "$t"
  mkdir -p "$out/corpus-$name"
  cp "$corpus"/* "$out/corpus-$name/"
  # shellcheck disable=SC2086
  "$exe" "${common[@]}" $extra ${IDCOL_FUZZ_FLAGS:-} -max_total_time="$seconds" -print_final_stats=1 \
    -artifact_prefix="$out/artifacts-$name/" "$out/corpus-$name" > "$out/fuzz-$name.log" 2>&1 &
  pids+=($!)
done
i=0
for t in "${targets[@]}"; do
  IFS='|' read -r name exe corpus prefix suffix extra <<< "$t"
  if wait "${pids[$i]}"; then
    echo "fuzz_$name: $(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$out/fuzz-$name.log" | grep -o '[0-9]*$') inputs in ${seconds} s, no report;" \
      "$(grep -o 'cov: [0-9]*' "$out/fuzz-$name.log" | tail -1)"
  else
    tail -40 "$out/fuzz-$name.log" >&2
    report "$name" "$exe" "$corpus" "$prefix" "$suffix" "$out/fuzz-$name.log"
    status=1
  fi
  i=$((i + 1))
done
exit $status
