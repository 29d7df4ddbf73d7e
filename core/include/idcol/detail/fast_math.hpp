// Inline elementary functions whose every operation the batch lanes repeat
// (batch_simd_kernel.hpp, newton_lanes_*.hpp), so that a lane forms the
// scalar solver's bits: glibc's exp, log, pow and hypot are out-of-line calls,
// one per lane, and they also keep the compiler from vectorising the
// polytope's loop over its faces.
//
// Each is written once, over a number layer, in formulas/elementary.hpp,
// for this scalar code and the lanes alike; here are the scalar entry
// points and what each computes.
//
// exp_nonpositive: e^x for x <= 0, for the LogSumExp families, whose
// exponents are <= 0 once the maximum is shifted out. Method: x = n ln2 + r
// with |r| <= ln2/2 (n by the round-to-nearest shifter trick, ln2 split in
// two so that n ln2_hi is exact), e^r by its Taylor series to r^13
// (truncation below 5e-18 relative), and 2^n built in the exponent field.
// Relative error within 2.5e-16 (about 1 ulp; test_shapes checks it against
// std::exp). x < -708 (e^x below the normal range) returns 0, and so does
// x = -inf; NaN is not expected (the arguments are differences of finite
// numbers) and gives an unspecified value.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "idcol/detail/formulas/elementary.hpp"
#include "idcol/detail/scalar_num.hpp"

namespace idcol::detail {

inline double exp_nonpositive(double x) { return formulas::exp_nonpositive<ScalarNum>(x); }

/// e^x over the whole double range, inline, for alpha = e^s of the KKT
/// point (kkt.hpp). The batch lanes run the same template, so that a lane's
/// alpha is the scalar solver's to the bit; glibc's exp is an out-of-line
/// call per lane.
///
/// x = (64 k + j) ln2 / 64 + r with |r| <= ln2 / 128 (N = 64 k + j by the
/// shifter trick, ln2 / 64 split in two so that N ln2_hi / 64 is exact), and
/// e^x = 2^k 2^(j/64) e^r: 2^(j/64) from kExp2Table, e^r - 1 by its Taylor
/// series to r^5 (truncation below 4e-17 relative), 2^k built in the
/// exponent field. Where 2^k is not a normal double (x beyond about +-708),
/// 2^k is applied as 2^k1 2^k2 with both halves normal: the first product is
/// exact, so the one rounding is the same as the single product's, and the
/// result overflows to inf above x = 709.78 and falls through the
/// subnormals to 0 below -708, as e^x does. x above 710 is 710 (inf), x
/// below -746 is -746 (0), NaN gives NaN. Relative error within 2.3e-16 over
/// the normal range (test_shapes checks it against std::exp).
inline double exp_any(double x) { return formulas::exp_any<ScalarNum>(x); }

/// ln x for x > 0 (subnormals included), for pow_unit. x = 2^e m with m in
/// [1/sqrt 2, sqrt 2) (a subnormal x is first scaled by 2^54), and
/// ln m = 2 atanh(f), f = (m - 1) / (m + 1), |f| <= 0.1716, by its series
/// 2 f + 2 f f^2 (1/3 + f^2/5 + ... + f^18/21) (truncation below 1e-18
/// relative); then e ln2 + ln m with ln2 split as in exp_nonpositive.
/// Relative error within 4e-16 away from x = 1, absolute within 3e-17 near
/// it (test_shapes). x = 0 gives -inf; inf and NaN pass through.
inline double log_positive(double x) { return formulas::log_positive<ScalarNum>(x); }

/// t^k for t in [0, 1] and k > 0: e^(k ln t), for the superquadric support
/// point's |v_i|^(1/(2n-1)) (shapes.cpp), whose batch lanes repeat it. The
/// error of k ln t reaches the result relative to t^k, and t^k |ln t| <=
/// 1/(e k): the absolute error stays within a few units of 1 however small
/// t is. t = 0 gives 0.
inline double pow_unit(double t, double k) { return formulas::pow_unit<ScalarNum>(t, k); }

/// sqrt(a^2 + b^2) without overflow or underflow on the way: where the
/// larger magnitude lies outside [2^-500, 2^500] both are first scaled by
/// 2^600 or 2^-600 (exact) and the root scaled back. Within about 1 unit in
/// the last place; an infinite argument gives inf, as std::hypot does, and
/// NaN otherwise gives NaN.
inline double hypot_any(double a, double b) { return formulas::hypot_any<ScalarNum>(a, b); }

}  // namespace idcol::detail
