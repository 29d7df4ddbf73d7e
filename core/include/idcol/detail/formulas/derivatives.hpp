// The derivatives of a converged contact (derivatives.cpp: alpha_gradient,
// solution_sensitivity, contact_kinematics_derivatives, contact_wrench and
// contact_wrench_derivatives) written once over a number layer N
// (elementary.hpp): the library's functions instantiate them with double,
// the batch's Newton lanes (newton_lanes_kernel.hpp) with a vector of W
// doubles, so that a row's derivatives formed in lanes are the loop's, bit
// for bit.
//
// A point q (DerivPoint) holds what they read of a solve: alpha*, k,
// lambda2, the row scale of the factorised Jacobian, and where to read x_1,
// r = p_12, R_12, the witness points y1, y2 in the bodies' frames, and each
// body's gradient and Hessian there (3-vectors, and 3x3 matrices stored by
// columns as Eigen stores them: entry (i, j) at [i + 3 j], read by m3), so
// that the library hands its SolveResult's own storage over uncopied. `lu` is the LU of the scaled KKT Jacobian
// J_int (result.hpp): lu.solve_columns(B, X) gives J_int X = B (6 x 6,
// each column as lu6_solve solves it) and lu.solve_transpose(b, x)
// J_int^T x = b. A sum of terms adds left to
// right; (A B)(i, j) = (A(i, 0) B(0, j) + A(i, 1) B(1, j)) + A(i, 2) B(2, j).
// The equations are the paper's (eq:...); derivatives.cpp says what each
// function gives.
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/elementary.hpp"

