// The scalar number layer of the formulas written once
// (detail/formulas/*.hpp): T = double, a Mask is a bool, and an early exit
// is a branch. The batch lanes have their own layer over a vector of
// doubles (batch_simd_kernel.hpp, LaneNum) with the same members.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "idcol/detail/exp2_table.hpp"

namespace idcol::detail {

/// x^K by repeated squaring, unrolled at compile time.
template <int K>
inline double ipow_fixed(double x) {
  double r = 1.0;
  for (int k = K; k > 0; k >>= 1) {
    if (k & 1) r *= x;
    x *= x;
  }
  return r;
}
/// x^k for an integer k >= 0, by repeated squaring. Exponents up to 16
/// (superquadrics up to n = 8) jump to an unrolled copy of the same
/// multiplications, so the result is the same; the loop was half of a
/// superellipsoid evaluation.
inline double ipow(double x, int k) {
  switch (k) {
    case 0: return 1.0;
    case 1: return x;
    case 2: return ipow_fixed<2>(x);
    case 3: return ipow_fixed<3>(x);
    case 4: return ipow_fixed<4>(x);
    case 5: return ipow_fixed<5>(x);
    case 6: return ipow_fixed<6>(x);
    case 7: return ipow_fixed<7>(x);
    case 8: return ipow_fixed<8>(x);
    case 9: return ipow_fixed<9>(x);
    case 10: return ipow_fixed<10>(x);
    case 11: return ipow_fixed<11>(x);
    case 12: return ipow_fixed<12>(x);
    case 13: return ipow_fixed<13>(x);
    case 14: return ipow_fixed<14>(x);
    case 15: return ipow_fixed<15>(x);
    case 16: return ipow_fixed<16>(x);
    default: break;
  }
  double r = 1.0;
  while (k > 0) {
    if (k & 1) r *= x;
    x *= x;
    k >>= 1;
  }
  return r;
}

/// The number layer for double (see formulas/elementary.hpp for the members).
struct ScalarNum {
  using T = double;
  using Mask = bool;
  using Bits = std::uint64_t;
  /// Two numbers as one SSE2 register (a GCC/Clang vector extension); each
  /// half makes the scalar operation.
  using T2 = double __attribute__((vector_size(16)));
  /// Bounds are tested exactly, not prescreened (formulas/newton.hpp).
  static constexpr bool kPrescreen = false;
  /// One problem at a time: a formula may index its rows by a row number
  /// (formulas/polytope_simplex.hpp), where lanes select them.
  static constexpr bool kOneProblem = true;
  static T2 pair(double a, double b) { return T2{a, b}; }
  /// p[0] and p[1] as one T2 (one unaligned load).
  static T2 load2(const double* p) {
    T2 v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  static double lo(T2 v) { return v[0]; }
  static double hi(T2 v) { return v[1]; }
  static double splat(double x) { return x; }
  static double sel(bool m, double a, double b) { return m ? a : b; }
  static T2 sel2(bool m, T2 a, T2 b) { return m ? a : b; }
  /// A row number (an LU's pivot row), and the choice between two.
  static int index(int k) { return k; }
  static int sel_index(bool m, int a, int b) { return m ? a : b; }
  static bool not_(bool m) { return !m; }
  static bool mask(bool b) { return b; }
  static bool any(bool m) { return m; }
  static bool finite(double a) { return std::isfinite(a); }
  static double copysign(double a, double b) { return std::copysign(a, b); }
  static double hypot(double a, double b) { return std::hypot(a, b); }
  static double abs(double a) { return std::abs(a); }
  static double sqrt(double a) { return std::sqrt(a); }
  static double log(double a) { return std::log(a); }
  static double pow(double a, double k) { return std::pow(a, k); }
  static double ipow(double x, int k) { return detail::ipow(x, k); }
  static Bits bits(double x) {
    Bits b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  }
  static double from_bits(Bits b) {
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
  }
  template <bool kFused>
  static double mul_add(double a, double b, double c) {
    if constexpr (kFused) return std::fma(a, b, c);
    return a * b + c;
  }
  static bool leaves(bool m, bool& /*bad*/) { return m; }
  static double exp2_table(Bits j) { return kExp2Table[j]; }
  /// v 2^k, k = floor(n / 64) from t's low bits (2^51 + n): one product
  /// where 2^k is normal, else 2^k1 2^k2 with both halves normal (the first
  /// product exact, so the one rounding is the single product's).
  static double times_pow2(double v, double t, Bits /*j*/) {
    const std::int64_t k = static_cast<std::int64_t>(bits(t) - 0x4338000000000000ull) >> 6;
    auto pow2 = [](std::int64_t e) { return from_bits(static_cast<Bits>(e + 1023) << 52); };
    if (k >= -1022 && k <= 1023) return v * pow2(k);
    const std::int64_t k1 = k / 2;
    return (v * pow2(k1)) * pow2(k - k1);
  }
  template <class A, class B>
  static double lazy(bool m, A&& a, B&& b) {
    return m ? a() : b();
  }
  template <class E>
  static auto& phi(E& e) {
    return e.phi;
  }
  template <class E>
  static auto& grad(E& e, int i) {
    return e.grad[i];
  }
  template <class E>
  static auto& hess(E& e, int i, int j) {
    return e.hess(i, j);
  }
};

}  // namespace idcol::detail
