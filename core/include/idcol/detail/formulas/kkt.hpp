// The KKT residual (eq:kkt_residual) and its Jacobian (eq:kkt_jacobian) of
// the surrogate problem in s = log(alpha), written once over a number layer
// N (elementary.hpp): the scalar solver (kkt.hpp) instantiates them with
// double, the batch lanes (newton_lanes_kernel.hpp) with a vector of W
// doubles, so that a lane's residual and Jacobian are the loop's, bit for
// bit, because both run this source. kkt.hpp says what the coordinates are.
//
// A point p has members z[6] (the unknowns), F[6], alpha, y1[3], y2[3],
// g2w[3] (R grad phi2) and the evaluations e1, e2, read through N::phi,
// N::grad and N::hess. R(i, k) is the relative rotation's entry. Every sum
// of three products adds in the order Eigen 3.4's expressions took for a
// column-major 3x3 matrix in the library's SSE2 build: rows 0 and 1
// (t0 + t1) + t2, row 2 t0 + (t1 + t2); a transposed matrix times a vector,
// and dot products, (t0 + t1) + t2. The scalar solver's answers before this
// was written once were formed by those expressions, and are unchanged to
// the bit.
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/elementary.hpp"

namespace idcol::detail::formulas {

/// A v, A(i, k) given, in Eigen's order (above): rows 0 and 1 as one N::T2
/// (two doubles in an SSE2 register for the scalar layer, two vectors for
/// the lanes; each half makes the scalar operation), row 2 alone.
template <class N, class A>
[[gnu::always_inline]] inline void mat_vec(const A& M, const typename N::T (&v)[3], typename N::T (&out)[3]) {
  const auto r01 = (N::pair(M(0, 0), M(1, 0)) * v[0] + N::pair(M(0, 1), M(1, 1)) * v[1]) + N::pair(M(0, 2), M(1, 2)) * v[2];
  out[0] = N::lo(r01);
  out[1] = N::hi(r01);
  out[2] = M(2, 0) * v[0] + (M(2, 1) * v[1] + M(2, 2) * v[2]);
}
/// a . b, (t0 + t1) + t2.
template <class N>
[[gnu::always_inline]] inline typename N::T dot3(const typename N::T (&a)[3], const typename N::T (&b)[3]) {
  return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
}

/// F(z) at the point p (kkt.hpp's scaling): p.z is the caller's. eval1(y,
/// e) and eval2(y, e) evaluate the two shapes at their sharpness.
template <class N, class Pt, class R3, class C3, class Z, class Ev1, class Ev2>
[[gnu::always_inline]] inline void kkt_residual(const R3& R, const C3& c1, const C3& c2, double L, double inv_sigma1,
                                                double inv_sigma2, const Z& z, Pt& p, Ev1&& eval1, Ev2&& eval2) {
  using T = typename N::T;
  // 1/alpha = e^-s first: the witness points need only it, and the division
  // for alpha itself leaves their path. The point keeps it (p.ia), so that
  // kkt_init_lambda and kkt_jacobian multiply by it where they divided by
  // alpha: five divisions fewer a Newton step. The lanes gain most: a
  // division of eight lanes holds the divider twice as long as one of four,
  // so divisions, unlike the other operations, cost as much a lane on
  // AVX-512 as on AVX2.
  const T ia = exp_any<N>(-z[3]);
  p.ia = ia;
  p.alpha = 1.0 / ia;
  const T c = L * ia;
  for (int i = 0; i < 3; ++i) p.y1[i] = c * (z[i] + c1[i]);
  const T w[3] = {z[0] - c2[0], z[1] - c2[1], z[2] - c2[2]};
  // y2 = c R^T w as Eigen forms it: (c R^T) w.
  for (int i = 0; i < 3; ++i) p.y2[i] = ((c * R(0, i)) * w[0] + (c * R(1, i)) * w[1]) + (c * R(2, i)) * w[2];
  eval1(p.y1, p.e1);
  eval2(p.y2, p.e2);
  const T g2[3] = {N::grad(p.e2, 0), N::grad(p.e2, 1), N::grad(p.e2, 2)};
  T g2w[3];
  mat_vec<N>(R, g2, g2w);
  for (int i = 0; i < 3; ++i) p.g2w[i] = g2w[i];
  const T l1 = z[4], l2 = z[5];
  p.F[0] = N::phi(p.e1) * inv_sigma1;
  p.F[1] = N::phi(p.e2) * inv_sigma2;
  for (int i = 0; i < 3; ++i) p.F[2 + i] = c * (l1 * N::grad(p.e1, i) + l2 * p.g2w[i]);
  T h1 = (p.y1[0] * N::grad(p.e1, 0) + p.y1[1] * N::grad(p.e1, 1)) + p.y1[2] * N::grad(p.e1, 2);
  T h2 = (p.y2[0] * N::grad(p.e2, 0) + p.y2[1] * N::grad(p.e2, 1)) + p.y2[2] * N::grad(p.e2, 2);
  p.F[5] = 1.0 - (l1 * h1 + l2 * h2) * ia;
}

/// The multipliers of eq:guess at a start (alpha, its point's d1 = r_S .
/// grad phi1 and d2 = r_S . R grad phi2, r_S in units of L): alpha^2 /
/// (L d_i) where its sign is right, else alpha / 2, and alpha / 2 for any
/// that is not finite and positive.
template <class N>
[[gnu::always_inline]] inline void guess_multipliers(typename N::T alpha, double L, typename N::T d1, typename N::T d2,
                                                     typename N::T& l1, typename N::T& l2) {
  using T = typename N::T;
  const T a2 = alpha * alpha / L;
  const T half = 0.5 * alpha;
  l1 = N::sel(d1 > 0.0, a2 / d1, half);
  l2 = N::sel(d2 < 0.0, -a2 / d2, half);
  l1 = N::sel(N::finite(l1) & (l1 > 0.0), l1, half);
  l2 = N::sel(N::finite(l2) & (l2 > 0.0), l2, half);
}

/// init_lambda (PairSolver): the multipliers of eq:guess at a point p that
/// kkt_residual evaluated, written into p.z, and the rows of F they enter.
template <class N, class C3, class Pt>
[[gnu::always_inline]] inline void kkt_init_lambda(double L, const C3& c1, const C3& c2, Pt& p) {
  using T = typename N::T;
  const T rS[3] = {c1[0] + c2[0], c1[1] + c2[1], c1[2] + c2[2]};
  const T d1 = (rS[0] * N::grad(p.e1, 0) + rS[1] * N::grad(p.e1, 1)) + rS[2] * N::grad(p.e1, 2);
  const T d2 = (rS[0] * p.g2w[0] + rS[1] * p.g2w[1]) + rS[2] * p.g2w[2];
  T l1, l2;
  guess_multipliers<N>(p.alpha, L, d1, d2, l1, l2);
  p.z[4] = l1;
  p.z[5] = l2;
  const T c = L * p.ia;  // as kkt_residual forms these rows
  for (int i = 0; i < 3; ++i) p.F[2 + i] = c * (l1 * N::grad(p.e1, i) + l2 * p.g2w[i]);
  const T h1 = (p.y1[0] * N::grad(p.e1, 0) + p.y1[1] * N::grad(p.e1, 1)) + p.y1[2] * N::grad(p.e1, 2);
  const T h2 = (p.y2[0] * N::grad(p.e2, 0) + p.y2[1] * N::grad(p.e2, 1)) + p.y2[2] * N::grad(p.e2, 2);
  p.F[5] = 1.0 - (l1 * h1 + l2 * h2) * p.ia;
}

/// The Newton run's merit 0.5 ||F||^2, its sum in the order Eigen 3.4 takes
/// for a 6-vector's squaredNorm on SSE2 (the packets (F0, F1), (F2, F3),
/// (F4, F5) as p0 + (p1 + p2), then the two halves added): the loop's and
/// the lanes' merits are then the same bits, so a comparison of merits (the
/// Armijo test, the LM trials, the stall count, the cold start's ranking)
/// decides alike on both paths.
template <class N>
[[gnu::always_inline]] inline typename N::T kkt_merit(const typename N::T* F) {
  using T2 = typename N::T2;
  const T2 p0 = N::load2(F), p1 = N::load2(F + 2), p2 = N::load2(F + 4);
  const T2 s = p0 * p0 + (p1 * p1 + p2 * p2);
  return 0.5 * (N::lo(s) + N::hi(s));
}

/// The four terms of the convergence measure (kkt.hpp's
/// kkt_relative_residual is their maximum) at a point p that kkt_residual
/// evaluated, each a relative error:
///   t[0], t[1]  |phi_i| / (|y_i| |grad phi_i|) (|phi_i| where that is 0),
///   t[2]        |l1 g1 + l2 R g2| / (|l1| |g1| + |l2| |g2|) (1 where 0),
///   t[3]        |F5|.
/// Each norm is the square root of (t0 + t1) + t2, as Eigen's.
template <class N, class Pt>
[[gnu::always_inline]] inline void kkt_relative_terms(const Pt& p, typename N::T (&t)[4]) {
  using T = typename N::T;
  auto norm = [](T a0, T a1, T a2) { return N::sqrt((a0 * a0 + a1 * a1) + a2 * a2); };
  const T n1 = norm(N::grad(p.e1, 0), N::grad(p.e1, 1), N::grad(p.e1, 2));
  const T n2 = norm(N::grad(p.e2, 0), N::grad(p.e2, 1), N::grad(p.e2, 2));
  const T d1 = norm(p.y1[0], p.y1[1], p.y1[2]) * n1, d2 = norm(p.y2[0], p.y2[1], p.y2[2]) * n2;
  const T a1 = N::abs(N::phi(p.e1)), a2 = N::abs(N::phi(p.e2));
  t[0] = N::sel(d1 > 0.0, a1 / d1, a1);
  t[1] = N::sel(d2 > 0.0, a2 / d2, a2);
  const T l1 = p.z[4], l2 = p.z[5];
  const T w = N::abs(l1) * n1 + N::abs(l2) * n2;
  const T st = norm(l1 * N::grad(p.e1, 0) + l2 * p.g2w[0], l1 * N::grad(p.e1, 1) + l2 * p.g2w[1],
                    l1 * N::grad(p.e1, 2) + l2 * p.g2w[2]);
  t[2] = N::sel(w > 0.0, st / w, N::splat(1.0));
  t[3] = N::abs(p.F[5]);
}

/// dF/dz at a point p that kkt_residual evaluated (the chain rule
/// (.)_s = (.)_alpha alpha and eq:phi_partials), into J(i, j). Rows 0 and 1
/// of each 3x3 product run as one N::T2 (N::pair(a, b), N::lo, N::hi): two
/// doubles in an SSE2 register for the scalar layer, which then makes the
/// two rows' products in one instruction, two vectors for the lanes; each
/// half makes the scalar operation, so the bits are the same either way.
template <class N, class Pt, class R3, class Jm>
[[gnu::always_inline]] inline void kkt_jacobian(const R3& R, double L, double inv_sigma1, double inv_sigma2, const Pt& p,
                                                Jm& J) {
  using T = typename N::T;
  using T2 = typename N::T2;
  auto tail = [](T t0, T t1, T t2) { return t0 + (t1 + t2); };
  const T ia = p.ia, c = L * ia;
  const T l1 = p.z[4], l2 = p.z[5];
  const auto& e1 = p.e1;
  const auto& e2 = p.e2;
  const auto& y1 = p.y1;
  const auto& y2 = p.y2;
  auto g1 = [&](int i) -> T { return N::grad(e1, i); };
  auto g2 = [&](int i) -> T { return N::grad(e2, i); };
  auto H1 = [&](int i, int j) -> T { return N::hess(e1, i, j); };
  auto H2 = [&](int i, int j) -> T { return N::hess(e2, i, j); };
  // Column k of a matrix, rows 0-1.
  auto col01 = [](auto&& M, int k) { return N::pair(M(0, k), M(1, k)); };
  const T2 R0 = col01(R, 0), R1 = col01(R, 1), R2 = col01(R, 2);
  // RH2 = R H2, column j: rows 0-1 in rh[j], row 2 in rh2[j].
  T2 rh[3];
  T rh2[3];
  for (int j = 0; j < 3; ++j) {
    rh[j] = (R0 * H2(0, j) + R1 * H2(1, j)) + R2 * H2(2, j);
    rh2[j] = tail(R(2, 0) * H2(0, j), R(2, 1) * H2(1, j), R(2, 2) * H2(2, j));
  }
  // H2w = RH2 R^T, column j: rows 0-1 in hw[j], row 2 in hw2[j].
  T2 hw[3];
  T hw2[3];
  for (int j = 0; j < 3; ++j) {
    const T r0 = R(j, 0), r1 = R(j, 1), r2 = R(j, 2);
    hw[j] = (rh[0] * r0 + rh[1] * r1) + rh[2] * r2;
    hw2[j] = tail(rh2[0] * r0, rh2[1] * r1, rh2[2] * r2);
  }
  // H1 y1, R H2 y2, H2 y2.
  const T2 H1c[3] = {col01(H1, 0), col01(H1, 1), col01(H1, 2)};
  const T2 h1y = (H1c[0] * y1[0] + H1c[1] * y1[1]) + H1c[2] * y1[2];
  const T h1y2 = tail(H1(2, 0) * y1[0], H1(2, 1) * y1[1], H1(2, 2) * y1[2]);
  const T2 h2yw = (rh[0] * y2[0] + rh[1] * y2[1]) + rh[2] * y2[2];
  const T h2yw2 = tail(rh2[0] * y2[0], rh2[1] * y2[1], rh2[2] * y2[2]);
  const T2 h2y = (col01(H2, 0) * y2[0] + col01(H2, 1) * y2[1]) + col01(H2, 2) * y2[2];
  const T h2y2 = tail(H2(2, 0) * y2[0], H2(2, 1) * y2[1], H2(2, 2) * y2[2]);
  const T h1 = (y1[0] * g1(0) + y1[1] * g1(1)) + y1[2] * g1(2);
  const T h2 = (y2[0] * g2(0) + y2[1] * g2(1)) + y2[2] * g2(2);
  const T q1 = (y1[0] * N::lo(h1y) + y1[1] * N::hi(h1y)) + y1[2] * h1y2;
  const T q2 = (y2[0] * N::lo(h2y) + y2[1] * N::hi(h2y)) + y2[2] * h2y2;
  const T cs1 = c * inv_sigma1, cs2 = c * inv_sigma2;
  for (int j = 0; j < 3; ++j) {
    J(0, j) = cs1 * g1(j);
    J(1, j) = cs2 * p.g2w[j];
  }
  J(0, 3) = -h1 * inv_sigma1, J(0, 4) = N::splat(0.0), J(0, 5) = N::splat(0.0);
  J(1, 3) = -h2 * inv_sigma2, J(1, 4) = N::splat(0.0), J(1, 5) = N::splat(0.0);
  // c^2 (l1 H1 + l2 H2w), column j: rows 2-3 of J as a pair, row 4 alone.
  const T cc = c * c;
  for (int j = 0; j < 3; ++j) {
    const T2 v = cc * (l1 * H1c[j] + l2 * hw[j]);
    J(2, j) = N::lo(v);
    J(3, j) = N::hi(v);
    J(4, j) = cc * (l1 * H1(2, j) + l2 * hw2[j]);
  }
  // t = l1 (g1 + H1 y1) + l2 (g2w + R H2 y2): rows 0-1 as a pair.
  const T2 t01 = l1 * (N::pair(g1(0), g1(1)) + h1y) + l2 * (N::pair(p.g2w[0], p.g2w[1]) + h2yw);
  const T t2 = l1 * (g1(2) + h1y2) + l2 * (p.g2w[2] + h2yw2);
  const T mc = -c, ca = -(c * ia);
  J(2, 3) = mc * N::lo(t01), J(3, 3) = mc * N::hi(t01), J(4, 3) = mc * t2;
  for (int i = 0; i < 3; ++i) {
    J(2 + i, 4) = c * g1(i);
    J(2 + i, 5) = c * p.g2w[i];
  }
  J(5, 0) = ca * N::lo(t01), J(5, 1) = ca * N::hi(t01), J(5, 2) = ca * t2;
  J(5, 3) = (l1 * (2.0 * h1 + q1) + l2 * (2.0 * h2 + q2)) * ia;
  J(5, 4) = -h1 * ia;
  J(5, 5) = -h2 * ia;
}

}  // namespace idcol::detail::formulas
