// The exact polytope's contact with an ellipsoid (exact_polytope_start.hpp,
// exact_polytope_ellipsoid_contact, says what it is and why a dual active-set
// method), written once over a number layer N: the scalar solver runs it on
// one pose (N = ScalarNum), the cold lanes on W poses in lock step (N =
// LaneNum). Each step tries the active sets in one order; a lane takes the
// first that holds for it, as the scalar code does, and the candidates each
// set needs are formed for every lane that still looks for one. As in
// polytope_simplex.hpp, each layer brings its own search for the entering
// face, and the Eigen expressions this replaced are kept in Eigen 3.4's
// order: a 3-vector's dot product, squared norm and a transposed matrix
// times a vector as (t0 + t1) + t2, a matrix times a vector as mat_vec.
//
// This header includes only the formulas and defines templates only
// (elementary.hpp says why).
#pragma once

#include "idcol/detail/formulas/kkt.hpp"
#include "idcol/detail/formulas/polytope_simplex.hpp"

namespace idcol::detail::formulas {

/// A face of the polytope seen from the ellipsoid's unit ball: g = C^T a,
/// its offset b and h = a . r.
template <class N>
struct BallFace {
  typename N::T g[3], b, h;
};

/// a x b, Eigen's cross product (dot3, kkt.hpp, its dot product).
template <class N>
[[gnu::always_inline]] inline void cross3(const typename N::T (&a)[3], const typename N::T (&b)[3], typename N::T (&c)[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/// The optimum of the K faces U active with offsets b: alpha, y and w (the
/// multipliers of U are positive multiples of -w). Not set where the faces
/// meet in no edge or vertex, or the scaled bodies never touch there.
template <class N, int K>
[[gnu::always_inline]] inline typename N::Mask ball_set(const BallFace<N>* const (&U)[K], const typename N::T (&b)[K],
                                                        typename N::T& a, typename N::T (&y)[3], typename N::T (&w)[K]) {
  using T = typename N::T;
  using Mask = typename N::Mask;
  T P[3], Q[3], wp[K], wq[K];  // w = alpha wp - wq
  Mask ok = N::mask(true);
  if constexpr (K == 1) {
    const T gg = dot3<N>(U[0]->g, U[0]->g);
    wp[0] = b[0] / gg, wq[0] = U[0]->h / gg;
    for (int i = 0; i < 3; ++i) P[i] = wp[0] * U[0]->g[i], Q[i] = wq[0] * U[0]->g[i];
  } else if constexpr (K == 2) {
    const T(&g1)[3] = U[0]->g;
    const T(&g2)[3] = U[1]->g;
    const T g11 = dot3<N>(g1, g1), g12 = dot3<N>(g1, g2), g22 = dot3<N>(g2, g2), det = g11 * g22 - g12 * g12;
    ok = det > 1e-12 * g11 * g22;  // parallel faces: no edge
    if (!N::any(ok)) return ok;
    const T id = 1.0 / det;
    wp[0] = (g22 * b[0] - g12 * b[1]) * id, wp[1] = (g11 * b[1] - g12 * b[0]) * id;
    wq[0] = (g22 * U[0]->h - g12 * U[1]->h) * id, wq[1] = (g11 * U[1]->h - g12 * U[0]->h) * id;
    for (int i = 0; i < 3; ++i) P[i] = wp[0] * g1[i] + wp[1] * g2[i], Q[i] = wq[0] * g1[i] + wq[1] * g2[i];
  } else {
    // G^-1 = [c1 c2 c3] / det, c_i the cross products of the other two
    // rows; (G G^T)^-1 b = G^-T G^-1 b, so w_i = c_i . y / det.
    const T(&g1)[3] = U[0]->g;
    const T(&g2)[3] = U[1]->g;
    const T(&g3)[3] = U[2]->g;
    T c[3][3];
    cross3<N>(g2, g3, c[0]);
    cross3<N>(g3, g1, c[1]);
    cross3<N>(g1, g2, c[2]);
    const T det = dot3<N>(g1, c[0]);
    ok = N::abs(det) > 1e-12 * N::sqrt(dot3<N>(g1, g1)) * N::sqrt(dot3<N>(g2, g2)) * N::sqrt(dot3<N>(g3, g3));  // no vertex
    if (!N::any(ok)) return ok;
    const T id = 1.0 / det;
    for (int i = 0; i < 3; ++i) {
      P[i] = ((b[0] * c[0][i] + b[1] * c[1][i]) + b[2] * c[2][i]) * id;
      Q[i] = ((U[0]->h * c[0][i] + U[1]->h * c[1][i]) + U[2]->h * c[2][i]) * id;
    }
    for (int j = 0; j < 3; ++j) wp[j] = dot3<N>(c[j], P) * id;
    for (int j = 0; j < 3; ++j) wq[j] = dot3<N>(c[j], Q) * id;
  }
  // |alpha P - Q| = alpha: (|P|^2 - 1) alpha^2 - 2 B alpha + Cq = 0, least
  // positive root. Its discriminant B^2 - (|P|^2 - 1) |Q|^2 is formed as
  // |Q|^2 - |P x Q|^2 (Lagrange's identity): for a small ellipsoid far
  // from a large polytope |P| >> 1 (a body of 1e-3 against one of 1e3:
  // 1e6), and the difference of the two large products would lose about
  // 1e-4 of D, 5e-11 of alpha, a Newton step more (ci.toml's Tiny-Big).
  T PxQ[3];
  cross3<N>(P, Q, PxQ);
  const T B = dot3<N>(P, Q), Cq = dot3<N>(Q, Q), D = Cq - dot3<N>(PxQ, PxQ);
  ok = ok & (D >= 0.0);
  if (!N::any(ok)) return ok;
  const T den = B + N::sqrt(N::sel(ok, D, N::splat(0.0)));
  ok = ok & (den > 0.0);
  if (!N::any(ok)) return ok;
  const T an = Cq / den;
  ok = ok & (an > 0.0) & N::finite(an);
  if (!N::any(ok)) return ok;
  a = an;
  for (int i = 0; i < 3; ++i) y[i] = an * P[i] - Q[i];
  for (int j = 0; j < K; ++j) w[j] = an * wp[j] - wq[j];
  return ok;
}

/// The state of the active-set method: the active faces S[0..ns), their w,
/// alpha, y (in the ball) and v = r + C y (in the polytope's frame).
template <class N>
struct BallState {
  using T = typename N::T;
  BallFace<N> S[3];
  T wS[3], a, y[3], v[3];
  decltype(N::index(0)) ns;
};

/// An active set's size as a type (ball_contact's candidates).
template <int K>
struct SetSize {
  static constexpr int value = K;
};

/// The pair's constants: the polytope's outer radius, the violation
/// tolerance, the step limit, and the polytope's smoothing length soft (0:
/// no move).
struct BallConsts {
  double outer;
  double tol;
  int max_steps;
  double soft;
};

/// The ellipsoid of semi-axes ax in the polytope's frame, {r + C y : |y| <=
/// 1}, from the surrogate problem's geometry (body 1 at the origin, body 2
/// at r_S turned by R[i][j]): the polytope body 1, the ellipsoid at r_S,
/// C = R diag(ax); the polytope body 2 (u = R^T (x - r_S)), the ellipsoid
/// at -R^T r_S, C = R^T diag(ax).
template <class N>
[[gnu::always_inline]] inline void ball_frame(const typename N::T (&R)[3][3], const typename N::T (&r_S)[3],
                                              const double (&ax)[3], bool polytope_first, typename N::T (&C)[3][3],
                                              typename N::T (&r)[3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C[i][j] = (polytope_first ? R[i][j] : R[j][i]) * ax[j];
  for (int i = 0; i < 3; ++i) r[i] = polytope_first ? r_S[i] : -((R[0][i] * r_S[0] + R[1][i] * r_S[1]) + R[2][i] * r_S[2]);
}

/// The contact v of ball_frame's problem in body 1's frame: v itself where
/// the polytope is body 1, else r_S + R v.
template <class N>
[[gnu::always_inline]] inline void ball_point(const typename N::T (&R)[3][3], const typename N::T (&r_S)[3],
                                              const typename N::T (&v)[3], bool polytope_first, typename N::T (&x)[3]) {
  if (polytope_first) {
    for (int i = 0; i < 3; ++i) x[i] = v[i];
    return;
  }
  mat_vec<N>([&](int i, int j) { return R[i][j]; }, v, x);
  for (int i = 0; i < 3; ++i) x[i] = r_S[i] + x[i];
}

/// Runs the dual active-set method for the polytope (its faces through
/// scan) against the ellipsoid {r + C y : |y| <= 1} (C[i][j]), then,
/// with soft > 0, the first-order move where an edge or a vertex touches.
/// scan(v, a, worst, e) finds the face most violated at v in alpha P by more
/// than worst (e.row, e.ax, e.ay, e.az, e.b). Answers the mask of the
/// problems that end at a contact, alpha and v in s; steps, the steps the
/// last problem to finish took.
/// Long: one step's entering face, its seven active sets tried in order and
/// the accepted set's update share the state; split, each would take it all.
template <class N, class Scan>
[[gnu::always_inline]] inline typename N::Mask ball_contact(const typename N::T (&C)[3][3], const typename N::T (&r)[3],
                                                            const BallConsts& k, Scan&& scan, BallState<N>& s, int& steps) {
  using T = typename N::T;
  using Mask = typename N::Mask;
  // The problem's size: the polytope's outer radius and the ellipsoid's
  // largest semi-axis, the largest column of C.
  T big = N::splat(0.0);
  for (int j = 0; j < 3; ++j) {
    const T c2 = (C[0][j] * C[0][j] + C[1][j] * C[1][j]) + C[2][j] * C[2][j];
    big = N::sel(big < c2, c2, big);
  }
  const T size = k.outer + N::sqrt(big);
  Mask alive = N::finite(r[0]) & N::finite(r[1]) & N::finite(r[2]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) alive = alive & N::finite(C[i][j]);
  const T rn = N::sqrt(dot3<N>(r, r));
  alive = alive & (rn > 0.0);
  s.ns = N::index(0);
  s.a = N::splat(0.0);
  for (int i = 0; i < 3; ++i) {
    s.y[i] = N::splat(0.0);
    s.v[i] = r[i];
    s.wS[i] = N::splat(0.0);
  }
  Mask fail = N::not_(alive);
  steps = 0;
  if (!N::any(alive)) return alive;
  auto Cmul = [&](const T (&y)[3], T (&out)[3]) {  // r + C y
    mat_vec<N>([&](int i, int j) { return C[i][j]; }, y, out);
    for (int i = 0; i < 3; ++i) out[i] = r[i] + out[i];
  };
  // The active sets {k} + a subset of S, most faces first: the optimum
  // usually keeps every face of S (a face, then an edge, then a vertex),
  // so the first set tried is usually the one (on the paper's sweep, 2.2
  // sets a call instead of 4.4 fewest first: about 500 instructions).
  static constexpr int kPick[7][2] = {{0, 1}, {0, 2}, {1, 2}, {0, -1}, {1, -1}, {2, -1}, {-1, -1}};
  for (int it = 0;; ++it) {
    steps = it;
    SimplexEntering<N> e;
    const Mask go = alive & scan(s.v, s.a, k.tol * (rn + s.a * size), e);
    if (!N::any(go)) break;  // feasible: optimal
    if (it == k.max_steps) {
      fail = fail | go;
      break;
    }
    BallFace<N> f;
    const T an[3] = {e.ax, e.ay, e.az};
    for (int i = 0; i < 3; ++i) f.g[i] = (C[0][i] * an[0] + C[1][i] * an[1]) + C[2][i] * an[2];
    f.b = e.b;
    f.h = dot3<N>(an, r);
    Mask found = N::not_(go);  // lanes with nothing to look for count as found
    auto try_set = [&](auto kk, int c) {
      constexpr int K = decltype(kk)::value;
      const int p0 = kPick[c][0], p1 = kPick[c][1];
      Mask valid = N::not_(found) & (s.ns > p0) & (s.ns > p1);
      if (!N::any(valid)) return;
      const BallFace<N>* U[K];
      U[0] = &f;
      if constexpr (K >= 2) U[1] = &s.S[p0];
      if constexpr (K == 3) U[2] = &s.S[p1];
      T bU[K], w[K] = {}, a_n = N::splat(0.0), yn[3] = {};  // set by ball_set where valid
      for (int j = 0; j < K; ++j) bU[j] = U[j]->b;
      valid = valid & ball_set<N, K>(U, bU, a_n, yn, w);
      if (!N::any(valid)) return;
      // KKT: w <= 0.
      T wmax = N::splat(0.0), wpos = N::splat(-__builtin_inf());
      for (int j = 0; j < K; ++j) {
        const T aw = N::abs(w[j]);
        wmax = N::sel(wmax < aw, aw, wmax);  // std::max(wmax, |w|)
        wpos = N::sel(wpos < w[j], w[j], wpos);
      }
      valid = valid & N::not_(wpos > 1e-12 * wmax);
      // The faces of S left out of U hold.
      const T tol = k.tol * (rn + a_n * size);
      for (int j = 0; j < 3; ++j) {
        if (j == p0 || j == p1) continue;
        const Mask in = s.ns > j;
        if (!N::any(valid & in)) continue;
        valid = valid & (N::not_(in) | (dot3<N>(s.S[j].g, yn) + s.S[j].h - a_n * s.S[j].b <= tol));
      }
      if (!N::any(valid)) return;
      BallFace<N> keep[K];
      for (int j = 0; j < K; ++j) keep[j] = *U[j];
      for (int j = 0; j < K; ++j) {
        for (int i = 0; i < 3; ++i) s.S[j].g[i] = N::sel(valid, keep[j].g[i], s.S[j].g[i]);
        s.S[j].b = N::sel(valid, keep[j].b, s.S[j].b);
        s.S[j].h = N::sel(valid, keep[j].h, s.S[j].h);
        s.wS[j] = N::sel(valid, w[j], s.wS[j]);
      }
      s.ns = N::sel_index(valid, K, s.ns);
      s.a = N::sel(valid, a_n, s.a);
      for (int i = 0; i < 3; ++i) s.y[i] = N::sel(valid, yn[i], s.y[i]);
      found = found | valid;
    };
    try_set(SetSize<3>{}, 0), try_set(SetSize<3>{}, 1), try_set(SetSize<3>{}, 2);
    try_set(SetSize<2>{}, 3), try_set(SetSize<2>{}, 4), try_set(SetSize<2>{}, 5);
    try_set(SetSize<1>{}, 6);
    const Mask none = go & N::not_(found);  // no active set holds: numerical trouble
    fail = fail | none;
    alive = alive & N::not_(none);
    if (!N::any(alive)) break;
    T v[3];
    Cmul(s.y, v);
    for (int i = 0; i < 3; ++i) s.v[i] = N::sel(go, v[i], s.v[i]);
  }
  if (k.soft > 0.0) {
    // The smooth polytope's contact to first order where an edge or a
    // vertex touches: the active faces' offsets moved by soft log(mu /
    // sum mu) (mu = -w), and the contact solved again.
    const Mask two = alive & (s.ns >= 2);
    if (N::any(two)) {
      const Mask three = s.ns >= 3;
      T sum = N::splat(0.0);
      sum = sum - s.wS[0];
      sum = sum - s.wS[1];
      sum = N::sel(three, sum - s.wS[2], sum);
      Mask ok = two & (sum > 0.0);
      T bU[3];
      for (int j = 0; j < 3; ++j) {
        const Mask in = j < 2 ? N::mask(true) : three;
        bU[j] = s.S[j].b;
        if (!N::any(ok & in)) continue;
        ok = ok & (N::not_(in) | (-s.wS[j] > 0.0));
        bU[j] = s.S[j].b + k.soft * log_start<N>(N::sel(ok, -s.wS[j] / sum, N::splat(1.0)));
      }
      if (N::any(ok)) {
        T a2 = N::splat(0.0), y2[3] = {}, w2[2], a3 = N::splat(0.0), y3[3] = {}, w3[3];
        const BallFace<N>* U2[2] = {&s.S[0], &s.S[1]};
        const BallFace<N>* U3[3] = {&s.S[0], &s.S[1], &s.S[2]};
        const T b2[2] = {bU[0], bU[1]};
        Mask ok2 = ok & N::not_(three), ok3 = ok & three;
        if (N::any(ok2)) ok2 = ok2 & ball_set<N, 2>(U2, b2, a2, y2, w2);
        if (N::any(ok3)) ok3 = ok3 & ball_set<N, 3>(U3, bU, a3, y3, w3);
        const Mask moved = ok2 | ok3;
        s.a = N::sel(ok2, a2, N::sel(ok3, a3, s.a));
        T v[3], yy[3];
        for (int i = 0; i < 3; ++i) yy[i] = N::sel(ok2, y2[i], N::sel(ok3, y3[i], s.y[i]));
        Cmul(yy, v);
        for (int i = 0; i < 3; ++i) {
          s.y[i] = yy[i];
          s.v[i] = N::sel(moved, v[i], s.v[i]);
        }
      }
    }
  }
  return alive & N::not_(fail) & (s.a > 0.0) & N::finite(s.a) & N::finite(s.v[0]) & N::finite(s.v[1]) &
         N::finite(s.v[2]);
}

}  // namespace idcol::detail::formulas