namespace idcol::detail::formulas {

/// What the derivatives read of a converged solve (SolveResult and its
/// internal part).
template <class T>
struct DerivPoint {
  T alpha, k, lambda2;
  T L;      // the pair length r1_out + r2_out
  T rs[6];  // the row scale D_r of J_int (row 0's meets the zero row of G_c)
  const T *x1, *r, *y1, *y2, *g1, *g2;  // 3 each
  const T *R, *H1, *H2;                 // 9 each, by columns (m3)
};

/// Entry (i, j) of a 3x3 matrix stored by columns.
template <class T>
[[gnu::always_inline]] inline const T& m3(const T* M, int i, int j) {
  return M[i + 3 * j];
}

/// a x b.
template <class T>
[[gnu::always_inline]] inline void cross3(const T* a, const T* b, T* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

/// R^T v, R by columns.
template <class T>
[[gnu::always_inline]] inline void rt_times(const T* R, const T* v, T* out) {
  for (int i = 0; i < 3; ++i) out[i] = (m3(R, 0, i) * v[0] + m3(R, 1, i) * v[1]) + m3(R, 2, i) * v[2];
}

/// v scaled by its largest |entry| m: u = v / m and n = |u|, so that |v| =
/// m n neither overflows nor underflows. The mask: m is finite and > 0
/// (elsewhere u and n are not meaningful, and m is NaN where v holds one).
template <class N>
[[gnu::always_inline]] inline auto scaled3(const typename N::T* v, typename N::T& m, typename N::T (&u)[3],
                                           typename N::T& n) {
  const auto a0 = N::abs(v[0]), a1 = N::abs(v[1]), a2 = N::abs(v[2]);
  m = N::sel(a1 > a0, a1, a0);
  m = N::sel(a2 > m, a2, m);
  const auto nan = N::not_(v[0] == v[0]) | N::not_(v[1] == v[1]) | N::not_(v[2] == v[2]);
  m = N::sel(nan, N::splat(__builtin_nan("")), m);
  for (int i = 0; i < 3; ++i) u[i] = v[i] / m;
  n = N::sqrt((u[0] * u[0] + u[1] * u[1]) + u[2] * u[2]);
  return (m > 0.0) & N::finite(m);
}

/// |v| (scaled3): m itself where v holds only zeros, an infinity or a NaN.
template <class N>
[[gnu::always_inline]] inline typename N::T stable_norm(const typename N::T* v) {
  typename N::T m, n, u[3];
  const auto ok = scaled3<N>(v, m, u, n);
  return N::sel(ok, m * n, m);
}

/// v / |v| (scaled3): v itself where it is zero or not finite.
template <class N>
[[gnu::always_inline]] inline void stable_normalized(const typename N::T* v, typename N::T (&out)[3]) {
  typename N::T m, n, u[3];
  const auto ok = scaled3<N>(v, m, u, n);
  for (int i = 0; i < 3; ++i) out[i] = N::sel(ok, u[i] / n, v[i]);
}

/// eq:gap, (1 - 1/alpha) |r| as |r| - |r| / alpha; halved and doubled where
/// that overflows (|r| / alpha, the two bodies' extents along r, near the
/// double range).
template <class N>
[[gnu::always_inline]] inline typename N::T contact_gap(typename N::T nr, typename N::T a) {
  const typename N::T gap = nr - nr / a;
  return N::sel(N::finite(gap), gap, 2.0 * (0.5 * nr - (0.5 * nr) / a));
}

/// Ad_{X_12}^T F for a wrench F = (moment, force) in frame 1: the wrench in
/// frame 2, its moment about frame 2's origin.
template <class T>
[[gnu::always_inline]] inline void coadjoint_t(const T* R, const T* p, const T* F, T* out) {
  const T f[3] = {F[3], F[4], F[5]};
  T pf[3];
  cross3(p, f, pf);
  const T m[3] = {F[0] - pf[0], F[1] - pf[1], F[2] - pf[2]};
  T a[3], b[3];
  rt_times(R, m, a);
  rt_times(R, f, b);
  for (int i = 0; i < 3; ++i) out[i] = a[i], out[3 + i] = b[i];
}

/// G_c of eq:df_dq with J = I, for the unscaled residual of
/// eq:kkt_residual in (x, s = log alpha, lambda1, lambda2): rows 1-5 in
/// G[0..4] (row 0, phi1, does not depend on the pose): a^T (eq:phi_q),
/// lambda2 B (eq:phi_xq), lambda2 c^T (eq:phi_alphaq), with y_q from
/// eq:y_partials_q, [y2~, -I / alpha].
template <class N>
[[gnu::always_inline]] inline void g_matrix(const DerivPoint<typename N::T>& q, typename N::T (&G)[5][6]) {
  using T = typename N::T;
  const T m = -1.0 / q.alpha;
  const T* y = q.y2;
  const T* g = q.g2;
  const T* H = q.H2;
  // g^T [y~, m I] = ((g x y)^T, m g^T)
  T gy[3];
  cross3(g, y, gy);
  for (int j = 0; j < 3; ++j) {
    G[0][j] = gy[j];
    G[0][3 + j] = m * g[j];
  }
  // B = [H y~ - g~, m H]; (H y~) e_j = H (y x e_j)
  T B[3][6];
  for (int i = 0; i < 3; ++i) {
    B[i][0] = m3(H, i, 1) * y[2] - m3(H, i, 2) * y[1];
    B[i][1] = m3(H, i, 2) * y[0] - m3(H, i, 0) * y[2];
    B[i][2] = m3(H, i, 0) * y[1] - m3(H, i, 1) * y[0];
    for (int j = 0; j < 3; ++j) B[i][3 + j] = m * m3(H, i, j);
  }
  B[0][1] = B[0][1] + g[2];
  B[0][2] = B[0][2] - g[1];
  B[1][0] = B[1][0] - g[2];
  B[1][2] = B[1][2] + g[0];
  B[2][0] = B[2][0] + g[1];
  B[2][1] = B[2][1] - g[0];
  const T c = q.lambda2 / q.alpha;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 6; ++j)
      G[1 + i][j] = c * ((m3(q.R, i, 0) * B[0][j] + m3(q.R, i, 1) * B[1][j]) + m3(q.R, i, 2) * B[2][j]);
  // -(lambda2 / alpha) (g + H y)^T [y~, m I]
  T v[3], vy[3];
  for (int i = 0; i < 3; ++i) v[i] = g[i] + ((m3(H, i, 0) * y[0] + m3(H, i, 1) * y[1]) + m3(H, i, 2) * y[2]);
  cross3(v, y, vy);
  const T cn = -q.lambda2 / q.alpha;
  for (int j = 0; j < 3; ++j) {
    G[4][j] = cn * vy[j];
    G[4][3 + j] = cn * (m * v[j]);
  }
}

/// d alpha / d xi = -alpha (D_r J_int^{-T} e_s)^T G_c.
template <class N, class Lu>
[[gnu::always_inline]] inline void alpha_gradient(const DerivPoint<typename N::T>& q, const typename N::T (&G)[5][6],
                                                  const Lu& lu, typename N::T (&out)[6]) {
  using T = typename N::T;
  const T zero = N::splat(0.0);
  const T e[6] = {zero, zero, zero, N::splat(1.0), zero, zero};
  T t[6];
  lu.solve_transpose(e, t);
  const T w[5] = {q.rs[1] * t[1], q.rs[2] * t[2], q.rs[3] * t[3], q.rs[4] * t[4], q.rs[5] * t[5]};
  const T na = -q.alpha;
  for (int j = 0; j < 6; ++j)
    out[j] = na * ((((w[0] * G[0][j] + w[1] * G[1][j]) + w[2] * G[2][j]) + w[3] * G[3][j]) + w[4] * G[4][j]);
}

/// dz / d xi = -D_c^{-1} J_int^{-1} D_r G_c (eq:dz_dq), rows x (3), alpha
/// (d alpha = alpha ds), lambda1, lambda2: D_c^{-1} = diag(k L I3, alpha,
/// k, k).
template <class N, class Lu>
[[gnu::always_inline]] inline void sensitivity(const DerivPoint<typename N::T>& q, const typename N::T (&G)[5][6],
                                               const Lu& lu, typename N::T (&dz)[6][6]) {
  using T = typename N::T;
  const T kL = q.k * q.L;
  const T scale[6] = {kL, kL, kL, q.alpha, q.k, q.k};
  T B[6][6], X[6][6];  // B = D_r G_c, row i; J_int X = B, column by column
  for (int j = 0; j < 6; ++j) {
    B[0][j] = N::splat(0.0);
    for (int i = 1; i < 6; ++i) B[i][j] = q.rs[i] * G[i - 1][j];
  }
  lu.solve_columns(B, X);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) dz[i][j] = scale[i] * -X[i][j];
}

