// Elementary functions written once over a number layer N, for the scalar
// solver (N = ScalarNum, T = double: scalar_num.hpp) and the batch lanes
// (N = the lanes' LaneNum, T = a vector of W doubles: batch_simd_kernel.hpp).
// Both run these same operations in the same order, so a lane gives the
// scalar code's bits by construction, not by a second copy kept in step.
//
// What N provides (static members):
//   T, Mask, Bits           the number, what its comparisons give, its bits
//   splat(double)           a T holding the constant
//   sel(Mask, T a, T b)     a where the mask is set, else b (every bit)
//   not_(Mask), abs, sqrt, log, pow(T, double)
//   bits(T), from_bits(Bits)  the bit pattern and back
//   mul_add<kFused>(a, b, c)  a b + c, rounded once where kFused, else twice
//   leaves(Mask m, Mask& bad) where the scalar code takes an early exit: the
//                           scalar layer answers m (the caller returns its
//                           special value); the lanes flag those lanes in bad
//                           (the scalar solver answers them) and answer false
//   lazy(bool-like m, fa, fb)  fa() where m, else fb(): the scalar layer
//                           calls one, the lanes both and select
//   T2, pair(a, b), lo, hi  two Ts as one (the scalar layer: an SSE2 register)
//   sel2(Mask, T2 a, T2 b)  sel for a T2
//   index(int), sel_index   a row number (an int, or one per lane) and the
//                           choice between two
//   kOneProblem             true where N holds one problem (the scalar
//                           layer): a formula may index rows by a row
//                           number and stop a test at its first false,
//                           where lanes select rows and test everything
//                           (polytope_simplex.hpp)
//   exp2_table(Bits j)      kExp2Table[j] (exp2_table.hpp), j in [0, 64)
//   times_pow2(v, t, j)     exp_any's last step, v 2^k for k = floor(n / 64)
//                           where t = n + 1.5 2^52 holds the integer n and
//                           j = n mod 64 (the scalar layer tests k's range
//                           and multiplies once where 2^k is normal, the
//                           lanes multiply twice always: the same bits)
//
// This header includes nothing and defines templates only, so that a lane
// translation unit compiled for AVX instantiates its own copies over its own
// internal types and no inline function compiled for one instruction set
// can stand in for another's.
#pragma once

