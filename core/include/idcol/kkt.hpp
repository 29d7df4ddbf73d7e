// The KKT residual (eq:kkt_residual) and its Jacobian (eq:kkt_jacobian) in
// s = log(alpha) (Sec. "Scaling Reparameterization and Bounds"), for the
// surrogate problem (Sec. "Surrogate Formulation"), templated on the pair.
//
// Coordinates. The surrogate replaces r by r_S = f_S L r_hat with the pair
// length L = r1_out + r2_out; lengths are further divided by L, and the
// witness point is measured from the point c1 = w r_S, w = r1_out / L, that
// splits the segment between the frame origins in the ratio of the bodies'
// sizes. The unknowns are z = (xi, s, lambda1, lambda2) with
// x_S = L (xi + c1), alpha_S = e^s, and with c2 = r_S - c1 = (r2_out / L) r_S
//   y1 = (L / alpha) (xi + c1),      y2 = (L / alpha) R^T (xi - c2),
// so neither y1 nor y2 is formed by cancellation, even when one body is 1e6
// times smaller than the other. (A shift of the unknown leaves the Newton
// step and the Jacobian unchanged.)
//   F0 = phi1(y1) / sigma1,          F1 = phi2(y2) / sigma2,
//   F2..4 = (L / alpha) (lambda1 grad phi1 + lambda2 R grad phi2),
//   F5 = 1 - (lambda1 y1.grad phi1 + lambda2 y2.grad phi2) / alpha,
// where sigma_i = phi_scale() makes the constraint rows dimensionless. This is
// the paper's residual with rows scaled by (1/sigma1, 1/sigma2, L, L, L, 1);
// row scaling leaves the Newton step unchanged.
#pragma once

#include <algorithm>
#include <cmath>

#include "idcol/detail/fast_math.hpp"
#include "idcol/detail/formulas/kkt.hpp"
#include "idcol/shapes.hpp"

