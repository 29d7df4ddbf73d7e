#!/usr/bin/env bash
# The evidence for the vector layer of a solver written once over a number
# type (double, or a vector of doubles whose every lane must give the
# double's bits): one kernel source (kernel.inc: the solver's exp of a
# nonpositive argument, unfused and with explicit fused multiply-adds, a 3x3
# matrix-vector product with a dot product, and a masked Newton iteration
# that stops when no lane moves) instantiated for
#   scalar   double (the reference: glue_scalar.hpp, built for SSE2)
#   vext     a wrapper of this project over GCC/Clang vector extensions (glue_vext.hpp)
#   xsimd    xsimd's batch<double, arch> (glue_xsimd.hpp; libxsimd-dev)
#   stdx     GCC's std::experimental::simd (glue_stdx.hpp)
#   hwy      Google Highway, every target of one file (glue_hwy.hpp; libhwy-dev)
# each at 2 lanes (SSE2) and 4 lanes (AVX2 + FMA) where the layer has them.
#
#   scripts/vector_layers/run.sh [OUT.md]    (default results/vector_layers.md)
#
# Installs libhwy-dev and libxsimd-dev if missing (apt-get, as
# scripts/setup.sh does), builds with g++ and, when present, clang++ (one
# translation unit at a time, every one with -ffp-contract=off as core's),
# and writes OUT.md (through a temporary file and a rename): per compiler,
# the elements of 2^20 inputs whose result differs from the scalar
# reference's bits (exp: uniform in [-745, 0] with NaN, infinities, zeros,
# the -708 clamp and the rounding boundaries n ln2 +- ln2/2; the others
# uniform), then instructions per element of one call over 2^16 elements
# under callgrind. Not part of the build or of CI: a study, rerun when a
# layer or the compiler changes. About 10 minutes on 2 cores.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/results/vector_layers.md}
need=()
for p in libhwy-dev libxsimd-dev valgrind; do dpkg -s "$p" >/dev/null 2>&1 || need+=("$p"); done
if ((${#need[@]})); then
  echo "installing ${need[*]}"
  apt-get update -qq && apt-get install -y -qq "${need[@]}" >/dev/null
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
FLAGS="-O3 -DNDEBUG -std=c++17 -ffp-contract=off -fno-math-errno -Wall -Wextra -Wno-psabi"
AVX="-mavx2 -mfma"
build() {  # build CXX DIR
  local cxx=$1 b=$2
  mkdir -p "$b"
  c() { local o=$1; shift; $cxx $FLAGS -I"$here" -c "$@" -o "$b/$o.o"; }
  (cd "$here"
   c scalar_sse2 scalar_tu.cpp -DKNAME=scalar_sse2
   c scalar_avx2 scalar_tu.cpp -DKNAME=scalar_avx2 $AVX
   c vext_sse2_w2 vext_tu.cpp -DKNAME=vext_sse2_w2 -DVEXT_W=2
   c vext_sse2_w4 vext_tu.cpp -DKNAME=vext_sse2_w4 -DVEXT_W=4
   c vext_avx2_w4 vext_tu.cpp -DKNAME=vext_avx2_w4 -DVEXT_W=4 $AVX
   c xsimd_sse2 xsimd_tu.cpp -DKNAME=xsimd_sse2 "-DXS_ARCH=xsimd::sse2" -DXS_DISPATCH
   c xsimd_avx2_nofma3 xsimd_tu.cpp -DKNAME=xsimd_avx2_nofma3 "-DXS_ARCH=xsimd::avx2" $AVX
   c xsimd_fma3_avx2 xsimd_tu.cpp -DKNAME=xsimd_fma3_avx2 "-DXS_ARCH=xsimd::fma3<xsimd::avx2>" -DXS_DISPATCH $AVX
   c xsimd_dispatch xsimd_dispatch.cpp
   c stdx_sse2_w2 stdx_tu.cpp -DKNAME=stdx_sse2_w2 -DSTDX_W=2
   c stdx_sse2_w4 stdx_tu.cpp -DKNAME=stdx_sse2_w4 -DSTDX_W=4
   c stdx_avx2_w4 stdx_tu.cpp -DKNAME=stdx_avx2_w4 -DSTDX_W=4 $AVX
   c hwy hwy_tu.cpp
   c main main.cpp)
  $cxx "$b"/*.o -o "$b/study" -lhwy
}
LAYERS="scalar_sse2 scalar_avx2 vext_sse2_w2 vext_sse2_w4 vext_avx2_w4 xsimd_sse2 xsimd_avx2_nofma3 xsimd_fma3_avx2 xsimd_dispatched stdx_sse2_w2 stdx_sse2_w4 stdx_avx2_w4 hwy_baseline hwy_ssse3 hwy_sse4 hwy_avx2 hwy_dynamic"
counts() {  # counts STUDY: one table row per layer, instructions per element
  local s=$1
  echo "| layer | exp | exp, fused | matvec + dot | masked Newton |"
  echo "|---|---:|---:|---:|---:|"
  for L in $LAYERS; do
    local row="| $L |"
    for K in exp expf matvec sqrt; do
      valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$work/cg.out" "$s" cg "$L" "$K" >/dev/null 2>&1
      local ir
      ir=$(grep '^summary' "$work/cg.out" | awk '{print $2}')
      row="$row $(awk -v i="$ir" 'BEGIN { printf "%.2f", i / 65536 }') |"
    done
    echo "$row"
  done
}
compilers=(g++)
command -v clang++ >/dev/null && compilers+=(clang++)
{
  echo "# Vector layers: one kernel source, every lane against the scalar double"
  echo
  echo "Written by \`scripts/vector_layers/run.sh\` (the kernels, the layers and what"
  echo "the columns mean are described at its top; core/README.md, \"The vector"
  echo "layer\", says what this decides)."
  echo
  echo "- git revision: $(git -C "$root" rev-parse --short=7 HEAD)"
  echo "- date: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "- machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) CPUs; AVX-512F: $(grep -q avx512f /proc/cpuinfo && echo yes || echo no)"
  echo "- flags: \`$FLAGS\`, AVX2 units add \`$AVX\`"
  echo "- packages: libhwy-dev $(dpkg-query -W -f='${Version}' libhwy-dev), libxsimd-dev $(dpkg-query -W -f='${Version}' libxsimd-dev), $(valgrind --version)"
  for cxx in "${compilers[@]}"; do
    build "$cxx" "$work/$cxx" >&2
    echo
    echo "## $($cxx --version | head -1)"
    echo
    echo "Elements whose bits differ from scalar_sse2's (of 2^20; matvec counts its three outputs):"
    echo
    echo '```'
    "$work/$cxx/study" check
    echo '```'
    echo
    echo "Instructions per element (callgrind, one call over 2^16 elements):"
    echo
    counts "$work/$cxx/study"
  done
} > "$work/out.md"
mv "$work/out.md" "$out.tmp.$$" && mv "$out.tmp.$$" "$out"
echo "wrote $out"