namespace idcol::detail::formulas {

/// e^x for x <= 0, for the LogSumExp families (fast_math.hpp says how).
/// kFused: the argument reduction and the polynomial as fused multiply-adds
/// (the polytope face kernel's AVX2 form), else unfused. x < -708 and NaN
/// give 0.
template <class N, bool kFused = false>
[[gnu::always_inline]] inline typename N::T exp_nonpositive(typename N::T x) {
  using T = typename N::T;
  const auto ok = x >= -708.0;
  x = N::sel(ok, x, N::splat(-708.0));
  constexpr double kShifter = 0x1.8p52;  // t = x/ln2 + 1.5*2^52 rounds x/ln2 to an integer in t's low bits
  const T t = N::template mul_add<kFused>(x, N::splat(1.4426950408889634), N::splat(kShifter));
  const T n = t - kShifter;
  // (x - n ln2_hi) - n ln2_lo, ln2_hi of 32 significant bits (n ln2_hi is
  // exact), as n (-ln2_lo) + (n (-ln2_hi) + x): the same sums unfused.
  const T r = N::template mul_add<kFused>(n, N::splat(-1.90821492927058770002e-10),
                                          N::template mul_add<kFused>(n, N::splat(-6.93147180369123816490e-01), x));
  // e^r by its Taylor series to r^13, by Horner's rule.
  T p = N::splat(1.0 / 6227020800.0);
  constexpr double kC[13] = {1.0 / 479001600.0, 1.0 / 39916800.0, 1.0 / 3628800.0, 1.0 / 362880.0, 1.0 / 40320.0,
                             1.0 / 5040.0,      1.0 / 720.0,      1.0 / 120.0,     1.0 / 24.0,     1.0 / 6.0,
                             0.5,               1.0,              1.0};
  for (double c : kC) p = N::template mul_add<kFused>(p, r, N::splat(c));
  // t's low mantissa bits hold 2^51 + n; shifted by 52 only the 12 bits of
  // n + 1023 (in [1, 1023] here) survive: the biased exponent of 2^n.
  const T scale = N::from_bits((N::bits(t) + 1023) << 52);
  return N::sel(ok, p * scale, N::splat(0.0));
}

/// e^x over the whole double range (fast_math.hpp says how).
template <class N>
[[gnu::always_inline]] inline typename N::T exp_any(typename N::T x) {
  using T = typename N::T;
  x = N::sel(x < -746.0, N::splat(-746.0), x);
  x = N::sel(x > 710.0, N::splat(710.0), x);
  constexpr double kShifter = 0x1.8p52;
  const T t = x * (1.4426950408889634 * 64.0) + kShifter;  // 64 / ln2 (times 64: exact)
  const T n = t - kShifter;
  const T r = (x - n * (6.93147180369123816490e-01 / 64.0)) - n * (1.90821492927058770002e-10 / 64.0);
  const auto j = N::bits(t) & 63ull;
  const T tj = N::exp2_table(j);
  const T r2 = r * r;
  const T p = r + r2 * ((0.5 + r * (1.0 / 6.0)) + r2 * (1.0 / 24.0 + r * (1.0 / 120.0)));
  return N::times_pow2(tj + tj * p, t, j);
}

/// ln x for x > 0, subnormals included (fast_math.hpp says how). The
/// exponent field becomes a double by the 2^52 trick, exact.
template <class N>
[[gnu::always_inline]] inline typename N::T log_positive(typename N::T x) {
  using T = typename N::T;
  const auto sub = x < 0x1p-1022;
  x = N::sel(sub, x * 0x1p54, x);
  const auto bits = N::bits(x);
  // The biased exponent of x counted from 1022, so that m = x 2^-e is in
  // [1/2, 1); a mantissa above sqrt(1/2) has its exponent raised by one.
  T m = N::from_bits((bits & 0x000fffffffffffffull) | 0x3fe0000000000000ull);
  T e = (N::from_bits((bits >> 52) | 0x4330000000000000ull) - 0x1p52) - N::sel(sub, N::splat(1076.0), N::splat(1022.0));
  const auto low = m < 0.70710678118654752440;
  m = N::sel(low, m + m, m);
  e = N::sel(low, e - 1.0, e);
  const T f = (m - 1.0) / (m + 1.0);
  const T f2 = f * f, f4 = f2 * f2, f8 = f4 * f4;
  const T P = ((1.0 / 3.0 + f2 * (1.0 / 5.0)) + (1.0 / 7.0 + f2 * (1.0 / 9.0)) * f4) +
              ((1.0 / 11.0 + f2 * (1.0 / 13.0)) + (1.0 / 15.0 + f2 * (1.0 / 17.0)) * f4) * f8 +
              (1.0 / 19.0 + f2 * (1.0 / 21.0)) * (f8 * f8);
  const T lm = (f + f) + (f + f) * (f2 * P);
  const T r = e * 6.93147180369123816490e-01 + (e * 1.90821492927058770002e-10 + lm);
  return N::sel(x == 0.0, N::splat(-__builtin_huge_val()), N::sel(x <= 0x1.fffffffffffffp1023, r, x));  // inf, NaN pass
}

/// ln x for x in [1, 1e300] (the smooth polytope's weight sum, in [1, m]),
/// within about an ulp: x = 2^e f with f in [1/sqrt 2, sqrt 2) (the
/// exponent field a double by the 2^52 trick, exact), ln f = 2 atanh(s),
/// s = (f - 1) / (f + 1), by its series to s^21, and e ln2 with ln2 split
/// as in exp_nonpositive (truncation below 1e-18 relative; test_shapes:
/// PolytopeFaceKernelMatchesItsDefinition). Inline: the call to the
/// library's log, and the registers it clobbers, cost the face kernel as
/// much as its exp. x outside (0, a NaN from a point with an infinite
/// coordinate) leaves: the scalar layer answers N::log(x), the lanes flag.
template <class N>
[[gnu::always_inline]] inline typename N::T log_ge1(typename N::T x, typename N::Mask& bad) {
  using T = typename N::T;
  if (N::leaves(N::not_((x >= 1.0) & (x <= 1e300)), bad)) return N::log(x);
  const auto bits = N::bits(x);
  T e = (N::from_bits((bits >> 52) | 0x4330000000000000ull) - 0x1p52) - 1023.0;
  T f = N::from_bits((bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull);  // in [1, 2)
  const auto big = f > 1.4142135623730951;
  f = N::sel(big, f * 0.5, f);
  e = N::sel(big, e + 1.0, e);
  const T s = (f - 1.0) / (f + 1.0);
  const T z = s * s;
  T p = N::splat(1.0 / 21.0);
  constexpr double kC[9] = {1.0 / 19.0, 1.0 / 17.0, 1.0 / 15.0, 1.0 / 13.0, 1.0 / 11.0, 1.0 / 9.0, 1.0 / 7.0, 1.0 / 5.0, 1.0 / 3.0};
  for (double c : kC) p = p * z + c;
  const T hs = 2.0 * s;
  return (e * 6.93147180369123816490e-01 + hs) + (hs * (z * p) + e * 1.90821492927058770002e-10);
}

/// t^k for t in [0, 1] and k > 0 (fast_math.hpp).
template <class N>
[[gnu::always_inline]] inline typename N::T pow_unit(typename N::T t, double k) {
  return exp_any<N>(k * log_positive<N>(t));
}

/// sqrt(a^2 + b^2) without overflow or underflow on the way (fast_math.hpp).
template <class N>
[[gnu::always_inline]] inline typename N::T hypot_any(typename N::T a, typename N::T b) {
  using T = typename N::T;
  a = N::abs(a);
  b = N::abs(b);
  const T m = N::sel(a > b, a, b);
  const auto big = m > 0x1p500, small = m < 0x1p-500;
  const T f = N::sel(big, N::splat(0x1p-600), N::sel(small, N::splat(0x1p600), N::splat(1.0)));  // g = 1/f
  const T g = N::sel(big, N::splat(0x1p600), N::sel(small, N::splat(0x1p-600), N::splat(1.0)));
  a = a * f;
  b = b * f;
  const T r = N::sqrt(a * a + b * b) * g;
  const T inf = N::splat(__builtin_huge_val());
  return N::sel(a == __builtin_huge_val(), inf, N::sel(b == __builtin_huge_val(), inf, r));
}

}  // namespace idcol::detail::formulas
