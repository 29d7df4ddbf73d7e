#!/usr/bin/env bash
# Writes the instructions-per-solve table of scripts/callgrind_pairs.sh as a
# Markdown results file with its provenance (machine, compiler, flags, git
# revision, command), next to the targets of the speed work:
#   scripts/callgrind_record.sh [build-dir] [out.md]
# (defaults: build, results/callgrind_pairs.md). The file is written to a
# temporary name and moved into place only when every pair has run, so an
# interrupted run leaves the previous file as it was.
set -euo pipefail
B=${1:-build}
OUT=${2:-results/callgrind_pairs.md}
here=$(cd "$(dirname "$0")" && pwd)
rev=${IDCOL_REV:-$(git -C "$here" rev-parse --short HEAD)$(git -C "$here" diff --quiet HEAD -- core || echo "+dirty")}
cxx=$(grep -m1 '^CMAKE_CXX_COMPILER:' "$B/CMakeCache.txt" | cut -d= -f2)
btype=$(grep -m1 '^CMAKE_BUILD_TYPE:' "$B/CMakeCache.txt" | cut -d= -f2)
flags=$(grep -m1 "^CMAKE_CXX_FLAGS_${btype^^}:" "$B/CMakeCache.txt" | cut -d= -f2)
extra=$(grep -m1 '^CMAKE_CXX_FLAGS:' "$B/CMakeCache.txt" | cut -d= -f2)
tmp=$(mktemp "${OUT}.XXXXXX")
trap 'rm -f "$tmp"' EXIT
table=$("$here/callgrind_pairs.sh" "$B")
# Targets of the speed work: a third of the authors' instructions per solve,
# measured in the same binary (Poly-Poly, SE-SE, SE-SEC, Ellip-Ellip,
# Poly-Ellip; cold SE-SE and SE-SEC have a tail target instead).
declare -A target=(
  [Poly-Poly/cold]=21900 [Poly-Poly/warm]=9950 [SE-SE/warm]=7250 [SE-SEC/warm]=7250
  [Ellip-Ellip/cold]=10550 [Ellip-Ellip/warm]=5300 [Poly-Ellip/cold]=16700 [Poly-Ellip/warm]=7450)
{
  echo "# Instructions per solve (callgrind)"
  echo
  echo "Instructions counted by callgrind inside the solve calls of core/idcol_prof"
  echo "(bench/prof_solver.cpp): the paper's sweep poses, cold = ${NCOLD:-2000} solves spread"
  echo "over the 20000 poses, warm = ${NWARM:-19999} consecutive warm-started solves."
  echo "Deterministic: independent of the load of the machine."
  echo
  echo "- command: \`scripts/callgrind_record.sh $B $OUT\`"
  echo "- git revision: $rev"
  echo "- machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(grep -c ^processor /proc/cpuinfo) cores ($(nproc) available to this run), $(uname -sr)"
  echo "- compiler: $("$cxx" --version | head -1)"
  echo "- build type: $btype, flags: ${extra:+$extra }$flags"
  echo "- valgrind: $(valgrind --version)"
  echo
  echo "| pair | cold Ir/solve | warm Ir/solve | cold target | warm target |"
  echo "|---|---:|---:|---:|---:|"
  echo "$table" | tail -n +2 | while read -r p c w; do
    echo "| $p | $c | $w | ${target[$p/cold]:--} | ${target[$p/warm]:--} |"
  done
} > "$tmp"
mv "$tmp" "$OUT"
trap - EXIT
echo "wrote $OUT"
