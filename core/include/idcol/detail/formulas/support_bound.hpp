// The support functions of the families, h(u) = max over the body of u . y
// (or an upper bound on it where the body is smooth), and the certified
// lower bound on alpha* that SolverOptions::alpha_max is tested against
// (PairSolver::separated_at_start), written once over a number layer N
// (elementary.hpp) for the shapes' support() (shapes.hpp) and the batch
// lanes' screen of the rows Separated at once (newton_lanes_kernel.hpp), so
// that a lane's bound is the loop's, bit for bit. A vector argument u is
// anything with u[0..2].
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/elementary.hpp"

namespace idcol::detail::formulas {

/// std::max(a, b): b where a < b, else a.
template <class N>
[[gnu::always_inline]] inline typename N::T max2(typename N::T a, typename N::T b) {
  return N::sel(a < b, b, a);
}

/// ||(v0, v1, v2)||_p for v_i >= 0: m ((v0/m)^p + (v1/m)^p + (v2/m)^p)^(1/p)
/// with m = max v_i, and 0 where m is not positive.
template <class N>
[[gnu::always_inline]] inline typename N::T pnorm3(typename N::T v0, typename N::T v1, typename N::T v2, double p) {
  using T = typename N::T;
  const T m = max2<N>(v0, max2<N>(v1, v2));
  const T s = (N::pow(v0 / m, p) + N::pow(v1 / m, p)) + N::pow(v2 / m, p);
  return N::sel(m > 0.0, m * N::pow(s, 1.0 / p), N::splat(0.0));
}

/// The superellipsoid's (semi-axes ax[0..2], exponent n), exact: the dual norm
/// ||diag(ax) u||_q, q = 2n / (2n - 1); the Euclidean norm for n = 1.
template <class N, class A, class U>
[[gnu::always_inline]] inline typename N::T superellipsoid_support_value(const A& ax, double n, const U& u) {
  using T = typename N::T;
  const T v0 = N::abs(ax[0] * u[0]), v1 = N::abs(ax[1] * u[1]), v2 = N::abs(ax[2] * u[2]);
  if (n == 1.0) return N::sqrt((v0 * v0 + v1 * v1) + v2 * v2);
  return pnorm3<N>(v0, v1, v2, 2.0 * n / (2.0 * n - 1.0));
}

/// The superelliptic cylinder's (half-height h, radius R, exponent n),
/// exact: ||(h |u0|, R |(u1, u2)|)||_q, q = 2n / (2n - 1).
template <class N, class U>
[[gnu::always_inline]] inline typename N::T cylinder_support_value(double h, double R, double n, const U& u) {
  using T = typename N::T;
  const T v0 = h * N::abs(u[0]), v1 = R * N::hypot(u[1], u[2]);
  if (n == 1.0) return N::hypot(v0, v1);
  return pnorm3<N>(v0, v1, N::splat(0.0), 2.0 * n / (2.0 * n - 1.0));
}

/// The exact frustum's (base radius Rb at x = -a, top radius Rt at x = b),
/// which holds the smooth truncated cone: the larger of its end discs'.
template <class N, class U>
[[gnu::always_inline]] inline typename N::T cone_support_value(double Rb, double Rt, double a, double b, const U& u) {
  using T = typename N::T;
  const T w = N::hypot(u[1], u[2]);
  return max2<N>(-a * u[0] + Rb * w, b * u[0] + Rt * w);
}

/// The exact polytope's (vertices vert(i, 0..2), i < nv), which holds the
/// smooth one: the largest u . v, each (t0 + t1) + t2 as Eigen's dot.
template <class N, class U, class Fv>
[[gnu::always_inline]] inline typename N::T polytope_support_value(int nv, Fv&& vert, const U& u) {
  using T = typename N::T;
  T h = N::splat(-__builtin_inf());
  for (int i = 0; i < nv; ++i) h = max2<N>(h, (u[0] * vert(i, 0) + u[1] * vert(i, 1)) + u[2] * vert(i, 2));
  return h;
}

/// PairSolver::alpha_lower_bound: with u = r_hat, the scaled body 1 lies in
/// the half-space u . x <= alpha h1(u) and the scaled body 2, placed at r,
/// in u . x >= |r| - alpha h2(-R^T u): the two can only meet when
/// alpha (h1 + h2) >= |r|. The factor below 1 covers the rounding of the
/// few operations that form it. R(i, k) is the relative rotation's entry,
/// R^T u formed as Eigen forms a transposed matrix times a vector,
/// (t0 + t1) + t2; support1(u) and support2(w) are the bodies' support
/// functions.
template <class N, class R3, class U, class S1, class S2>
[[gnu::always_inline]] inline typename N::T alpha_lower_bound(typename N::T rn, const U& rhat, const R3& R,
                                                              S1&& support1, S2&& support2) {
  using T = typename N::T;
  T w[3];
  for (int k = 0; k < 3; ++k) w[k] = -((R(0, k) * rhat[0] + R(1, k) * rhat[1]) + R(2, k) * rhat[2]);
  const T h = support1(rhat) + support2(w);
  return (1.0 - 1e-14) * (rn / h);
}

}  // namespace idcol::detail::formulas
