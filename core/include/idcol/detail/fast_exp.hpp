// e^x for x <= 0, inline and branch-free, for the LogSumExp families, whose
// exponents are <= 0 once the maximum is shifted out. glibc's exp is an
// out-of-line call, which also keeps the compiler from vectorising the
// polytope's loop over its faces.
//
// Method: x = n ln2 + r with |r| <= ln2/2 (n by the round-to-nearest shifter
// trick, ln2 split in two so that n ln2_hi is exact), e^r by its Taylor series
// to r^13 (truncation below 5e-18 relative), and 2^n built in the exponent
// field. Relative error within 2.5e-16 (about 1 ulp; test_shapes checks it
// against std::exp). x < -708 (e^x below the normal range) returns 0, and so
// does x = -inf; NaN is not expected (the arguments are differences of finite
// numbers) and gives an unspecified value.
#pragma once

#include <cstdint>
#include <cstring>

namespace idcol::detail {

inline double exp_nonpositive(double x) {
  // Selects, not branches: with -fno-trapping-math (set for shapes.cpp) GCC
  // if-converts them and vectorises the polytope's loop over its faces.
  const bool tiny = !(x >= -708.0);
  x = tiny ? -708.0 : x;
  constexpr double kShifter = 0x1.8p52;  // t = x/ln2 + 1.5*2^52 rounds x/ln2 to an integer in t's low bits
  constexpr double kLog2e = 1.4426950408889634;
  constexpr double kLn2Hi = 6.93147180369123816490e-01;  // 32 significant bits: n * kLn2Hi is exact
  constexpr double kLn2Lo = 1.90821492927058770002e-10;
  const double t = x * kLog2e + kShifter;
  const double n = t - kShifter;
  const double r = (x - n * kLn2Hi) - n * kLn2Lo;
  double p = 1.0 / 6227020800.0;  // 1/13!
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  // t's low mantissa bits hold 2^51 + n; shifted by 52 only the 12 bits of
  // n + 1023 (in [1, 1023] here) survive: the biased exponent of 2^n.
  std::uint64_t bits;
  std::memcpy(&bits, &t, sizeof bits);
  bits = (bits + 1023) << 52;
  double scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return tiny ? 0.0 : p * scale;
}

}  // namespace idcol::detail
