// The geometry of the cold start (PairSolver::support_guess), written once
// over a number layer N (elementary.hpp) for the scalar solver (shapes.cpp,
// solver_impl.hpp) and the cold lanes (newton_lanes_cold.hpp): the support
// points of the families, the boundary point along a ray from the frame
// origin, and the smooth polytope's exact exit face. A vector argument u is
// anything with u[0..2]; a result is written to an array of three T.
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/kkt.hpp"  // mat_vec
#include "idcol/detail/formulas/shape_eval.hpp"

namespace idcol::detail::formulas {

/// std::clamp(x, lo, hi).
template <class N>
[[gnu::always_inline]] inline typename N::T clamp(typename N::T x, double lo, double hi) {
  return N::sel(x < lo, N::splat(lo), N::sel(hi < x, N::splat(hi), x));
}

/// The distance from the frame origin to the boundary of a homogeneous body
/// along a unit u, from phi(u) (psi(u) = phi(u) + 1): 1/psi(u) clamped to
/// the certified radii, the outer radius where psi(u) is not positive.
template <class N>
[[gnu::always_inline]] inline typename N::T homogeneous_extent(typename N::T phi, double inner, double outer) {
  const typename N::T psi = phi + 1.0;
  return N::sel(psi > 0.0, clamp<N>(1.0 / psi, inner, outer), N::splat(outer));
}

/// The same for a LogSumExp body: two Newton steps along u from the outer
/// radius, rho <- clamp(rho - phi / (u . grad)), stopping where u . grad is
/// not positive or phi is not finite. eval(y, phi, grad) evaluates the body
/// at y = rho u; n is the gradient at the last point evaluated, the
/// stopping point included.
template <class N, class U, class Ev>
[[gnu::always_inline]] inline typename N::T newton_extent(const U& u, double inner, double outer, typename N::T (&n)[3],
                                                          Ev&& eval) {
  using T = typename N::T;
  T rho = N::splat(outer);
  auto live = N::mask(true);
  for (int i = 0; i < 2; ++i) {
    const T y[3] = {rho * u[0], rho * u[1], rho * u[2]};
    T phi, g[3];
    eval(y, phi, g);
    const T d = (u[0] * g[0] + u[1] * g[1]) + u[2] * g[2];
    for (int k = 0; k < 3; ++k) n[k] = i == 0 ? g[k] : N::sel(live, g[k], n[k]);
    live = live & ((d > 0.0) & N::finite(phi));
    rho = N::sel(live, clamp<N>(rho - phi / d, inner, outer), rho);
    if (!N::any(live)) break;
  }
  return rho;
}

/// The face through which the ray along u leaves the exact polytope
/// {y : a_i . y <= b_i} (faces 0..m-1, a_i = normal(i, 0..2), b_i =
/// offset(i) > 0): the first of the largest c_i = (a_i . u) / b_i. Writes
/// p = u / c_i and n = a_i; answers whether some c_i is positive (a face
/// with b_i = inf, c_i = 0, never wins).
template <class N, class U, class Fn, class Fb>
[[gnu::always_inline]] inline auto polytope_exit_face(int m, Fn&& normal, Fb&& offset, const U& u, typename N::T (&p)[3],
                                                      typename N::T (&n)[3]) {
  using T = typename N::T;
  T best = N::splat(0.0);
  for (int k = 0; k < 3; ++k) n[k] = N::splat(0.0);
  for (int i = 0; i < m; ++i) {
    const T c = ((normal(i, 0) * u[0] + normal(i, 1) * u[1]) + normal(i, 2) * u[2]) / offset(i);
    const auto up = c > best;
    best = N::sel(up, c, best);
    for (int k = 0; k < 3; ++k) n[k] = N::sel(up, N::splat(normal(i, k)), n[k]);
  }
  for (int k = 0; k < 3; ++k) p[k] = u[k] / best;
  return best > 0.0;
}

/// The support point of the unit superquadric ||w||_2n <= 1 in scaled
/// coordinates for the scaled direction v (D = 3 for the superellipsoid, 2
/// for the cylinder's axial and radial coordinates): the surface point whose
/// normal is along v, w_i proportional to sign(v_i) |v_i|^(1/(2n-1)),
/// normalised onto the surface. v = 0 has none: the scalar layer answers
/// w = 0, the lanes flag the lane in bad.
template <class N, int D, class Ex>
[[gnu::always_inline]] inline void superquadric_support(const Ex& ex, const typename N::T (&v)[D], typename N::T (&w)[D],
                                                        typename N::Mask& bad) {
  using T = typename N::T;
  T m = N::abs(v[0]);
  for (int i = 1; i < D; ++i) m = N::sel(N::abs(v[i]) > m, N::abs(v[i]), m);
  if (N::leaves(N::not_(m > 0.0), bad)) {
    for (int i = 0; i < D; ++i) w[i] = N::splat(0.0);
    return;
  }
  const double k = 1.0 / (2.0 * ex.n - 1.0);
  T S = N::splat(0.0);
  for (int i = 0; i < D; ++i) {
    const T t = N::abs(v[i]) / m;  // in [0, 1]
    const T pw = k == 1.0 ? t : N::lazy(t == 1.0, [&] { return t; }, [&] { return pow_unit<N>(t, k); });
    w[i] = N::copysign(pw, v[i]);
    S = S + pow_2n<N>(ex, w[i]);  // in [1, D]
  }
  const T root = root_2n<N>(ex, S);
  for (int i = 0; i < D; ++i) w[i] = w[i] / root;
}

/// The support point of the frustum that holds the smooth truncated cone
/// (base radius Rb at x = -a, top radius Rt at x = h): the rim point of the
/// end disc that reaches the support.
template <class N, class U>
[[gnu::always_inline]] inline void cone_support(double Rb, double Rt, double a, double h, const U& u, typename N::T (&p)[3]) {
  using T = typename N::T;
  const T w = N::hypot(u[1], u[2]);
  const auto base = -a * u[0] + Rb * w >= h * u[0] + Rt * w;
  const T radial = N::sel(w > 0.0, N::sel(base, N::splat(Rb), N::splat(Rt)) / w, N::splat(0.0));
  p[0] = N::sel(base, N::splat(-a), N::splat(h));
  p[1] = radial * u[1];
  p[2] = radial * u[2];
}

/// The support point of the exact polytope with vertices vert(i, 0..2), i <
/// nv: the mean of the vertices whose u . v reaches the support h = max
/// u . v to within tol, summed in the vertices' order. A u with no such
/// vertex (not finite) gives 0/0; the lanes also flag it in bad.
template <class N, class U, class Fv>
[[gnu::always_inline]] inline void polytope_support(int nv, Fv&& vert, double tol, const U& u, typename N::T (&q)[3],
                                                    typename N::Mask& bad) {
  using T = typename N::T;
  constexpr int kKept = 64;  // products kept between the two passes (more: formed again, the same bits)
  T dots[kKept];
  auto prod = [&](int i) { return (u[0] * vert(i, 0) + u[1] * vert(i, 1)) + u[2] * vert(i, 2); };
  T h = N::splat(-__builtin_inf());
  for (int i = 0; i < nv; ++i) {
    const T d = prod(i);
    if (i < kKept) dots[i] = d;
    h = N::sel(h < d, d, h);  // std::max(h, d)
  }
  const T lim = h - tol;
  T cnt = N::splat(0.0);
  for (int k = 0; k < 3; ++k) q[k] = N::splat(0.0);
  for (int i = 0; i < nv; ++i) {
    const auto in = (i < kKept ? dots[i] : prod(i)) >= lim;
    for (int k = 0; k < 3; ++k) q[k] = N::sel(in, q[k] + vert(i, k), q[k]);
    cnt = N::sel(in, cnt + 1.0, cnt);
  }
  (void)N::leaves(N::not_(cnt > 0.0), bad);
  for (int k = 0; k < 3; ++k) q[k] = q[k] / cnt;
}

/// support_guess's plane (PairSolver::support_guess; the cold lanes'
/// cold_candidates). p1 and p2 are the two bodies' boundary points on the
/// line of centres (body 1's along r_hat, body 2's along -R^T r_hat, each
/// in its frame), n1 and n2 their outer normals. Each normal offers a
/// plane: v = n1 / |n1| (w = -R^T v in body 2's frame) touching p1 and
/// body 2's support point a2 along w, and w = n2 / |n2| (v = -R w) touching
/// body 1's support point a1 along v and p2. A plane offers the scaling
/// f = v . r_S / (v . a1 + w . a2) at which both bodies touch it; the larger
/// positive offer is kept in best (0 where neither is), its two points in
/// q1 and q2. support1(v, a1) and support2(w, a2) give the support points.
/// A normal that is zero offers nothing (N::leaves: the lanes flag it).
template <class N, class R3, class P, class S1, class S2>
[[gnu::always_inline]] inline void support_plane(const R3& R, const P& rS, const P& p1, const P& n1, const P& p2,
                                                 const P& n2, S1&& support1, S2&& support2, typename N::T& best,
                                                 typename N::T (&q1)[3], typename N::T (&q2)[3],
                                                 typename N::Mask& bad) {
  using T = typename N::T;
  auto dot = [](const auto& a, const auto& b) { return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]; };
  best = N::splat(0.0);
  for (int i = 0; i < 3; ++i) q1[i] = q2[i] = N::splat(0.0);
  auto offer = [&](const T (&v)[3], const T (&w)[3], const auto& a1, const auto& a2) {
    const T f = dot(v, rS) / (dot(v, a1) + dot(w, a2));
    const auto take = f > best;
    best = N::sel(take, f, best);
    for (int i = 0; i < 3; ++i) {
      q1[i] = N::sel(take, a1[i], q1[i]);
      q2[i] = N::sel(take, a2[i], q2[i]);
    }
  };
  const T g1 = N::sqrt(dot(n1, n1)), g2 = N::sqrt(dot(n2, n2));
  if (!N::leaves(N::not_(g1 > 0.0), bad)) {
    const T v[3] = {n1[0] / g1, n1[1] / g1, n1[2] / g1};
    T w[3];
    for (int i = 0; i < 3; ++i) w[i] = -((R(0, i) * v[0] + R(1, i) * v[1]) + R(2, i) * v[2]);  // -(R^T v)
    T a2[3];
    support2(w, a2);
    offer(v, w, p1, a2);
  }
  if (!N::leaves(N::not_(g2 > 0.0), bad)) {
    const T w[3] = {n2[0] / g2, n2[1] / g2, n2[2] / g2};
    T Rw[3];
    mat_vec<N>(R, w, Rw);
    const T v[3] = {-Rw[0], -Rw[1], -Rw[2]};
    T a1[3];
    support1(v, a1);
    offer(v, w, a1, p2);
  }
}

