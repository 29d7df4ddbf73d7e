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
