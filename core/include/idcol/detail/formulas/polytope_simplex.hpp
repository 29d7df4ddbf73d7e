// The two exact polytopes' contact (exact_polytope_start.hpp says what it is
// and why a dual simplex), written once over a number layer N: the scalar
// solver runs it on one pose (N = ScalarNum), the cold lanes on W poses in
// lock step (N = LaneNum), each lane making the scalar pivots of its pose.
// Only the search for the entering face differs with the layout, so each
// layer brings its own (Scan below): the scalar one four faces a vector with
// a test per block, the lanes' one face for W poses. Both return the first
// face whose violation is the largest, strictly above the threshold.
//
// The Eigen expressions this replaced are kept operation for operation in
// Eigen 3.4's order (a 4-vector's dot product as (w0 g0 + w2 g2) + (w1 g1 +
// w3 g3), the packet halves' sums), so that the answers kept their bits.
// Where one problem and W lanes must differ (a row indexed or selected, a
// test stopped at its first false or made whole), N::kOneProblem says which.
//
// This header includes only the formulas and defines templates only
// (elementary.hpp says why).
#pragma once

#include "idcol/detail/formulas/kkt.hpp"

namespace idcol::detail::formulas {

/// ln x for a normal x > 0, to about 1e-9 absolute: the starts' cheap
/// logarithm (exact_polytope_start.hpp, log_start, says why). x = 2^e m
/// with m in [sqrt(1/2), sqrt 2), ln m = 2 atanh(t), t = (m - 1) / (m + 1),
/// by its series to t^9; the exponent field a double by the 2^52 trick.
template <class N>
[[gnu::always_inline]] inline typename N::T log_start(typename N::T x) {
  using T = typename N::T;
  const auto bits = N::bits(x);
  T e = (N::from_bits((bits >> 52) | 0x4330000000000000ull) - 0x1p52) - 1023.0;
  T m = N::from_bits((bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull);  // in [1, 2)
  const auto high = m > 1.4142135623730951;
  m = N::sel(high, 0.5 * m, m);
  e = N::sel(high, e + 1.0, e);
  const T t = (m - 1.0) / (m + 1.0), u = t * t;
  return e * 0.6931471805599453 + (t + t) * (1.0 + u * (1.0 / 3.0 + u * (1.0 / 5.0 + u * (1.0 / 7.0 + u * (1.0 / 9.0)))));
}

/// The entering face a scan found: its row (body 1's faces first, then body
/// 2's from m1), its normal and offset in its own body's frame, and whether
/// it is body 2's.
template <class N>
struct SimplexEntering {
  using T = typename N::T;
  decltype(N::index(0)) row;
  T ax, ay, az, b;
  typename N::Mask body2;
  /// No face yet (row -1): where a scan starts.
  static SimplexEntering none() {
    return {N::index(-1), N::splat(0.0), N::splat(0.0), N::splat(0.0), N::splat(0.0), N::mask(false)};
  }
};

/// The dual simplex's state: the basis inverse's columns w[r] (G_K W = I),
/// the multipliers y, the basis rows' right-hand sides h, the vertex z =
/// (x, alpha) = W h and the basis rows (-1: artificial). Each 4-vector is
/// held as two N::T2 halves, (0, 1) and (2, 3), as Eigen held it in two
/// SSE2 packets.
template <class N>
struct SimplexState {
  using T = typename N::T;
  using T2 = typename N::T2;
  T2 w[4][2], z[2];
  T y[4], h[4];
  decltype(N::index(0)) row[4];
  T alpha() const { return N::hi(z[1]); }
};

/// The pair's constants: body 1's outer radius R1 (the artificial
/// tetrahedron's inradius is 2 R1), the pair's size R1 + R2, m1 (body 1's
/// face count: rows from m1 on are body 2's), the violation tolerance (a
/// fraction of the problem's length) and the pivot limit.
struct SimplexConsts {
  double R1, size;
  int m1;
  double tol;
  int max_pivots;
};

/// Runs the dual simplex from the artificial basis on body 2 at r_S turned by
/// R (R[i][j], body 2's frame to body 1's), to its optimum. scan(it, x, a, u,
/// worst, e) finds the face most violated by more than worst (body 1's at x
/// in alpha P1, skipped at it = 0 where they all read 0; body 2's at u =
/// R^T (x - r_S)) and answers where it found one, with its data in e.
/// Answers the mask of the problems that have no start: r_S not finite, no
/// row to leave, or max_pivots pivots; the others end at their optimum in s.
/// pivots: the pivots the last problem to finish took.
/// Long: a pivot's four steps (the search, the entering row, the ratio test,
/// the update) read and write one basis; split, each would take the whole
/// state and the lanes' masks by reference.
template <class N, class Scan>
[[gnu::always_inline]] inline typename N::Mask polytope_simplex(const typename N::T (&R)[3][3],
                                                                const typename N::T (&r_S)[3], const SimplexConsts& k,
                                                                Scan&& scan, SimplexState<N>& s, int& pivots) {
  using T = typename N::T;
  using T2 = typename N::T2;
  using Mask = typename N::Mask;
  const Mask fin = N::finite(r_S[0]) & N::finite(r_S[1]) & N::finite(r_S[2]);
  Mask fail = N::not_(fin);
  const T rn = N::sqrt((r_S[0] * r_S[0] + r_S[1] * r_S[1]) + r_S[2] * r_S[2]);
  // The artificial basis (K = -1..-4): rows (t_k, -B), t_k = (+-1, +-1, +-1)
  // / sqrt 3 with an even number of minus signs (sum t_k = 0, t_k . t_l =
  // -1/3). Its inverse in closed form: w_k = (3/4 t_k, -1 / (4B)); the
  // multipliers -G_K^-T e_alpha = 1 / (4B).
  const double B = 2.0 * k.R1, c = 0.75 / __builtin_sqrt(3.0), wb = -0.25 / B;
  const double w0[4][4] = {{c, c, c, wb}, {c, -c, -c, wb}, {-c, c, -c, wb}, {-c, -c, c, wb}};
  for (int r = 0; r < 4; ++r) {
    s.w[r][0] = N::pair(N::splat(w0[r][0]), N::splat(w0[r][1]));
    s.w[r][1] = N::pair(N::splat(w0[r][2]), N::splat(w0[r][3]));
    s.y[r] = N::splat(0.25 / B);
    s.h[r] = N::splat(0.0);
    s.row[r] = N::index(-1);
  }
  s.z[0] = s.z[1] = N::pair(N::splat(0.0), N::splat(0.0));
  Mask alive = fin;
  int it = 0;
  for (;; ++it) {
    const T a = s.alpha();
    const T x[3] = {N::lo(s.z[0]), N::hi(s.z[0]), N::lo(s.z[1])};
    const T d[3] = {x[0] - r_S[0], x[1] - r_S[1], x[2] - r_S[2]};
    T u[3];
    for (int i = 0; i < 3; ++i) u[i] = (R[0][i] * d[0] + R[1][i] * d[1]) + R[2][i] * d[2];
    SimplexEntering<N> e;
    const Mask go = alive & scan(it, x, a, u, k.tol * (rn + a * k.size), e);
    if (!N::any(go)) break;  // every problem at its optimum (primal feasible) or failed
    if (it == k.max_pivots) {
      fail = fail | go;
      break;
    }
    // The entering row (g, he) in body 1's frame: body 2's normal turned
    // by R, and its offset moved by r_S. One problem takes only its own
    // body's branch; lanes take both and select.
    T2 g[2];
    T he;
    auto body2 = [&](T2 (&gb)[2], T& hb) {
      T n[3];
      const T an[3] = {e.ax, e.ay, e.az};
      mat_vec<N>([&](int i, int j) { return R[i][j]; }, an, n);
      gb[0] = N::pair(n[0], n[1]);
      gb[1] = N::pair(n[2], -e.b);
      hb = (n[0] * r_S[0] + n[1] * r_S[1]) + n[2] * r_S[2];
    };
    if constexpr (N::kOneProblem) {
      if (e.body2) {
        body2(g, he);
      } else {
        g[0] = N::pair(e.ax, e.ay), g[1] = N::pair(e.az, -e.b);
        he = 0.0;
      }
    } else {
      body2(g, he);
      g[0] = N::sel2(e.body2, g[0], N::pair(e.ax, e.ay));
      g[1] = N::sel2(e.body2, g[1], N::pair(e.az, -e.b));
      he = N::sel(e.body2, he, N::splat(0.0));
    }
    // Ratio test: g = sum rho_r g_r; the row whose multiplier y_r - theta
    // rho_r reaches 0 first leaves. A problem that is done takes rho = 0:
    // no row leaves and nothing below changes it.
    T rho[4];
    auto out = N::index(-1);
    T theta = N::splat(0.0);
    for (int r = 0; r < 4; ++r) {
      const T2 p = s.w[r][0] * g[0] + s.w[r][1] * g[1];
      rho[r] = N::sel(go, N::lo(p) + N::hi(p), N::splat(0.0));
      // One problem tests in order and stops at the first false; lanes
      // test everything: the same truth.
      Mask take;
      if constexpr (N::kOneProblem)
        take = rho[r] > 1e-13 && (out < 0 || s.y[r] < theta * rho[r]);
      else
        take = (rho[r] > 1e-13) & ((out < 0) | (s.y[r] < theta * rho[r]));
      out = N::sel_index(take, r, out);
      theta = N::lazy(take, [&] { return s.y[r] / rho[r]; }, [&] { return theta; });
    }
    const Mask none = go & (out < 0);  // no row can leave: the program would be infeasible, so rounding
    fail = fail | none;
    alive = alive & N::not_(none);
    if (!N::any(alive)) break;
    // The pivot: row out leaves, the entering row takes its place. One
    // problem indexes its rows; lanes, whose rows differ, select them.
    if constexpr (N::kOneProblem) {
      const T2 wo[2] = {s.w[out][0] / rho[out], s.w[out][1] / rho[out]};
      for (int r = 0; r < 4; ++r) {
        if (r == out) continue;
        for (int j = 0; j < 2; ++j) s.w[r][j] = s.w[r][j] - rho[r] * wo[j];
        s.y[r] = s.y[r] - theta * rho[r];
      }
      s.w[out][0] = wo[0], s.w[out][1] = wo[1];
      s.y[out] = theta;
      s.h[out] = he;
      s.row[out] = e.row;
    } else {
      const Mask o[4] = {out == 0, out == 1, out == 2, out == 3};
      const T ro = N::sel(o[0], rho[0], N::sel(o[1], rho[1], N::sel(o[2], rho[2], N::sel(o[3], rho[3], N::splat(1.0)))));
      T2 wo[2];
      for (int j = 0; j < 2; ++j)
        wo[j] = N::sel2(o[0], s.w[0][j], N::sel2(o[1], s.w[1][j], N::sel2(o[2], s.w[2][j], s.w[3][j]))) / ro;
      for (int r = 0; r < 4; ++r) {
        for (int j = 0; j < 2; ++j) s.w[r][j] = N::sel2(o[r], wo[j], s.w[r][j] - rho[r] * wo[j]);
        s.y[r] = N::sel(o[r], theta, s.y[r] - theta * rho[r]);
        s.h[r] = N::sel(o[r], he, s.h[r]);
        s.row[r] = N::sel_index(o[r], e.row, s.row[r]);
      }
    }
    for (int j = 0; j < 2; ++j)
      s.z[j] = ((s.h[0] * s.w[0][j] + s.h[1] * s.w[1][j]) + s.h[2] * s.w[2][j]) + s.h[3] * s.w[3][j];
  }
  pivots = it;
  return fail;
}

/// The optimum's multipliers' least over largest (the basis is unique where
/// it is not small), and the first-order move of the vertex towards the
/// smooth bodies' contact by soft1, soft2 (each polytope's L / beta, or 0),
/// a fraction step of the way (exact_polytope_start.hpp: exact_polytope_
/// contact says how). The least of four as Eigen's minCoeff pairs them.
template <class N>
[[gnu::always_inline]] inline typename N::T simplex_finish(SimplexState<N>& s, int m1, double soft1, double soft2,
                                                           double step) {
  using T = typename N::T;
  using T2 = typename N::T2;
  using Mask = typename N::Mask;
  auto lt_min = [](T a, T b) { return N::sel(b < a, b, a); };
  auto gt_max = [](T a, T b) { return N::sel(a < b, b, a); };
  const T ymin = lt_min(lt_min(s.y[0], s.y[2]), lt_min(s.y[1], s.y[3]));
  const T ymax = gt_max(gt_max(s.y[0], s.y[2]), gt_max(s.y[1], s.y[3]));
  const T ratio = ymin / ymax;
  if (!(soft1 > 0.0 || soft2 > 0.0)) return ratio;
  const Mask move = (s.row[0] >= 0) & (s.row[1] >= 0) & (s.row[2] >= 0) & (s.row[3] >= 0) & (ymin > 0.0);
  if (!N::any(move)) return ratio;
  Mask b2[4];
  T S[2] = {N::splat(0.0), N::splat(0.0)};
  for (int r = 0; r < 4; ++r) {
    b2[r] = s.row[r] >= m1;
    S[0] = N::sel(b2[r], S[0], S[0] + s.y[r]);
    S[1] = N::sel(b2[r], S[1] + s.y[r], S[1]);
  }
  T2 d[2] = {N::pair(N::splat(0.0), N::splat(0.0)), N::pair(N::splat(0.0), N::splat(0.0))};
  for (int r = 0; r < 4; ++r) {
    const T f = N::sel(b2[r], N::splat(soft2), N::splat(soft1)) * log_start<N>(s.y[r] / N::sel(b2[r], S[1], S[0]));
    for (int j = 0; j < 2; ++j) d[j] = d[j] + f * s.w[r][j];
  }
  const T q = s.alpha() / (1.0 - N::hi(d[1]));
  const T2 zs[2] = {s.z[0] + d[0] * q, s.z[1] + d[1] * q};
  const Mask ok = move & (N::hi(zs[1]) > 0.0) & N::finite(N::lo(zs[0])) & N::finite(N::hi(zs[0])) &
                  N::finite(N::lo(zs[1])) & N::finite(N::hi(zs[1]));
  for (int j = 0; j < 2; ++j) s.z[j] = N::sel2(ok, s.z[j] + N::splat(step) * (zs[j] - s.z[j]), s.z[j]);
  return ratio;
}

}  // namespace idcol::detail::formulas
