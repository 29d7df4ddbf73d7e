// Scalar glue (T = double, M = bool).
#include <cmath>
#include <cstdint>
#include <cstring>
template <class T> inline T splat(double c);
template <> inline double splat<double>(double c) { return c; }
inline double select(bool m, double a, double b) { return m ? a : b; }
inline double fused_mul_add(double a, double b, double c) { return std::fma(a, b, c); }
inline double pow2_from_shifter(double t) {
  std::uint64_t u; std::memcpy(&u, &t, 8); u = (u + 1023) << 52; double s; std::memcpy(&s, &u, 8); return s;
}
inline bool any(bool m) { return m; }
inline bool mask_and(bool a, bool b) { return a && b; }
template <class T> inline T loadu(const double* p);
template <> inline double loadu<double>(const double* p) { return *p; }
inline void storeu(double v, double* p) { *p = v; }