namespace idcol {

/// The data of one surrogate problem: the pair, the relative rotation, the
/// direction of r and the sharpness at which each shape is evaluated.
template <class S1, class S2>
struct KktProblem {
  const S1* s1;
  const S2* s2;
  Mat3 R;          // R_12
  Vec3 c1;         // w f_S r_hat: origin of xi, from body 1's frame origin (units of L)
  Vec3 c2;         // (1 - w) f_S r_hat: from that origin to body 2's frame origin
  double L;        // pair length scale r1_out + r2_out
  double sharp1;   // sharpness used for body 1 (its own, or a continuation stage)
  double sharp2;
  double inv_sigma1;
  double inv_sigma2;
};

/// Everything evaluated at one z, kept so that an accepted line-search trial
/// is not evaluated twice.
struct KktPoint {
  Vec6 z;
  Vec6 F;
  double alpha;
  double ia;  // 1 / alpha as kkt_residual forms it (e^-s), which the Jacobian multiplies by
  Vec3 y1, y2;
  ShapeEval e1, e2;
  Vec3 g2w;  // R grad phi2, in body-1 coordinates
};

/// F(z) (eq:kkt_residual, scaled as described above).
template <class S1, class S2>
inline void kkt_residual(const KktProblem<S1, S2>& P, const Vec6& z, KktPoint& p) {
  p.z = z;
  detail::formulas::kkt_residual<detail::ScalarNum>(
      P.R, P.c1, P.c2, P.L, P.inv_sigma1, P.inv_sigma2, z, p, [&](const Vec3& y, ShapeEval& e) { P.s1->eval(y, P.sharp1, e); },
      [&](const Vec3& y, ShapeEval& e) { P.s2->eval(y, P.sharp2, e); });
}

/// The convergence measure: every KKT condition as a relative error, so that
/// it means the same for every family and scale and is not dominated by
/// rounding when one gradient is huge (a 1000:1 body):
///   |phi_i| / (|y_i| |grad phi_i|)       relative distance to surface i,
///   |l1 g1 + l2 R g2| / (l1 |g1| + l2 |g2|)   misalignment of the normals,
///   |F5|                                  stationarity in alpha (already relative).
/// The terms are formulas::kkt_relative_terms, which the batch lanes run too.
inline double kkt_relative_residual(const KktPoint& p) {
  double t[4];
  detail::formulas::kkt_relative_terms<detail::ScalarNum>(p, t);
  return std::max({t[0], t[1], t[2], t[3]});
}

/// The first two terms of kkt_relative_residual: the larger relative
/// distance of the two witness points to their surfaces, |phi_i| / (|y_i|
/// |grad phi_i|). They fix alpha to first order; the alignment of the
/// normals and the stationarity in alpha, to second order only.
inline double kkt_surface_residual(const KktPoint& p) {
  const double d1 = p.y1.norm() * p.e1.grad.norm(), d2 = p.y2.norm() * p.e2.grad.norm();
  return std::max(d1 > 0.0 ? std::abs(p.e1.phi) / d1 : std::abs(p.e1.phi), d2 > 0.0 ? std::abs(p.e2.phi) / d2 : std::abs(p.e2.phi));
}

/// The part of kkt_relative_residual that rounding alone leaves at p. Moving
/// a witness point by a unit in the last place of its coordinates turns its
/// normal by about eps |y_i| |hess phi_i| / |grad phi_i|, and no iteration in
/// doubles can align the normals better than that. For almost every pair this
/// is 1e-14 or less, far under any tolerance; it reaches 1e-10 to 1e-9 only
/// for a body whose surface curves over a length 10^6 times shorter than its
/// distance from its frame origin (the beta = 10^4 rim of a 1000:1 needle
/// cone, 3.6 from its centre with a rim radius of 0.004).
///
/// The same move changes the stationarity in alpha, F5 = 1 - sum_i lambda_i
/// (y_i . grad phi_i) / alpha, by eps |y_i| |d(y_i . grad phi_i)/dy_i| =
/// eps |y_i| |grad phi_i + hess phi_i y_i| per body, weighted by
/// lambda_i / alpha. The term y . grad phi is the support-like quantity whose
/// terms are summed in F5; at a corner of a sharp body far from its origin
/// it changes much faster than the normal turns: the far corner of the
/// beta h / L = 10^6 box needle of the stress suite (box_needle_plate), 10
/// from its centre with a rounding length 1e-5, leaves F5 at 2-4e-10 while
/// the normals align to 1e-11.
inline double kkt_rounding_floor(const KktPoint& p) {
  constexpr double kUlps = 8.0 * 2.220446049250313e-16;
  auto turn = [](const Vec3& y, const ShapeEval& e) {
    const double g = e.grad.norm();
    return g > 0.0 ? y.norm() * e.hess.norm() / g : 0.0;
  };
  auto stationarity = [&p](double lambda, const Vec3& y, const ShapeEval& e) {
    return std::abs(lambda) / p.alpha * y.norm() * (e.grad + e.hess * y).norm();
  };
  const double f5 = stationarity(p.z[4], p.y1, p.e1) + stationarity(p.z[5], p.y2, p.e2);
  const double f = kUlps * std::max({turn(p.y1, p.e1), turn(p.y2, p.e2), f5});
  return std::isfinite(f) ? f : 0.0;
}

/// dF/dz at a point evaluated by kkt_residual (eq:kkt_jacobian, with the
/// chain rule (.)_s = (.)_alpha alpha and eq:phi_partials).
///
/// Written once for the loop and the lanes (formulas/kkt.hpp), entry by
/// entry in the order of operations Eigen 3.4's expressions of this formula
/// took with the library built for SSE2, rows 0 and 1 of each 3x3 product
/// as a pair (8% fewer instructions than the expressions, the same bits).
template <class S1, class S2, class M6>
inline void kkt_jacobian(const KktProblem<S1, S2>& P, const KktPoint& p, M6& J) {
  detail::formulas::kkt_jacobian<detail::ScalarNum>(P.R, P.L, P.inv_sigma1, P.inv_sigma2, p, J);
}

}  // namespace idcol
