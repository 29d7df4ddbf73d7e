#!/usr/bin/env bash
# Writes the instructions-per-solve table of scripts/callgrind_pairs.sh as a
# Markdown results file with its provenance (machine, compiler, flags, git
# revision, command), next to the targets of the speed work:
#   scripts/callgrind_record.sh [build-dir] [out.md]
#   scripts/callgrind_record.sh build results/callgrind_batch.md --batch
# (defaults: build, results/callgrind_pairs.md). --batch writes the loop
# against solve_batch table instead (WALK=1 BATCH=1 callgrind_pairs.sh: the
# random walk's and the batch's columns, warm <= cold checked on each, and
# loop / batch), with the raw output. The file is written to a
# temporary name and moved into place only when every pair has run, so an
# interrupted run leaves the previous file as it was.
set -euo pipefail
B=${1:-build}
OUT=${2:-results/callgrind_pairs.md}
MODE=${3:-}
here=$(cd "$(dirname "$0")" && pwd)
rev=${IDCOL_REV:-$(git -C "$here" rev-parse --short HEAD)$(git -C "$here" diff --quiet HEAD -- core || echo "+dirty")}
cxx=$(grep -m1 '^CMAKE_CXX_COMPILER:' "$B/CMakeCache.txt" | cut -d= -f2)
btype=$(grep -m1 '^CMAKE_BUILD_TYPE:' "$B/CMakeCache.txt" | cut -d= -f2)
flags=$(grep -m1 "^CMAKE_CXX_FLAGS_${btype^^}:" "$B/CMakeCache.txt" | cut -d= -f2)
extra=$(grep -m1 '^CMAKE_CXX_FLAGS:' "$B/CMakeCache.txt" | cut -d= -f2)
tmp=$(mktemp "${OUT}.XXXXXX")
trap 'rm -f "$tmp"' EXIT
if [[ "$MODE" == --batch ]]; then
  table=$(WALK=1 BATCH=1 "$here/callgrind_pairs.sh" "$B")
else
  table=$("$here/callgrind_pairs.sh" "$B")
fi
provenance() {
  echo "- git revision: $rev"
  echo "- machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(grep -c ^processor /proc/cpuinfo) cores ($(nproc) available to this run), $(uname -sr); callgrind counts do not depend on load"
  echo "- compiler: $("$cxx" --version | head -1)"
  echo "- build type: $btype, flags: ${extra:+$extra }$flags (no -march: the lane kernels carry their own instruction-set flags)"
  echo "- valgrind: $(valgrind --version) (the polytope face kernel and the polytope lanes run their fused AVX2 + FMA builds under it)"
}
if [[ "$MODE" == --batch ]]; then
  {
    echo "# Instructions per solve: the loop of solve() and solve_batch, cold and warm, sweep and random walk"
    echo
    echo "Instructions counted by callgrind inside the solves of core/idcol_prof"
    echo "(bench/prof_solver.cpp). Columns: cold = ${NCOLD:-2000} solves spread over the"
    echo "paper's sweep (20000 poses), warm = ${NWARM:-19999} consecutive warm-started solves of"
    echo "it; walk = ${NWALK:-5000} consecutive poses of a seeded random walk (steps of 0.05 in"
    echo "each twist coordinate), solved cold and warm; batch = the sweep's cold and"
    echo "warm poses through \`solve_batch(threads = 1)\` (warm: 10 chains, as 10^5"
    echo "poses in paper_table1's chains of 10^4, rotating through the lanes). Every"
    echo "pair's rows run in SIMD lanes there (the closed form for two ellipsoids,"
    echo "Newton steps for the others: core/README.md, \"Batch throughput and the"
    echo "SIMD path\"). Valgrind has no AVX-512, so the batch columns are the AVX2"
    echo "kernels' (4 lanes); on an AVX-512 CPU the lanes are 8."
    echo
    echo "- command: \`scripts/callgrind_record.sh $B $OUT --batch\` (WALK=1 BATCH=1 scripts/callgrind_pairs.sh, its output below, with the three right-hand columns computed from it)"
    provenance
    echo
    echo "| pair | cold | warm | walk cold | walk warm | batch cold | batch warm | warm <= cold (sweep, walk, batch) | loop / batch cold | loop / batch warm |"
    echo "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"
    all=yes
    while read -r p c w wc ww bc bw; do
      yn() { (($1 <= $2)) && echo yes || echo no; }
      v="$(yn "$w" "$c"), $(yn "$ww" "$wc"), $(yn "$bw" "$bc")"
      [[ "$v" == "yes, yes, yes" ]] || all=no
      echo "| $p | $c | $w | $wc | $ww | $bc | $bw | $v | $(awk -v a="$c" -v b="$bc" 'BEGIN{printf "%.2f", a/b}') | $(awk -v a="$w" -v b="$bw" 'BEGIN{printf "%.2f", a/b}') |"
    done < <(echo "$table" | tail -n +2)
    echo
    if [[ $all == yes ]]; then
      echo "Warm costs no more than cold on every pair, through the loop of solve() on the sweep and on the walk, and through the batch."
    else
      echo "Warm costs more than cold on some pair: the rows with a no above."
    fi
    echo
    echo "Raw output of the command:"
    echo
    echo '```text'
    echo "$table"
    echo '```'
  } > "$tmp"
  mv "$tmp" "$OUT"
  trap - EXIT
  echo "wrote $OUT"
  exit 0
fi
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
