// What the derivative tests difference: every output of a solve that has a
// derivative, flattened, from a tight cold solve. Shared by the pose
// (test_derivatives.cpp) and shape-parameter (test_shape_derivatives.cpp)
// tests so that both difference the same quantities in the same order.
#pragma once

#include <Eigen/Core>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

namespace idcol::test {

/// Options of every solve that is differenced: the factorisation kept and a
/// tolerance far below the differences' rounding.
inline SolverOptions tight() {
  SolverOptions o = with_derivatives();
  o.tolerance = 1e-13;
  return o;
}

/// The pair length L = r1_out + r2_out that makes lengths dimensionless.
inline double pair_length(const Shape& a, const Shape& b) { return radii(a).outer + radii(b).outer; }

/// x(3), alpha, lambda1, lambda2, p1(3), p2(3), nhat(3), gap, F1(6), F2(6).
constexpr int kN = 28;
using Vals = Eigen::Matrix<double, kN, 1>;
inline const HertzModel kHertz{1.0, 1.5};

/// The values at pose X, false if the solve did not converge.
inline bool values(const Shape& a, const Shape& b, const Pose& X, Vals& v) {
  const SolveResult r = solve(a, b, X, tight());
  if (!r.converged()) return false;
  const ContactKinematics c = contact_kinematics(r);
  const ContactWrench w = contact_wrench(r, kHertz);
  v << r.x_1, r.alpha, r.lambda1, r.lambda2, c.p1_1, c.p2_1, c.nhat_1, c.gap, w.F1_1, w.F2_2;
  return true;
}

}  // namespace idcol::test
