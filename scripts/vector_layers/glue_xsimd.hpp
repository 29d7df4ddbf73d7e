// (b) xsimd glue. Define XS_ARCH (e.g. xsimd::sse2, xsimd::fma3<xsimd::avx2>) first.
#include <xsimd/xsimd.hpp>
using V = xsimd::batch<double, XS_ARCH>;
using M = xsimd::batch_bool<double, XS_ARCH>;
using VU = xsimd::batch<std::uint64_t, XS_ARCH>;
template <class T> inline T splat(double c);
template <> inline V splat<V>(double c) { return V(c); }
inline V select(M m, V a, V b) { return xsimd::select(m, a, b); }
inline V fused_mul_add(V a, V b, V c) { return xsimd::fma(a, b, c); }
inline V pow2_from_shifter(V t) {
  VU u = xsimd::bitwise_cast<VU>(t);
  return xsimd::bitwise_cast<V>((u + VU(1023)) << 52);
}
inline bool any(M m) { return xsimd::any(m); }
inline M mask_and(M a, M b) { return a && b; }
template <class T> inline T loadu(const double* p);
template <> inline V loadu<V>(const double* p) { return V::load_unaligned(p); }
inline void storeu(V v, double* p) { v.store_unaligned(p); }
