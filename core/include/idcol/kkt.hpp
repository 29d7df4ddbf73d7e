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
#include <cstring>

#include "idcol/detail/fast_math.hpp"
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
  Vec3 y1, y2;
  ShapeEval e1, e2;
  Vec3 g2w;  // R grad phi2, in body-1 coordinates
};

/// F(z) (eq:kkt_residual, scaled as described above).
template <class S1, class S2>
inline void kkt_residual(const KktProblem<S1, S2>& P, const Vec6& z, KktPoint& p) {
  p.z = z;
  // 1/alpha = e^-s first: the witness points need only it, and the division
  // for alpha itself leaves their path (the batch lanes, which form the same
  // bits, wait on that path; fast_math.hpp).
  const double ia = detail::exp_any(-z[3]);
  p.alpha = 1.0 / ia;
  const double c = P.L * ia;
  const Vec3 xi = z.template head<3>();
  p.y1 = c * (xi + P.c1);
  p.y2 = c * (P.R.transpose() * (xi - P.c2));
  P.s1->eval(p.y1, P.sharp1, p.e1);
  P.s2->eval(p.y2, P.sharp2, p.e2);
  p.g2w = P.R * p.e2.grad;
  const double l1 = z[4], l2 = z[5];
  p.F[0] = p.e1.phi * P.inv_sigma1;
  p.F[1] = p.e2.phi * P.inv_sigma2;
  p.F.template segment<3>(2) = c * (l1 * p.e1.grad + l2 * p.g2w);
  p.F[5] = 1.0 - (l1 * p.y1.dot(p.e1.grad) + l2 * p.y2.dot(p.e2.grad)) * ia;
}