/// support_guess's three starts from the plane at scaling alpha: x1 =
/// alpha q1 (body 1's point), x2 = r_S + alpha R q2 (body 2's, alpha folded
/// into R first, as Eigen evaluates alpha * (R * q2)) and their midpoint.
template <class N, class R3, class P>
[[gnu::always_inline]] inline void support_starts(const R3& R, const P& rS, typename N::T alpha,
                                                  const typename N::T (&q1)[3], const typename N::T (&q2)[3],
                                                  typename N::T (&x)[3][3]) {
  using T = typename N::T;
  auto aR = [&](int i, int k) { return alpha * R(i, k); };
  T t[3];
  mat_vec<N>(aR, q2, t);
  for (int i = 0; i < 3; ++i) {
    x[0][i] = alpha * q1[i];
    x[1][i] = rS[i] + t[i];
    x[2][i] = 0.5 * (x[0][i] + x[1][i]);
  }
}

/// support_guess's ranking of its three starts by merit m[0..2], as the
/// loop forms it one candidate after another: the second beats the first
/// only strictly (a tie keeps the earlier), the third the better of those;
/// best, the winner's index. The other two are the spares, in
/// the order they lost (spare[0] lost to the first comparison, spare[1] to
/// the second) unless the second's merit is the smaller (then swapped):
/// best first. A merit that is not finite counts as +inf, so it never wins
/// and its start sorts after every finite spare; the loop keeps only the
/// finite spares, a prefix of the two.
template <class N>
struct StartRanking {
  decltype(N::index(0)) best, spare[2];
};
template <class N>
[[gnu::always_inline]] inline StartRanking<N> rank_starts(const typename N::T (&merit)[3]) {
  using T = typename N::T;
  const T inf = N::splat(__builtin_inf());
  T m[3];
  for (int c = 0; c < 3; ++c) m[c] = N::sel(N::finite(merit[c]), merit[c], inf);
  StartRanking<N> r;
  const auto b1 = m[1] < m[0];
  const T m01 = N::sel(b1, m[1], m[0]);
  const auto b2 = m[2] < m01;
  const auto i01 = N::sel_index(b1, 1, N::index(0));
  r.best = N::sel_index(b2, 2, i01);
  const auto first = N::sel_index(b1, 0, N::index(1));  // the loser of 0 and 1
  const auto second = N::sel_index(b2, i01, N::index(2));  // the loser of their winner and 2
  const T mf = N::sel(b1, m[0], m[1]);
  const T ms = N::sel(b2, m01, m[2]);
  const auto swap = ms < mf;
  r.spare[0] = N::sel_index(swap, second, first);
  r.spare[1] = N::sel_index(swap, first, second);
  return r;
}

}  // namespace idcol::detail::formulas