/// The contact kinematics' derivatives with respect to xi (eq:witness,
/// eq:ddD_dq, eq:dnhat_dq), each row-major, 6 columns.
template <class T>
struct KinematicsDerivs {
  T dp1[3][6], dp2[3][6], dgap[6], dn[3][6];
};

/// From dz / d xi. Products grouped so that none overflows at tiny |r|
/// (alpha ~ |r|, x ~ r): x / alpha, (r - x) / alpha and |r| / alpha are
/// O(1). The normal's: d nhat = (I - n n^T) H1 dy1 / |grad phi1| with dy1
/// = dx / alpha - y1 d alpha / alpha (its term in d alpha vanishes for
/// bodies with phi + 1 homogeneous of degree 1, not for the smooth polytope
/// and cone).
template <class N>
[[gnu::always_inline]] inline void kinematics_derivatives(const DerivPoint<typename N::T>& q,
                                                          const typename N::T (&dz)[6][6],
                                                          KinematicsDerivs<typename N::T>& d) {
  using T = typename N::T;
  const T a = q.alpha, ia = 1.0 / a, oma = 1.0 - ia;
  const T nr = stable_norm<N>(q.r);
  T da_a[6];
  for (int j = 0; j < 6; ++j) da_a[j] = ia * dz[3][j];
  for (int i = 0; i < 3; ++i) {
    const T c = q.r[i] / a - q.x1[i] / a;
    for (int j = 0; j < 6; ++j) {
      d.dp1[i][j] = ia * dz[i][j] - q.y1[i] * da_a[j];
      const T t = c * da_a[j];
      d.dp2[i][j] = (j < 3 ? t : t + oma * m3(q.R, i, j - 3)) + ia * dz[i][j];
    }
  }
  const T ca = (nr * ia) * ia;
  const T rn[3] = {q.r[0] / nr, q.r[1] / nr, q.r[2] / nr};
  for (int j = 0; j < 3; ++j) {
    d.dgap[j] = ca * dz[3][j];
    d.dgap[3 + j] = ca * dz[3][3 + j] + oma * ((rn[0] * m3(q.R, 0, j) + rn[1] * m3(q.R, 1, j)) + rn[2] * m3(q.R, 2, j));
  }
  const T ng = stable_norm<N>(q.g1);
  const T n[3] = {q.g1[0] / ng, q.g1[1] / ng, q.g1[2] / ng};
  T M[3][3];  // (I - n n^T) H1 / ng
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const T p0 = (i == 0 ? 1.0 : 0.0) - n[i] * n[0], p1 = (i == 1 ? 1.0 : 0.0) - n[i] * n[1],
              p2 = (i == 2 ? 1.0 : 0.0) - n[i] * n[2];
      M[i][j] = ((p0 * m3(q.H1, 0, j) + p1 * m3(q.H1, 1, j)) + p2 * m3(q.H1, 2, j)) / ng;
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 6; ++j) d.dn[i][j] = (M[i][0] * d.dp1[0][j] + M[i][1] * d.dp1[1][j]) + M[i][2] * d.dp1[2][j];
}

/// The Hertz contact wrench (eq:contactmodel, eq:contact_wrench) of a
/// contact with gap `gap` and body 1's unit normal n: active where delta =
/// -gap > 0; f_n = stiffness delta^exponent, F1 = (x1 x f, f) with f = -f_n
/// n on body 1, F2 = -Ad_{X_12}^T F1 on body 2; representable where all of
/// them are finite.
template <class N>
struct Wrench {
  using T = typename N::T;
  T delta, f_n, F1[6], F2[6];
  typename N::Mask active, representable;
};

