// phi, its gradient and its Hessian of the superquadric and cone families,
// written once over a number layer N (elementary.hpp says what N
// provides): the scalar shapes (shapes.hpp, shapes.cpp) instantiate them
// with double, the batch lanes (newton_lanes_kernel.hpp) with a vector of W
// doubles, so that a lane's evaluation is the shape's own, bit for bit.
//
// Each evaluation writes through N's accessors of an output E:
// N::phi(e), N::grad(e, i), N::hess(e, i, j) (ShapeEval for the scalar
// layer; the lanes' Eval). The Hessian is symmetric to the bit: each
// off-diagonal product is formed once and written to both entries.
//
// An exponent Ex (the superquadrics' n) has members n (double), n_int (n
// where n is an integer <= 1024, else 0) and sqrt_depth (k where 2n = 2^k,
// else -1), constants where n is known at compile time (FixedExponent) so
// that the powers and roots unroll.
//
// Templates only and no includes, for the reason elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/elementary.hpp"

namespace idcol::detail::formulas {

/// |x|^(2n-2) for |x| <= 1.
template <class N, class Ex>
[[gnu::always_inline]] inline typename N::T pow_2n_minus_2(const Ex& ex, typename N::T x) {
  if (ex.n_int) return N::ipow(x * x, ex.n_int - 1);
  return N::lazy(
      x == 0.0, [&] { return N::splat(ex.n == 1.0 ? 1.0 : 0.0); }, [&] { return N::pow(N::abs(x), 2.0 * ex.n - 2.0); });
}
/// |x|^(2n) for |x| <= 1.
template <class N, class Ex>
[[gnu::always_inline]] inline typename N::T pow_2n(const Ex& ex, typename N::T x) {
  return ex.n_int ? N::ipow(x * x, ex.n_int) : N::pow(N::abs(x), 2.0 * ex.n);
}
/// q^(n-1) for q in [0, 1].
template <class N, class Ex>
[[gnu::always_inline]] inline typename N::T pow_n_minus_1(const Ex& ex, typename N::T q) {
  if (ex.n_int) return N::ipow(q, ex.n_int - 1);
  return N::lazy(q == 0.0, [&] { return N::splat(0.0); }, [&] { return N::pow(q, ex.n - 1.0); });
}
/// S^(1/(2n)) for S in [1, 3]: sqrt_depth square roots where 2n = 2^k.
template <class N, class Ex>
[[gnu::always_inline]] inline typename N::T root_2n(const Ex& ex, typename N::T S) {
  if (ex.sqrt_depth >= 0) {
    for (int i = 0; i < ex.sqrt_depth; ++i) S = N::sqrt(S);
    return S;
  }
  return N::pow(S, 0.5 / ex.n);
}

/// The frame origin of a superquadric: psi = 0, derivatives undefined;
/// phi = -1, gradient and Hessian 0.
template <class N, class E>
inline void at_origin(E& e) {
  N::phi(e) = N::splat(-1.0);
  for (int i = 0; i < 3; ++i) {
    N::grad(e, i) = N::splat(0.0);
    for (int j = 0; j < 3; ++j) N::hess(e, i, j) = N::splat(0.0);
  }
}

/// Sphere of radius R (iR = 1/R): phi(y) = |y|/R - 1, gradient u/R and
/// Hessian (I - u u^T) / (R |y|) with u = y/|y|; |y| is the square root of
/// (y0^2 + y1^2) + y2^2, as Eigen's norm. Two divisions, phi's and 1/|y|:
/// the rest are products (a division of W lanes holds the divider about as
/// long as W scalar ones do). At the frame origin (|y| = 0: phi = -1, the
/// gradient undefined), N::leaves.
template <class N, class E>
[[gnu::always_inline]] inline void sphere(double R, double iR, typename N::T y0, typename N::T y1, typename N::T y2, E& e,
                                          typename N::Mask& bad) {
  using T = typename N::T;
  const T ny = N::sqrt((y0 * y0 + y1 * y1) + y2 * y2);
  N::phi(e) = ny / R - 1.0;
  if (N::leaves(N::not_(ny > 0.0), bad)) {
    for (int i = 0; i < 3; ++i) {
      N::grad(e, i) = N::splat(0.0);
      for (int j = 0; j < 3; ++j) N::hess(e, i, j) = N::splat(0.0);
    }
    return;
  }
  const T iny = 1.0 / ny;
  const T u[3] = {y0 * iny, y1 * iny, y2 * iny};
  for (int i = 0; i < 3; ++i) N::grad(e, i) = u[i] * iR;
  const T h = iR * iny;
  for (int i = 0; i < 3; ++i) {
    N::hess(e, i, i) = (1.0 - u[i] * u[i]) * h;
    for (int j = i + 1; j < 3; ++j) N::hess(e, i, j) = N::hess(e, j, i) = -(u[i] * u[j]) * h;
  }
}

/// Superellipsoid (a, b, c, n) with inv = (1/a, 1/b, 1/c):
///   phi(y) = (|y1/a|^(2n) + |y2/b|^(2n) + |y3/c|^(2n))^(1/(2n)) - 1,
/// evaluated with the largest |y_i/a_i| = m factored out, so that nothing
/// overflows: u = (y/a)/m, S = sum |u_i|^(2n) in [1, 3], psi = m S^(1/2n).
/// At the frame origin, N::leaves.
template <class N, class Ex, class E>
[[gnu::always_inline]] inline void superellipsoid(const double* inv, const Ex& ex, typename N::T y0, typename N::T y1,
                                                  typename N::T y2, E& e, typename N::Mask& bad) {
  using T = typename N::T;
  const T yb[3] = {y0 * inv[0], y1 * inv[1], y2 * inv[2]};
  T m = N::abs(yb[0]);
  m = N::sel(N::abs(yb[1]) > m, N::abs(yb[1]), m);
  m = N::sel(N::abs(yb[2]) > m, N::abs(yb[2]), m);
  if (N::leaves(N::not_(m > 0.0), bad)) return at_origin<N>(e);
  const T im = 1.0 / m;
  const T u[3] = {yb[0] * im, yb[1] * im, yb[2] * im};
  // p_i = |u_i|^(2n-2); S = sum |u_i|^(2n) = sum p_i u_i^2 is in [1, 3].
  T p[3];
  for (int i = 0; i < 3; ++i) p[i] = pow_2n_minus_2<N>(ex, u[i]);
  const T S = p[0] * u[0] * u[0] + p[1] * u[1] * u[1] + p[2] * u[2] * u[2];
  const T root = root_2n<N>(ex, S);
  const T psi = m * root;
  // w = u / root, and d_i = |w_i|^(2n-2) = p_i / root^(2n-2) = p_i root^2 / S
  // (root^(2n) = S), so no power is taken twice.
  const T ir = 1.0 / root;
  // root^2 / S = root^-(2n-2), by multiplications where n is an integer.
  const T sc = ex.n == 1.0 ? N::splat(1.0) : (ex.n_int ? N::ipow(ir * ir, ex.n_int - 1) : root * root / S);
  const double k = 2.0 * ex.n - 1.0;
  T d[3], G[3];
  for (int i = 0; i < 3; ++i) {
    d[i] = p[i] * sc;
    G[i] = (d[i] * (u[i] * ir)) * inv[i];
  }
  N::phi(e) = psi - 1.0;
  for (int i = 0; i < 3; ++i) N::grad(e, i) = G[i];
  // hess = D (k/psi) (diag(d) - g g^T) D, D = diag(1/a, 1/b, 1/c):
  // -(k/psi) G_i G_j with G = D g (the gradient), and (k/psi) d_i / a_i^2 on
  // the diagonal; 1/psi = (1/m)(1/root), no division.
  const T kp = k * (im * ir), nkp = -kp;
  for (int i = 0; i < 3; ++i) {
    N::hess(e, i, i) = nkp * (G[i] * G[i]) + kp * (d[i] * (inv[i] * inv[i]));
    for (int j = i + 1; j < 3; ++j) N::hess(e, i, j) = N::hess(e, j, i) = nkp * (G[i] * G[j]);
  }
}

/// Superelliptic cylinder (R, h, n), axis along y1, with ih = 1/h, iR = 1/R:
///   phi(y) = ((y1/h)^(2n) + ((y2^2 + y3^2)/R^2)^n)^(1/(2n)) - 1,
/// with m = max(|y1/h|, |(y2, y3)/R|) factored out. Two divisions (1/m,
/// 1/psi), the rest multiplications. At the frame origin, N::leaves.
template <class N, class Ex, class E>
[[gnu::always_inline]] inline void superelliptic_cylinder(double ih, double iR, const Ex& ex, typename N::T y0,
                                                          typename N::T y1, typename N::T y2, E& e, typename N::Mask& bad) {
  using T = typename N::T;
  const T w0 = y0 * ih, w2 = y1 * iR, w3 = y2 * iR;
  const T rho = hypot_any<N>(w2, w3);
  const T a1 = N::abs(w0);
  const T m = N::sel(rho > a1, rho, a1);
  if (N::leaves(N::not_(m > 0.0), bad)) return at_origin<N>(e);
  const T im = 1.0 / m;
  const T S = pow_2n<N>(ex, w0 * im) + pow_2n<N>(ex, rho * im);  // in [1, 2]
  const T psi = m * root_2n<N>(ex, S);
  const T ip = 1.0 / psi;
  const T w1 = w0 * ip, e2 = w2 * ip, e3 = w3 * ip;
  const T q = e2 * e2 + e3 * e3;  // (rho/psi)^2 <= 1
  const double k = 2.0 * ex.n - 1.0;
  const T d1 = pow_2n_minus_2<N>(ex, w1);
  const T g1 = d1 * w1;
  const T qn1 = pow_n_minus_1<N>(ex, q);
  const T g2 = qn1 * e2, g3 = qn1 * e3;
  // q^(n-2) e_k e_l = q^(n-1) e_k e_l / q (q^(n-2) itself for an integer
  // n), zero when n = 1 or q = 0.
  const T c2 = ex.n == 1.0 ? N::splat(0.0)
                           : N::lazy(
                                 q == 0.0, [&] { return N::splat(0.0); },
                                 [&] { return 2.0 * (ex.n - 1.0) * (ex.n_int ? N::ipow(q, ex.n_int - 2) : qn1 / q); });
  N::phi(e) = psi - 1.0;
  N::grad(e, 0) = g1 * ih;
  N::grad(e, 1) = g2 * iR;
  N::grad(e, 2) = g3 * iR;
  const T kip = k * ip;
  const T H11 = kip * (d1 - g1 * g1);
  const T H12 = -kip * (g1 * g2), H13 = -kip * (g1 * g3);
  const T H22 = ip * (qn1 + c2 * (e2 * e2) - k * (g2 * g2));
  const T H33 = ip * (qn1 + c2 * (e3 * e3) - k * (g3 * g3));
  const T H23 = ip * (c2 * (e2 * e3) - k * (g2 * g3));
  const double ih2 = ih * ih, ihR = ih * iR, iR2 = iR * iR;
  N::hess(e, 0, 0) = H11 * ih2;
  N::hess(e, 0, 1) = N::hess(e, 1, 0) = H12 * ihR;
  N::hess(e, 0, 2) = N::hess(e, 2, 0) = H13 * ihR;
  N::hess(e, 1, 1) = H22 * iR2;
  N::hess(e, 1, 2) = N::hess(e, 2, 1) = H23 * iR2;
  N::hess(e, 2, 2) = H33 * iR2;
}

/// The smooth truncated cone's constants: base radius Rb at y1 = -a, top
/// radius Rt at y1 = b, kappa = (Rt - Rb) / (a + b), Rfloor = min(Rb, Rt) / 2
/// (shapes.hpp says why), and the end caps' gradients -1/a and 1/b.
struct ConeConsts {
  double Rb, kappa, a, b, Rfloor, gbx, gtx;
};

/// Smooth truncated cone at sharpness `sharp`:
///   phi = smax_sharp(r^2/R(y1)^2 - 1, -y1/a - 1, y1/b - 1),
/// the LogSumExp with the maximum shifted out, its Hessian in covariance
/// form sum w_i H_i + sharp sum w_i (g_i - g)(g_i - g)^T (no overflow when the
/// side term's gradient is huge far from the body, no cancellation). The
/// log of the sum of weights, in [1, 3], is log_ge1's, inline and in lanes
/// (a lane whose sum is not finite leaves by `bad`).
template <class N, class E>
[[gnu::always_inline]] inline void smooth_truncated_cone(const ConeConsts& c, double sharp, typename N::T y0,
                                                         typename N::T y1, typename N::T y2, E& e,
                                                         typename N::Mask& bad) {
  using T = typename N::T;
  const T R0 = c.Rb + c.kappa * (y0 + c.a);
  const auto floor = R0 < c.Rfloor;  // only beyond the body's axial range
  const T R = N::sel(floor, N::splat(c.Rfloor), R0);
  const T kap = N::sel(floor, N::splat(0.0), N::splat(c.kappa));
  const T iR = 1.0 / R, iR2 = iR * iR;
  const T r2 = y1 * y1 + y2 * y2;
  const T cs = r2 * iR2 - 1.0;
  const T cb = -y0 / c.a - 1.0;
  const T ct = y0 / c.b - 1.0;
  // max(cs, cb, ct), the first of equal maxima.
  T cmax = cs;
  cmax = N::sel(cmax < cb, cb, cmax);
  cmax = N::sel(cmax < ct, ct, cmax);
  const T es = exp_nonpositive<N>(sharp * (cs - cmax)), eb = exp_nonpositive<N>(sharp * (cb - cmax)),
          et = exp_nonpositive<N>(sharp * (ct - cmax));
  const T S = es + eb + et;
  const T ws = es / S, wb = eb / S, wt = et / S;
  const T gs[3] = {-2.0 * kap * r2 * iR2 * iR, 2.0 * y1 * iR2, 2.0 * y2 * iR2};
  N::phi(e) = cmax + log_ge1<N>(S, bad) / sharp;  // S in [1, 3]: its largest term is e^0
  T g[3] = {ws * gs[0], ws * gs[1], ws * gs[2]};
  g[0] = g[0] + (wb * c.gbx + wt * c.gtx);
  for (int i = 0; i < 3; ++i) N::grad(e, i) = g[i];
  const T ds[3] = {gs[0] - g[0], gs[1] - g[1], gs[2] - g[2]};
  const T db[3] = {c.gbx - g[0], -g[1], -g[2]};
  const T dt[3] = {c.gtx - g[0], -g[1], -g[2]};
  const T h01 = -4.0 * kap * y1 * iR2 * iR, h02 = -4.0 * kap * y2 * iR2 * iR;
  const T z = N::splat(0.0);
  const T Hs[9] = {6.0 * kap * kap * r2 * iR2 * iR2, h01, h02, h01, 2.0 * iR2, z, h02, z, 2.0 * iR2};
  T wds[3], wdb[3], wdt[3];
  for (int i = 0; i < 3; ++i) wds[i] = ws * ds[i], wdb[i] = wb * db[i], wdt[i] = wt * dt[i];
  // (w d_i) d_j, summed side + base, then + top: the order of Eigen's
  // ws * ds * ds^T + wb * db * db^T + wt * dt * dt^T, which this replaced.
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      N::hess(e, i, j) = ws * Hs[3 * j + i] + sharp * ((wds[i] * ds[j] + wdb[i] * db[j]) + wdt[i] * dt[j]);
}

/// The smooth polytope's face value c = a.y - b at y, as
/// a_z y_z + (a_y y_y + a_x y_x) - b, each product fused into its sum where
/// kFused. The face kernel (polytope_kernel.hpp) passes four faces at one
/// point, the lanes (newton_lanes_polytope.hpp) one face at W points.
template <class N, bool kFused>
[[gnu::always_inline]] inline typename N::T polytope_face_value(typename N::T ax, typename N::T ay, typename N::T az,
                                                                typename N::T b, typename N::T y0, typename N::T y1,
                                                                typename N::T y2) {
  return N::template mul_add<kFused>(az, y2, N::template mul_add<kFused>(ay, y1, ax * y0)) - b;
}

/// The running face sums that polytope_from_sums reads: s0 = sum w_i,
/// s1 = sum w_i d_i and (kHessian) s2 = sum w_i d_i d_i^T (xx, xy, xz, yy,
/// yz, zz; each product fused into its sum where kFused), d_i = a_i - a*,
/// w_i = e^(k (c_i - cmax)) by exp_nonpositive (fused where kFused). The
/// face kernel keeps one per vector of four faces (its lanes the faces
/// i mod 4), the lanes one per residue i mod 4 (their lanes the poses): in
/// both, each sum adds its faces in increasing i.
template <class N, bool kFused, bool kHessian>
struct PolytopeFaceSums {
  using T = typename N::T;
  T s0 = N::splat(0.0);
  T s1x = s0, s1y = s0, s1z = s0;                                // s1
  T sxx = s0, sxy = s0, sxz = s0, syy = s0, syz = s0, szz = s0;  // s2

