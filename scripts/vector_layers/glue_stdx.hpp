// (c) std::experimental::simd glue. Define STDX_W (2 or 4) first.
#include <experimental/simd>
#include <cmath>
#include <cstdint>
namespace stdx = std::experimental;
using V = stdx::simd<double, stdx::simd_abi::deduce_t<double, STDX_W>>;
using M = V::mask_type;
using VU = stdx::simd<std::uint64_t, stdx::simd_abi::deduce_t<std::uint64_t, STDX_W>>;
template <class T> inline T splat(double c);
template <> inline V splat<V>(double c) { return V(c); }
inline V select(M m, V a, V b) { stdx::where(m, b) = a; return b; }
inline V fused_mul_add(V a, V b, V c) { return stdx::fma(a, b, c); }
inline V pow2_from_shifter(V t) {
  VU u = stdx::__proposed::simd_bit_cast<VU>(t);  // non-standard (GCC's __proposed)
  return stdx::__proposed::simd_bit_cast<V>((u + 1023) << 52);
}
inline bool any(M m) { return stdx::any_of(m); }
inline M mask_and(M a, M b) { return a && b; }
template <class T> inline T loadu(const double* p);
template <> inline V loadu<V>(const double* p) { return V(p, stdx::element_aligned); }
inline void storeu(V v, double* p) { v.copy_to(p, stdx::element_aligned); }
