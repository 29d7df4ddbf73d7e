// (d) Our own glue over GCC/Clang vector extensions. Define VEXT_W (2 or 4) first.
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <immintrin.h>
#endif
typedef double V __attribute__((vector_size(8 * VEXT_W)));
typedef decltype(V{} < V{}) M;  // what comparisons give: 64-bit integer lanes, -1 or 0
typedef unsigned long long VU __attribute__((vector_size(8 * VEXT_W)));
template <class T> inline T splat(double c);
template <> inline V splat<V>(double c) { return V{} + c; }
inline V select(M m, V a, V b) { return (V)((m & (M)a) | (~m & (M)b)); }
inline V fused_mul_add(V a, V b, V c) {
#if defined(__FMA__) && VEXT_W == 4
  return (V)_mm256_fmadd_pd((__m256d)a, (__m256d)b, (__m256d)c);
#else
  V r;
  for (int i = 0; i < VEXT_W; ++i) r[i] = __builtin_fma(a[i], b[i], c[i]);
  return r;
#endif
}
inline V pow2_from_shifter(V t) { return (V)(((VU)t + 1023ull) << 52); }
inline bool any(M m) {
#if defined(__AVX__) && VEXT_W == 4
  return !_mm256_testz_si256((__m256i)m, (__m256i)m);
#elif defined(__SSE2__) && VEXT_W == 2
  return _mm_movemask_pd((__m128d)m) != 0;
#else
  long long r = 0;
  for (int i = 0; i < VEXT_W; ++i) r |= m[i];
  return r != 0;
#endif
}
inline M mask_and(M a, M b) { return a & b; }
template <class T> inline T loadu(const double* p);
template <> inline V loadu<V>(const double* p) { V v; std::memcpy(&v, p, sizeof v); return v; }
inline void storeu(V v, double* p) { std::memcpy(p, &v, sizeof v); }
