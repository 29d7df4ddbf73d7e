#include "xsimd_dispatch.hpp"
Kernels xsimd_dispatched() {
  return xsimd::dispatch<xsimd::arch_list<xsimd::fma3<xsimd::avx2>, xsimd::sse2>>(XsGet{})();
}
