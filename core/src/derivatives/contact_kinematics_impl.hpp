// The formulas of contact_kinematics() (derivatives.cpp) from the numbers
// they read, so that the SIMD batch path, which has no SolveResult for the
// rows it answers in lanes, writes the same kinematics to the bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "idcol/derivatives.hpp"
#include "idcol/detail/formulas/derivatives.hpp"
#include "idcol/detail/scalar_num.hpp"
#include "idcol/types.hpp"

namespace idcol::detail {

/// |v|, scaled so that it neither overflows nor underflows
/// (formulas::stable_norm; Eigen's stableNorm picks its order of summation
/// from the vector's address at run time, so the same vector could round
/// differently in two places): 0, inf or NaN where v holds only zeros, an
/// infinity or a NaN.
inline double stable_norm3(const Vec3& v) { return formulas::stable_norm<ScalarNum>(v.data()); }

/// v / |v| (v itself where it is zero or not finite).
inline Vec3 stable_normalized3(const Vec3& v) {
  double u[3];
  formulas::stable_normalized<ScalarNum>(v.data(), u);
  return Vec3(u[0], u[1], u[2]);
}

/// alpha* and x_1 of a converged answer, r = p_12 of its pose, and body 1's
/// gradient at its witness point (SolveResult::internal.e1.grad).
inline ContactKinematics kinematics_from(double a, const Vec3& x_1, const Vec3& r, const Vec3& grad1) {
  ContactKinematics c;
  c.alpha = a;
  c.x_1 = x_1;
  // Divided, not multiplied by 1/alpha, so a subnormal alpha (|r| < 1e-308)
  // still gives finite points and gap (found by fuzz_solve).
  c.p1_1 = x_1 / a;                     // eq:witness
  // x and r divided separately: x - r overflows when |r| is near the double
  // range and x lies on the other side of the origin (found by fuzz_solve:
  // r = (-1.8e308, -10, -10), x_1 = 3.2e307).
  c.p2_1 = r + (x_1 / a - r / a);       // eq:witness
  // Scaled: r.norm() squares the entries and underflows to 0 for
  // |r| < 1e-154, where the solver itself still converges (found by fuzz_solve).
  const double nr = stable_norm3(r);
  c.gap = formulas::contact_gap<ScalarNum>(nr, a);  // eq:gap
  // |r| / alpha is the sum of the two bodies' extents along r: for bodies
  // near the double range (radii 1e300 and 1.8e308, found by fuzz_solve) it
  // overflows although p2 may fit. Halved, then doubled; what still
  // overflows does not fit in a double (the gap -(R1 + R2) + |r| there).
  if (!c.p2_1.allFinite()) c.p2_1 = 2.0 * (0.5 * r + ((0.5 * x_1) / a - (0.5 * r) / a));
  c.nhat_1 = stable_normalized3(grad1);  // eq:unit_normal
  c.representable = c.p1_1.allFinite() && c.p2_1.allFinite() && std::isfinite(c.gap);
  c.valid = true;
  return c;
}

}  // namespace idcol::detail