template <class N>
[[gnu::always_inline]] inline void contact_wrench(const DerivPoint<typename N::T>& q, typename N::T gap,
                                                  const typename N::T (&n)[3], double stiffness, double exponent,
                                                  Wrench<N>& w) {
  using T = typename N::T;
  w.delta = -gap;
  w.active = w.delta > 0.0;
  // No power where no contact is active (most of a scene's rows).
  w.f_n = N::any(w.active) ? stiffness * N::pow(w.delta, exponent) : N::splat(0.0);
  const T nf = -w.f_n;
  const T f[3] = {nf * n[0], nf * n[1], nf * n[2]};
  T m[3];
  cross3(q.x1, f, m);
  for (int i = 0; i < 3; ++i) w.F1[i] = m[i], w.F1[3 + i] = f[i];
  T F2[6];
  coadjoint_t(q.R, q.r, w.F1, F2);
  auto fin = N::finite(w.f_n);
  for (int i = 0; i < 6; ++i) {
    w.F2[i] = -F2[i];
    fin = fin & N::finite(w.F1[i]) & N::finite(w.F2[i]);
  }
  w.representable = fin;
}

/// The wrench's derivatives with respect to xi: d f_n = -stiffness exponent
/// delta^(exponent - 1) d gap; df = -n df_n - f_n dn (eq:dfc_dq); dF1 = [-f~
/// dx + x1~ df; df] (eq:dFc1_dq); dF2 = -Ad^T dF1 + [[m2~, f2~], [f2~, 0]]
/// (eq:dFc2_dq, with d(Ad_g^T) = ad_xi^T Ad_g^T). Row-major, 6 columns.
template <class T>
struct WrenchDerivs {
  T df_n[6], dF1[6][6], dF2[6][6];
};

template <class N>
[[gnu::always_inline]] inline void wrench_derivatives(const DerivPoint<typename N::T>& q, const typename N::T (&dz)[6][6],
                                                      const typename N::T (&n)[3], const KinematicsDerivs<typename N::T>& kd,
                                                      const Wrench<N>& w, double stiffness, double exponent,
                                                      WrenchDerivs<typename N::T>& d) {
  using T = typename N::T;
  const T c = (-stiffness * exponent) * N::pow(w.delta, exponent - 1.0);
  for (int j = 0; j < 6; ++j) d.df_n[j] = c * kd.dgap[j];
  const T f[3] = {w.F1[3], w.F1[4], w.F1[5]};
  for (int j = 0; j < 6; ++j) {
    T df[3], dx[3];
    for (int i = 0; i < 3; ++i) {
      df[i] = -n[i] * d.df_n[j] - w.f_n * kd.dn[i][j];
      dx[i] = dz[i][j];
    }
    T fdx[3], xdf[3];
    cross3(f, dx, fdx);
    cross3(q.x1, df, xdf);
    T col[6];
    for (int i = 0; i < 3; ++i) {
      col[i] = xdf[i] - fdx[i];
      col[3 + i] = df[i];
    }
    T out[6];
    coadjoint_t(q.R, q.r, col, out);
    for (int i = 0; i < 6; ++i) {
      d.dF1[i][j] = col[i];
      d.dF2[i][j] = -out[i];
    }
  }
  // + [[m2~, f2~], [f2~, 0]], (m2, f2) = F2
  const T* m2 = w.F2;
  const T* f2 = w.F2 + 3;
  auto add_skew = [&](int r0, int c0, const T* v) {
    d.dF2[r0 + 0][c0 + 1] = d.dF2[r0 + 0][c0 + 1] - v[2];
    d.dF2[r0 + 0][c0 + 2] = d.dF2[r0 + 0][c0 + 2] + v[1];
    d.dF2[r0 + 1][c0 + 0] = d.dF2[r0 + 1][c0 + 0] + v[2];
    d.dF2[r0 + 1][c0 + 2] = d.dF2[r0 + 1][c0 + 2] - v[0];
    d.dF2[r0 + 2][c0 + 0] = d.dF2[r0 + 2][c0 + 0] - v[1];
    d.dF2[r0 + 2][c0 + 1] = d.dF2[r0 + 2][c0 + 1] + v[0];
  };
  add_skew(0, 0, m2);
  add_skew(0, 3, f2);
  add_skew(3, 0, f2);
}

}  // namespace idcol::detail::formulas
