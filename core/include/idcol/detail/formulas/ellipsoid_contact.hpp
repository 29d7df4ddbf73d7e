// alpha* and the witness point of two ellipsoids in closed form up to one
// scalar (Perram and Wertheim's contact function; solver_impl.hpp,
// ellipsoid_contact_from, says what), written once over a number layer N
// (elementary.hpp) for the scalar solver's first guess and the batch lanes'
// ellipsoid kernel (batch_simd_kernel.hpp), so that a lane's guess is the
// loop's, bit for bit.
//
// M1(i, j) and M2(i, j) are the two bodies' matrices in body 1's frame
// (symmetric; only the upper triangle of (1 - l) M1 + l M2 is read), r the
// frame offset. Every 3x3 product adds in Eigen's order (kkt.hpp, mat_vec).
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/kkt.hpp"

namespace idcol::detail::formulas {

/// a . (A b).
template <class N, class A>
[[gnu::always_inline]] inline typename N::T dot_mat(const typename N::T (&a)[3], const A& M, const typename N::T (&b)[3]) {
  typename N::T Mb[3];
  mat_vec<N>(M, b, Mb);
  return dot3<N>(a, Mb);
}

/// The cold start of the iteration, n1 / (n1 + n2) with n_i = sqrt(r^T M_i
/// r): exact for two spheres.
template <class N, class A, class B>
[[gnu::always_inline]] inline typename N::T ellipsoid_contact_start(const A& M1, const B& M2, const typename N::T (&r)[3]) {
  const typename N::T n1 = N::sqrt(dot_mat<N>(r, M1, r)), n2 = N::sqrt(dot_mat<N>(r, M2, r));
  return n1 / (n1 + n2);
}

/// The contact from the start l in (0, 1): Newton steps on F'(l) kept in a
/// bracket, until a step moves l by at most 1e-9 of min(l, 1 - l); then
/// alpha = sqrt(F(l)) and x = (1 - l) M1 C(l)^-1 r. Where it fails (a C(l)
/// that is not positive definite, a derivative or F that is not finite, 40
/// steps without settling, an x that is not finite) the scalar layer
/// answers false, the lanes flag the lane in bad.
template <class N, class A, class B>
[[gnu::always_inline]] inline bool ellipsoid_contact_from(const A& M1, const B& M2, const typename N::T (&r)[3],
                                                          typename N::T l, typename N::T& alpha, typename N::T (&x)[3],
                                                          typename N::Mask& bad) {
  using T = typename N::T;
  using Mask = typename N::Mask;
  T D[3][3];  // M2 - M1, column-major (D[j][i] = D(i, j)), as Ci below
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) D[j][i] = M2(i, j) - M1(i, j);
  auto Dm = [&](int i, int j) { return D[j][i]; };
  // C(l)^-1 of the symmetric positive definite C(l) from its adjugate, six
  // cofactors by symmetry (a guess needs no pivoting; a 3x3 LLT costs four
  // times as much, and Eigen's general 3x3 inverse, nine cofactors, 6% more
  // instructions per cold Ellip-Ellip solve under callgrind). Answers where
  // det C is not positive and finite.
  T Ci[3][3];  // column-major: Ci[j][i] = C^-1(i, j), so that rows 0-1 of a column are adjacent
  auto Cm = [&](int i, int j) { return Ci[j][i]; };
  auto invert = [&](T lv) {
    const T a = 1.0 - lv;
    // The upper triangle, columns 1 and 2 rows 0-1 as pairs.
    const auto p1 = a * N::pair(M1(0, 1), M1(1, 1)) + lv * N::pair(M2(0, 1), M2(1, 1));
    const auto p2 = a * N::pair(M1(0, 2), M1(1, 2)) + lv * N::pair(M2(0, 2), M2(1, 2));
    const T c00 = a * M1(0, 0) + lv * M2(0, 0), c22 = a * M1(2, 2) + lv * M2(2, 2);
    const T c01 = N::lo(p1), c11 = N::hi(p1), c02 = N::lo(p2), c12 = N::hi(p2);
    const T a00 = c11 * c22 - c12 * c12, a01 = c02 * c12 - c01 * c22;
    const T a02 = c01 * c12 - c02 * c11, a11 = c00 * c22 - c02 * c02;
    const T a12 = c01 * c02 - c00 * c12, a22 = c00 * c11 - c01 * c01;
    const T det = c00 * a00 + c01 * a01 + c02 * a02;
    const T id = 1.0 / det;
    Ci[0][0] = a00 * id, Ci[0][1] = Ci[1][0] = a01 * id, Ci[0][2] = Ci[2][0] = a02 * id;
    Ci[1][1] = a11 * id, Ci[1][2] = Ci[2][1] = a12 * id, Ci[2][2] = a22 * id;
    return N::not_((det > 0.0) & N::finite(det));
  };
  T lo = N::splat(0.0), hi = N::splat(1.0);
  Mask active = N::not_(bad);  // lanes still iterating
  Mask settled_all = N::mask(false);
  for (int it = 0; it < 40 && N::any(active); ++it) {
    const Mask singular = invert(l);
    T u[3], Du[3];
    mat_vec<N>(Cm, r, u);
    mat_vec<N>(Dm, u, Du);
    const T ru = dot3<N>(r, u);
    const T uDu = dot3<N>(u, Du);
    const T g = (1.0 - 2.0 * l) * ru - l * (1.0 - l) * uDu;                                              // F'(l)
    const T h = -2.0 * ru - 2.0 * (1.0 - 2.0 * l) * uDu + 2.0 * l * (1.0 - l) * dot_mat<N>(Du, Cm, Du);  // F''(l)
    if (N::leaves(active & (singular | N::not_(N::finite(g) & N::finite(h))), bad)) return false;
    active = active & N::not_(bad);
    const Mask up = g > 0.0;
    lo = N::sel(active & up, l, lo);
    hi = N::sel(active & N::not_(up), l, hi);
    const T mid = 0.5 * (lo + hi);
    T ln = N::lazy(h < 0.0, [&] { return T(l - g / h); }, [&] { return mid; });
    // Newton's step is quadratic here: one under 1e-9 leaves l exact to
    // rounding after it, and the KKT iteration confirms the rest. Such a
    // step is taken even outside the bracket: near the root g is rounding
    // noise, and its sign can close the bracket on the wrong side of the
    // root. Bisecting there moved l by up to half the bracket (about 1e-9)
    // and left 7% of the paper sweep's cold ellipsoid contacts off the
    // surfaces by 2e-10 to 9e-10 relative, above the tolerance, so that a
    // Newton step of the full solver had to follow.
    const T om0 = 1.0 - ln;
    const Mask small = (h < 0.0) & (N::abs(ln - l) <= 1e-9 * N::sel(om0 < ln, om0, ln));
    ln = N::sel(small | ((ln > lo) & (ln < hi)), ln, mid);
    const T om = 1.0 - ln;
    const Mask settled = N::abs(ln - l) <= 1e-9 * N::sel(om < ln, om, ln);  // std::min(ln, 1 - ln)
    l = N::sel(active, ln, l);
    settled_all = settled_all | (active & settled);
    active = active & N::not_(settled);
  }
  if (N::leaves(N::not_(settled_all), bad)) return false;  // 40 steps (or flagged on the way)
  if (N::leaves(invert(l), bad)) return false;
  T u[3];
  mat_vec<N>(Cm, r, u);
  const T F = l * (1.0 - l) * dot3<N>(r, u);
  if (N::leaves(N::not_((F > 0.0) & N::finite(F)), bad)) return false;
  alpha = N::sqrt(F);
  // x = (1 - l) (M1 u), which Eigen forms as ((1 - l) M1) u.
  const T om = 1.0 - l;
  mat_vec<N>([&](int i, int j) { return T(om * M1(i, j)); }, u, x);
  return !N::leaves(N::not_(N::finite(x[0]) & N::finite(x[1]) & N::finite(x[2])), bad);
}

}  // namespace idcol::detail::formulas
