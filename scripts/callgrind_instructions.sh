#!/usr/bin/env bash
# Instructions per solve of each pair of idcol_prof's set, cold and warm,
# counted by callgrind, as a JSON file that `idcol_harness history add
# RESULTS.json --into HISTORY --instructions OUT.json` adds to a history
# line (schema "idcol-instructions"). Deterministic for one build, so a
# change is a change of the code; fewer poses than scripts/callgrind_pairs.sh
# (seconds per pair rather than minutes).
#   scripts/callgrind_instructions.sh [build-dir] [OUT.json]
# Environment: NCOLD (default 200: every 100th of the 20000 sweep poses),
# NWARM (default 2000 consecutive warm-started poses), PAIRS.
set -euo pipefail
B=${1:-build}
OUT=${2:-/dev/stdout}
PAIRS=${PAIRS:-"Poly-Poly Poly-TC Poly-SE Poly-SEC Poly-Ellip TC-TC TC-SE TC-SEC TC-Ellip SE-SE SE-SEC SE-Ellip SEC-SEC SEC-Ellip Ellip-Ellip"}
NCOLD=${NCOLD:-200}
NWARM=${NWARM:-2000}
prof="$B/core/idcol_prof"
[[ -x $prof ]] || { echo "callgrind_instructions: $prof not built (cmake --build $B --target idcol_prof; needs IDCOL_BUILD_BENCHMARKS=ON and valgrind's headers)" >&2; exit 2; }
command -v valgrind > /dev/null || { echo "callgrind_instructions: valgrind is not installed" >&2; exit 2; }
src=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$B/CMakeCache.txt")
rev=$(git -C "$src" rev-parse HEAD 2> /dev/null || echo "")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
{
  printf '{"schema": "idcol-instructions", "git_revision": "%s", "valgrind": "%s",\n' "$rev" "$(valgrind --version)"
  printf ' "driver": "core/idcol_prof run PAIR cold %s (every %sth pose of the paper sweep) and warm %s (consecutive), callgrind Ir inside the solves",\n' \
    "$NCOLD" "$((20000 / NCOLD))" "$NWARM"
  printf ' "pairs": {'
  sep=""
  for p in $PAIRS; do
    printf '%s\n  "%s": {' "$sep" "$p"
    msep=""
    for m in cold:$NCOLD warm:$NWARM; do
      mode=${m%%:*} n=${m##*:}
      valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg" "$prof" run "$p" "$mode" "$n" > /dev/null 2>&1
      ir=$(awk '/^summary:/ {print $2; exit}' "$tmp/cg")
      printf '%s"%s": {"solves": %s, "instructions": %s}' "$msep" "$mode" "$n" "$ir"
      msep=", "
    done
    printf '}'
    sep=","
  done
  printf '}}\n'
} > "$tmp/out.json"
cp "$tmp/out.json" "$OUT"