/// The convergence measure: every KKT condition as a relative error, so that
/// it means the same for every family and scale and is not dominated by
/// rounding when one gradient is huge (a 1000:1 body):
///   |phi_i| / (|y_i| |grad phi_i|)       relative distance to surface i,
///   |l1 g1 + l2 R g2| / (l1 |g1| + l2 |g2|)   misalignment of the normals,
///   |F5|                                  stationarity in alpha (already relative).
inline double kkt_relative_residual(const KktPoint& p) {
  const double n1 = p.e1.grad.norm(), n2 = p.e2.grad.norm();
  const double d1 = p.y1.norm() * n1, d2 = p.y2.norm() * n2;
  const double e1 = d1 > 0.0 ? std::abs(p.e1.phi) / d1 : std::abs(p.e1.phi);
  const double e2 = d2 > 0.0 ? std::abs(p.e2.phi) / d2 : std::abs(p.e2.phi);
  const double l1 = p.z[4], l2 = p.z[5];
  const double w = std::abs(l1) * n1 + std::abs(l2) * n2;
  const double es = w > 0.0 ? (l1 * p.e1.grad + l2 * p.g2w).norm() / w : 1.0;
  return std::max({e1, e2, es, std::abs(p.F[5])});
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

namespace detail {
/// Two doubles as one SSE2 register (GCC/Clang vector extension): each lane
/// makes the scalar operation, so code written in pairs gives the bits of
/// the same code written lane by lane.
using Pair = double __attribute__((vector_size(16)));
inline Pair load_pair(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store_pair(double* p, Pair v) { std::memcpy(p, &v, sizeof v); }
}  // namespace detail

/// dF/dz at a point evaluated by kkt_residual (eq:kkt_jacobian, with the
/// chain rule (.)_s = (.)_alpha alpha and eq:phi_partials).
///
/// Written out entry by entry in the order of operations that Eigen 3.4's
/// expressions of this formula took with the library built for SSE2 (a 3x3
/// matrix times a vector or a matrix: rows 0 and 1 as (t0 + t1) + t2, row 2
/// as t0 + (t1 + t2); dot products (t0 + t1) + t2), which the batch lanes
/// repeat too (newton_lanes_kernel.hpp, jacobian): the same bits, in 8%
/// fewer instructions than the expression templates (434 against 470 a call
/// on the Poly-Poly cold sweep, callgrind). Rows 0 and 1 of each 3x3
/// product run as pairs (detail::Pair) over the column-major matrices.
template <class S1, class S2, class M6>
inline void kkt_jacobian(const KktProblem<S1, S2>& P, const KktPoint& p, M6& J) {
  using detail::Pair;
  using detail::load_pair;
  const double a = p.alpha, c = P.L / a;
  const double l1 = p.z[4], l2 = p.z[5];
  const double* g1 = p.e1.grad.data();
  const double* g2 = p.e2.grad.data();
  const double* g2w = p.g2w.data();
  const double* H1 = p.e1.hess.data();  // column-major: H(k, j) = H[k + 3 j]
  const double* H2 = p.e2.hess.data();
  const double* R = P.R.data();  // column-major
  const double* y1 = p.y1.data();
  const double* y2 = p.y2.data();
  auto tail = [](double t0, double t1, double t2) { return t0 + (t1 + t2); };
  const Pair R0 = load_pair(R), R1 = load_pair(R + 3), R2 = load_pair(R + 6);  // rows 0-1 of R's columns
  // RH2 = R H2, column j: rows 0-1 in rh[j], row 2 in rh2[j].
  Pair rh[3];
  double rh2[3];
  for (int j = 0; j < 3; ++j) {
    const double* h = H2 + 3 * j;
    rh[j] = (R0 * h[0] + R1 * h[1]) + R2 * h[2];
    rh2[j] = tail(R[2] * h[0], R[5] * h[1], R[8] * h[2]);
  }
  // H2w = RH2 R^T, column j: rows 0-1 in hw[j], row 2 in hw2[j].
  Pair hw[3];
  double hw2[3];
  for (int j = 0; j < 3; ++j) {
    const double r0 = R[j], r1 = R[j + 3], r2 = R[j + 6];  // R(j, k)
    hw[j] = (rh[0] * r0 + rh[1] * r1) + rh[2] * r2;
    hw2[j] = tail(rh2[0] * r0, rh2[1] * r1, rh2[2] * r2);
  }
  // H1 y1, R H2 y2, H2 y2.
  const Pair H10 = load_pair(H1), H11 = load_pair(H1 + 3), H12 = load_pair(H1 + 6);
  const Pair h1y = (H10 * y1[0] + H11 * y1[1]) + H12 * y1[2];
  const double h1y2 = tail(H1[2] * y1[0], H1[5] * y1[1], H1[8] * y1[2]);
  const Pair h2yw = (rh[0] * y2[0] + rh[1] * y2[1]) + rh[2] * y2[2];
  const double h2yw2 = tail(rh2[0] * y2[0], rh2[1] * y2[1], rh2[2] * y2[2]);
  const Pair h2y = (load_pair(H2) * y2[0] + load_pair(H2 + 3) * y2[1]) + load_pair(H2 + 6) * y2[2];
  const double h2y2 = tail(H2[2] * y2[0], H2[5] * y2[1], H2[8] * y2[2]);
  const double h1 = (y1[0] * g1[0] + y1[1] * g1[1]) + y1[2] * g1[2];
  const double h2 = (y2[0] * g2[0] + y2[1] * g2[1]) + y2[2] * g2[2];
  const double q1 = (y1[0] * h1y[0] + y1[1] * h1y[1]) + y1[2] * h1y2;
  const double q2 = (y2[0] * h2y[0] + y2[1] * h2y[1]) + y2[2] * h2y2;
  const double cs1 = c * P.inv_sigma1, cs2 = c * P.inv_sigma2;
  J(0, 0) = cs1 * g1[0], J(0, 1) = cs1 * g1[1], J(0, 2) = cs1 * g1[2];
  J(0, 3) = -h1 * P.inv_sigma1, J(0, 4) = 0.0, J(0, 5) = 0.0;
  J(1, 0) = cs2 * g2w[0], J(1, 1) = cs2 * g2w[1], J(1, 2) = cs2 * g2w[2];
  J(1, 3) = -h2 * P.inv_sigma2, J(1, 4) = 0.0, J(1, 5) = 0.0;
  // c^2 (l1 H1 + l2 H2w), column j: rows 2-3 of J as a pair, row 4 alone.
  const double cc = c * c;
  const Pair H1c[3] = {H10, H11, H12};
  for (int j = 0; j < 3; ++j) {
    const Pair v = cc * (l1 * H1c[j] + l2 * hw[j]);
    J(2, j) = v[0];
    J(3, j) = v[1];
    J(4, j) = cc * (l1 * H1[2 + 3 * j] + l2 * hw2[j]);
  }
  // t = l1 (g1 + H1 y1) + l2 (g2w + R H2 y2): rows 0-1 as a pair.
  const Pair t01 = l1 * (load_pair(g1) + h1y) + l2 * (load_pair(g2w) + h2yw);
  const double t2 = l1 * (g1[2] + h1y2) + l2 * (g2w[2] + h2yw2);
  const double mc = -c, ca = -(c / a);
  J(2, 3) = mc * t01[0], J(3, 3) = mc * t01[1], J(4, 3) = mc * t2;
  for (int i = 0; i < 3; ++i) {
    J(2 + i, 4) = c * g1[i];
    J(2 + i, 5) = c * g2w[i];
  }
  J(5, 0) = ca * t01[0], J(5, 1) = ca * t01[1], J(5, 2) = ca * t2;
  J(5, 3) = (l1 * (2.0 * h1 + q1) + l2 * (2.0 * h2 + q2)) / a;
  J(5, 4) = -h1 / a;
  J(5, 5) = -h2 / a;
}

}  // namespace idcol