  /// Adds the face of normal (ax, ay, az) and value c, at k = sharp / L,
  /// about the dominant normal a* = (sx, sy, sz) of value cmax.
  [[gnu::always_inline]] void add(T k, T c, T cmax, T ax, T ay, T az, T sx, T sy, T sz) {
    const T w = exp_nonpositive<N, kFused>(k * (c - cmax));
    const T dx = ax - sx, dy = ay - sy, dz = az - sz;
    const T wx = w * dx, wy = w * dy, wz = w * dz;
    s0 = s0 + w;
    s1x = s1x + wx;
    s1y = s1y + wy;
    s1z = s1z + wz;
    if constexpr (kHessian) {
      sxx = N::template mul_add<kFused>(wx, dx, sxx);
      sxy = N::template mul_add<kFused>(wx, dy, sxy);
      sxz = N::template mul_add<kFused>(wx, dz, sxz);
      syy = N::template mul_add<kFused>(wy, dy, syy);
      syz = N::template mul_add<kFused>(wy, dz, syz);
      szz = N::template mul_add<kFused>(wz, dz, szz);
    }
  }
};

/// The smooth polytope's phi, gradient and (kHessian) Hessian from its face
/// sums, which the face kernel (polytope_kernel.hpp, four faces a vector)
/// and the lanes (newton_lanes_polytope.hpp, one face for W poses) form in
/// the same order: s0 = sum w_i, s1 = sum w_i d_i, s2 = sum w_i d_i d_i^T
/// (xx, xy, xz, yy, yz, zz), d_i = a_i - a* about the dominant normal a*
/// (face value cmax), w_i = exp(sharp (c_i - cmax) / L):
///   phi = cmax / L + log(s0) / sharp,  grad = (a* + E[d]) / L,
///   hess = sharp / L^2 (E[d d^T] - E[d] E[d]^T)
/// (eq:smoothmax_grad, eq:smoothmax_hessian; small differences, no
/// cancelling O(1) terms when one face dominates at large sharpness).
template <class N, bool kHessian, class E>
[[gnu::always_inline]] inline void polytope_from_sums(typename N::T s0, const typename N::T (&s1)[3],
                                                      const typename N::T (&s2)[6], typename N::T cmax,
                                                      const typename N::T (&a)[3], double L, double sharp, E& e,
                                                      typename N::Mask& bad) {
  using T = typename N::T;
  const T inv = 1.0 / s0;
  const T d0 = s1[0] * inv, d1 = s1[1] * inv, d2 = s1[2] * inv;  // E[a] - a*
  N::phi(e) = cmax / L + log_ge1<N>(s0, bad) / sharp;
  N::grad(e, 0) = (a[0] + d0) / L;
  N::grad(e, 1) = (a[1] + d1) / L;
  N::grad(e, 2) = (a[2] + d2) / L;
  if constexpr (kHessian) {
    const double hk = sharp / (L * L);
    const T hxy = (s2[1] * inv - d0 * d1) * hk, hxz = (s2[2] * inv - d0 * d2) * hk;
    const T hyz = (s2[4] * inv - d1 * d2) * hk;
    N::hess(e, 0, 0) = (s2[0] * inv - d0 * d0) * hk;
    N::hess(e, 0, 1) = N::hess(e, 1, 0) = hxy;
    N::hess(e, 0, 2) = N::hess(e, 2, 0) = hxz;
    N::hess(e, 1, 1) = (s2[3] * inv - d1 * d1) * hk;
    N::hess(e, 1, 2) = N::hess(e, 2, 1) = hyz;
    N::hess(e, 2, 2) = (s2[5] * inv - d2 * d2) * hk;
  }
}

}  // namespace idcol::detail::formulas
