// The formulas of contact_kinematics() (derivatives.cpp) from the numbers
// they read, so that the SIMD batch path, which has no SolveResult for the
// rows it answers in lanes, writes the same kinematics to the bit.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "idcol/derivatives.hpp"
#include "idcol/types.hpp"

namespace idcol::detail {

/// v scaled by its largest |entry| m, u = v / m, and n = |u|, summed in one
/// fixed order, so that |v| = m n neither overflows nor underflows (as
/// Eigen's stableNorm): Eigen's reductions of a 3-vector pick their order
/// from its address at run time, so the same vector could round
/// differently in two places. False, with u and n unset, when m is 0, inf
/// or NaN.
inline bool scaled3(const Vec3& v, double& m, Vec3& u, double& n) {
  m = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  if (std::isnan(v[0]) || std::isnan(v[1]) || std::isnan(v[2])) m = std::numeric_limits<double>::quiet_NaN();
  if (!(m > 0.0) || !std::isfinite(m)) return false;
  u = Vec3(v[0] / m, v[1] / m, v[2] / m);
  n = std::sqrt((u[0] * u[0] + u[1] * u[1]) + u[2] * u[2]);
  return true;
}

/// |v|: 0, inf or NaN where v holds only zeros, an infinity or a NaN.
inline double stable_norm3(const Vec3& v) {
  double m, n;
  Vec3 u;
  return scaled3(v, m, u, n) ? m * n : m;
}

/// v / |v| (v itself where it is zero or not finite).
inline Vec3 stable_normalized3(const Vec3& v) {
  double m, n;
  Vec3 u;
  return scaled3(v, m, u, n) ? Vec3(u / n) : v;
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
  c.gap = nr - nr / a;                  // eq:gap
  // |r| / alpha is the sum of the two bodies' extents along r: for bodies
  // near the double range (radii 1e300 and 1.8e308, found by fuzz_solve) it
  // overflows although p2 may fit. Halved, then doubled; what still
  // overflows does not fit in a double (the gap -(R1 + R2) + |r| there).
  if (!c.p2_1.allFinite()) c.p2_1 = 2.0 * (0.5 * r + ((0.5 * x_1) / a - (0.5 * r) / a));
  if (!std::isfinite(c.gap)) c.gap = 2.0 * (0.5 * nr - (0.5 * nr) / a);
  c.nhat_1 = stable_normalized3(grad1);  // eq:unit_normal
  c.representable = c.p1_1.allFinite() && c.p2_1.allFinite() && std::isfinite(c.gap);
  c.valid = true;
  return c;
}

}  // namespace idcol::detail
