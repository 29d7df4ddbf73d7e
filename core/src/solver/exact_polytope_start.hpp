// The exact polytopes' contact, as a cold start for two smooth polytopes:
// the smallest uniform scaling alpha at which the exact polytopes (which hold
// the smooth bodies) touch, and a point where they do, by a dual simplex on
// the four-variable linear program of their half-spaces.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "idcol/detail/fast_math.hpp"
#include "idcol/detail/formulas/polytope_ellipsoid.hpp"
#include "idcol/detail/formulas/polytope_simplex.hpp"
#include "idcol/detail/scalar_num.hpp"
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol::detail {

/// Two doubles as one SSE2 register (GCC/Clang vector extension): each lane
/// makes the scalar operation.
using Pair = double __attribute__((vector_size(16)));
inline Pair load_pair(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// Pivots after which exact_polytope_contact gives up (the paper's polytope
/// pair takes 4 to 8, 5.3 on average, over the sweep's poses; random pairs
/// in the test at most 9).
inline constexpr int kExactStartMaxPivots = 32;
/// A half-space counts as violated above this fraction of the problem's
/// length (|r_S| + alpha (R1 + R2)): 1e4 units in the last place, above the
/// rounding of the vertex, so that rounding cannot make the loop pivot on;
/// it moves alpha by about this fraction of the bodies' size over their
/// inner radius.
inline constexpr double kExactStartTol = 1e-12;
/// A basis multiplier below this fraction of the largest (multiplier_ratio
/// of exact_polytope_contact) marks an optimum that is not unique (faces,
/// or an edge and a face, in contact): the vertex found is one corner of
/// the contact set, a poor start for the smooth bodies (stress
/// box_face_to_face: 0 -> 23.8 Newton steps a solve), and the solver takes
/// the three ranked points instead.
inline constexpr double kExactStartUnique = 1e-9;
/// The most faces (both bodies') for which the solver takes the exact start:
/// its pivots scan every face, and two 1,000-face polytopes (stress
/// facets1000) cost 5.4% more instructions per solve from it than from the
/// three ranked points; the paper's pair has 16.
inline constexpr int kExactStartMaxFaces = 64;
/// The fraction of the first-order move to the smooth contact that the two
/// polytopes' start takes (exact_polytope_contact's soft1, soft2). Measured
/// on the paper's polytope pair, Newton steps per cold solve (mean / most)
/// for a fraction of 0, 0.15, 0.3, 0.4 and 1: 20,000 poses of the sweep
/// 4.84/12, 4.65/10, 4.49/11, 4.38/11, 3.24/15; 20,000 uniform random poses
/// 4.96/11, 4.79/10, 4.61/11, 4.49/12, 3.32/32. The whole move leaves a
/// tail (a start the first-order model puts on the wrong side of a rounded
/// edge), a third of it none.
inline constexpr double kExactStartPolytopeStep = 0.3;

/// ln x for a normal x > 0, to about 1e-9 absolute: enough for the first-
/// order moves of the starts below and the shrink that gates them, at about
/// a third of log_positive's instructions (under callgrind its four calls a
/// polytope pair's start cost 280). x = 2^e m with m in [sqrt(1/2), sqrt 2),
/// ln m = 2 atanh(t), t = (m - 1) / (m + 1), |t| <= 0.1716, by its series to
/// t^9 (truncation below 1e-9).
inline double log_start(double x) { return formulas::log_start<ScalarNum>(x); }

/// The face of [a_x | a_y | a_z | b] (n rows a column, a multiple of 4,
/// the rows after the faces padding with a = 0, b = +inf) that y (at
/// scaling a >= 0) violates most, if by more than worst: its violation
/// a_i . y - a b_i (a length, the normals being unit) to worst and its row
/// plus base to enter. Four rows at a time as two SSE2 pairs; a block is
/// searched row by row only when its largest violation beats worst. A
/// padding row gives -inf, or NaN at a = 0; the maxima below keep their
/// second operand unless the first is larger, and a block's first row is
/// a face, so a NaN never stands for the block.
inline void most_violated(const double* F, int n, const Vec3& y, double a, int base, double& worst_io, int& enter) {
  const Pair y0 = {y[0], y[0]}, y1 = {y[1], y[1]}, y2 = {y[2], y[2]}, pa = {a, a};
  const double *ax = F, *ay = F + n, *az = F + 2 * n, *b = F + 3 * n;
  double worst = worst_io;
  for (int i = 0; i < n; i += 4) {
    const Pair v01 = load_pair(ax + i) * y0 + load_pair(ay + i) * y1 + load_pair(az + i) * y2 - load_pair(b + i) * pa;
    const Pair v23 = load_pair(ax + i + 2) * y0 + load_pair(ay + i + 2) * y1 + load_pair(az + i + 2) * y2 - load_pair(b + i + 2) * pa;
    const Pair m = v23 > v01 ? v23 : v01;
    if (!((m[1] > m[0] ? m[1] : m[0]) > worst)) continue;
    const double v[4] = {v01[0], v01[1], v23[0], v23[1]};
    for (int k = 0; k < 4; ++k)
      if (v[k] > worst) worst = v[k], enter = base + i + k;
  }
  worst_io = worst;
}

/// The exact polytopes' contact on the surrogate problem's geometry
/// (PairSolver's P_: body 1 at the origin, body 2 at r_S = L (c1 + c2),
/// turned by R = R_12): the linear program in z = (x, alpha), x in body 1's
/// frame,
///   min alpha  s.t.  a1_i . x <= alpha b1_i                  (body 1's faces)
///                    (R a2_j) . (x - r_S) <= alpha b2_j      (body 2's faces),
/// whose value is the alpha* of the exact polytopes (a lower bound on the
/// smooth bodies' alpha*, as the smooth bodies lie inside them).
///
/// Why a dual simplex: the program has 4 variables and m1 + m2 rows (16 for
/// the paper's pair), the rows are the shapes' own face arrays (face_block,
/// read in place, body 2's in its own frame), and a basis that is dual
/// feasible comes for free, so no phase 1 is needed: four artificial rows
/// t_k . x <= alpha B, t_k the face normals of a regular tetrahedron and
/// B = 2 R1 (so the tetrahedron of inradius 2 R1 holds P1 and the rows are
/// redundant), active at z = 0 with multipliers 1 / (4B). Each pivot brings
/// in the most violated face (a length, the normals being unit) and drops
/// the basis row the ratio test names; alpha only grows. The artificial rows
/// cannot stay in an optimal basis with alpha > 0 (P1 lies strictly inside
/// the tetrahedron), so they are never scanned. Measured under callgrind on
/// the paper's polytope against itself (every tenth of the sweep's 20,000
/// poses), against two algorithms on the Minkowski difference of the vertex
/// lists tried first: a GJK ray cast took 6.8 support calls and 7,360
/// instructions a call, Minkowski portal refinement 8.1 support calls and
/// 4,950 instructions, this 5.3 pivots and 2,480 instructions (a support
/// call scans both vertex lists, a pivot both face lists, about as long;
/// the dual simplex needs fewer of them and no nearest-point subproblem).
///
/// The basis inverse W (G_K W = I, G_K the basis rows) is kept by the
/// product form; z = W h_K is formed afresh after each pivot.
///
/// On success alpha > 0 and x_1 is a vertex of the program: in alpha P1 and
/// in r_S + alpha R P2 to kExactStartTol of the problem's length. False if
/// r_S is zero or not finite, or on numerical trouble (no row to leave, or
/// kExactStartMaxPivots pivots); pivots, if given, receives the count.
///
/// soft1, soft2 > 0 (each polytope's L / beta, its smoothing length, or 0
/// for none) move the vertex towards the smooth bodies' contact: each basis
/// row's face is pulled in by soft log(y_r / S) (y the multipliers, S the
/// sum of its body's), where LogSumExp weights proportional to y put the
/// smooth gradient along the contact normal on the smooth boundary, as
/// exact_polytope_ellipsoid_contact's soft does. Only the alpha column of
/// the basis changes, a rank-one change: the moved vertex is z + d z_alpha
/// / (1 - d_alpha), d = W delta (Sherman-Morrison), and the start goes
/// kExactStartPolytopeStep of the way there.
/// The simplex's constants for the pair (formulas::SimplexConsts): the
/// loop's and the lanes' (the batch reads them once per pair).
inline formulas::SimplexConsts simplex_consts(const SmoothPolytope& p1, const SmoothPolytope& p2) {
  return {p1.radii().outer, p1.radii().outer + p2.radii().outer, p1.num_halfspaces(), kExactStartTol, kExactStartMaxPivots};
}

inline bool exact_polytope_contact(const SmoothPolytope& p1, const SmoothPolytope& p2, const Mat3& R, const Vec3& r_S, double& alpha,
                                   Vec3& x_1, int* pivots = nullptr, double* multiplier_ratio = nullptr, double soft1 = 0.0,
                                   double soft2 = 0.0) {
  // The faces in place: [a_x | a_y | a_z | b], n rows a column (m faces,
  // then padding).
  const double* F1 = p1.face_block();
  const double* F2 = p2.face_block();
  const int n1 = p1.face_block_rows(), n2 = p2.face_block_rows();
  const int m1 = p1.num_halfspaces();  // rows m1.. are body 2's
  const formulas::SimplexConsts k = simplex_consts(p1, p2);
  double Rm[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Rm[i][j] = R(i, j);
  const double rS[3] = {r_S[0], r_S[1], r_S[2]};
  // The most violated face of either body, four at a time (most_violated).
  auto scan = [&](int it, const double (&x)[3], double a, const double (&u)[3], double worst,
                  formulas::SimplexEntering<ScalarNum>& e) {
    int enter = -1;
    if (it > 0) most_violated(F1, n1, Vec3(x[0], x[1], x[2]), a, 0, worst, enter);  // at z = 0 body 1's rows all read 0
    most_violated(F2, n2, Vec3(u[0], u[1], u[2]), a, m1, worst, enter);               // in body 2's frame
    if (enter < 0) return false;
    e.row = enter;
    e.body2 = enter >= m1;
    const double* F = e.body2 ? F2 : F1;
    const int n = e.body2 ? n2 : n1, j = e.body2 ? enter - m1 : enter;
    e.ax = F[j], e.ay = F[n + j], e.az = F[2 * n + j], e.b = F[3 * n + j];
    return true;
  };
  formulas::SimplexState<ScalarNum> s;
  int it = 0;
  if (formulas::polytope_simplex<ScalarNum>(Rm, rS, k, scan, s, it)) return false;
  if (pivots) *pivots = it;
  const double ratio = formulas::simplex_finish<ScalarNum>(s, m1, soft1, soft2, kExactStartPolytopeStep);
  if (multiplier_ratio) *multiplier_ratio = ratio;
  alpha = s.alpha();
  x_1 = Vec3(s.z[0][0], s.z[0][1], s.z[1][0]);
  return alpha > 0.0 && std::isfinite(alpha) && x_1.allFinite();
}

/// Active-set steps after which exact_polytope_ellipsoid_contact gives up
/// (the paper's polytope against its ellipsoid takes 1 to 4 over the
/// sweep's poses; random pairs in the test at most a dozen).
inline constexpr int kExactEllipsoidMaxSteps = 32;

/// The exact polytope's contact with an ellipsoid, in the polytope's frame:
/// with the polytope P = {u : a_i . u <= b_i} (unit a_i) at the origin and
/// the ellipsoid {r + C y : |y| <= 1} (C = R diag(semi-axes)),
///   min alpha  s.t.  a_i . (r + C y) <= alpha b_i  for every face,  |y| <= alpha,
/// whose value is the alpha* of the exact polytope and the ellipsoid (a
/// lower bound on the smooth polytope's alpha*, which lies inside P), and
/// v = r + C y the point where they touch, on both boundaries.
///
/// Why this method: written with g_i = C^T a_i and h_i = a_i . r, the faces
/// are g_i . y + h_i <= alpha b_i and the ellipsoid the unit ball; the
/// optimum touches the ball (|y| = alpha) with a face, an edge or a vertex
/// of P, that is 1 to 3 faces U active. For an active set U, y = alpha P -
/// Q with P = G^T (G G^T)^-1 b_U and Q = G^T (G G^T)^-1 h_U (G the rows
/// g_i, i in U: the point of the face, edge or vertex nearest the ball's
/// centre, or the vertex itself), and |y| = alpha is a quadratic in alpha,
/// whose least positive root the scaled bodies reach first. KKT holds
/// there (the multipliers of U are -w, w = (G G^T)^-1 (alpha b_U - h_U),
/// times a positive factor) when w <= 0. A dual active-set method (in the
/// manner of Goldfarb and Idnani's for quadratic programs) starts from
/// U = {} (alpha = 0, y = 0), brings in the face most violated (a length,
/// from the same scan as the polytopes' simplex), and solves the problem
/// of U and that face exactly: its optimum has the new face active, so it
/// is the first of the at most 7 active sets (the new face with 0, 1 or 2
/// of U) that meets KKT and the faces of U left out. alpha only grows, so
/// no set comes back, and each step costs one scan of the faces and a few
/// 3x3 products: no Newton iterations on a curved constraint, no vertex
/// lists. The ellipsoid being strictly convex, the optimum is unique.
///
/// On success alpha > 0 and v is the contact point, in P scaled by alpha
/// to kExactStartTol of the problem's length. False if r is zero or not
/// finite, or on numerical trouble (no active set meets KKT, or
/// kExactEllipsoidMaxSteps steps); steps, if given, receives the count.
/// soft > 0 (the polytope's L / beta, its smoothing length) asks for the
/// smooth polytope's contact to first order instead: where an edge or a
/// vertex touches, each active face is pulled in by soft log(mu_i / sum mu)
/// (mu the multipliers), where LogSumExp weights proportional to mu put the
/// smooth gradient along the contact normal on the smooth boundary, and the
/// contact is solved again. An edge or a vertex is where the smooth polytope
/// is rounded most; on 2,000 poses of the paper's sweep (Poly-Ellip) the
/// median |alpha - alpha*| / alpha* of the start falls from 3.2% to 0.054%
/// where it applies, and Newton steps per cold solve from 3.87 to 3.44.
/// (The two polytopes' vertex takes a fraction of the same move only,
/// kExactStartPolytopeStep: the whole of it left a tail there.)
/// Written once for the loop and the cold lanes (formulas::ball_contact,
/// formulas/polytope_ellipsoid.hpp); here on one pose, the faces searched
/// four at a time. ball_consts: its constants, the loop's and the lanes'.
inline formulas::BallConsts ball_consts(const SmoothPolytope& p, double soft) {
  return {p.radii().outer, kExactStartTol, kExactEllipsoidMaxSteps, soft};
}

inline bool exact_polytope_ellipsoid_contact(const SmoothPolytope& p, const double (&C)[3][3], const double (&r)[3],
                                             double& alpha, double (&v)[3], int* steps = nullptr, double soft = 0.0) {
  const double* F = p.face_block();
  const int n = p.face_block_rows();
  // The most violated face, four at a time (most_violated).
  auto scan = [&](const double (&y)[3], double a, double worst, formulas::SimplexEntering<ScalarNum>& e) {
    int enter = -1;
    most_violated(F, n, Vec3(y[0], y[1], y[2]), a, 0, worst, enter);
    if (enter < 0) return false;
    e.row = enter;
    e.ax = F[enter], e.ay = F[n + enter], e.az = F[2 * n + enter], e.b = F[3 * n + enter];
    return true;
  };
  formulas::BallState<ScalarNum> s;
  int it = 0;
  const bool ok = formulas::ball_contact<ScalarNum>(C, r, ball_consts(p, soft), scan, s, it);
  if (steps) *steps = it;
  alpha = s.a;
  for (int i = 0; i < 3; ++i) v[i] = s.v[i];
  return ok;
}

/// The same with C and r as Eigen's.
inline bool exact_polytope_ellipsoid_contact(const SmoothPolytope& p, const Mat3& C, const Vec3& r, double& alpha, Vec3& v,
                                             int* steps = nullptr, double soft = 0.0) {
  double Cm[3][3], r3[3] = {r[0], r[1], r[2]}, v3[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Cm[i][j] = C(i, j);
  const bool ok = exact_polytope_ellipsoid_contact(p, Cm, r3, alpha, v3, steps, soft);
  v = Vec3(v3[0], v3[1], v3[2]);
  return ok;
}

/// The semi-axes of a body that is an exact ellipsoid at the given
/// sharpness (a sphere; a superellipsoid at n = 1). False for every other
/// body.
template <class S>
inline bool ellipsoid_axes(const S& s, double sharp, Vec3& ax) {
  if constexpr (std::is_same_v<S, Sphere>) {
    (void)sharp;
    ax.setConstant(s.R());
    return true;
  } else if constexpr (std::is_same_v<S, Superellipsoid>) {
    if (sharp != 1.0) return false;
    ax = Vec3(s.a(), s.b(), s.c());
    return true;
  } else {
    (void)s, (void)sharp, (void)ax;
    return false;
  }
}

/// The most relative shrink L log(m) / (beta b_min) of a smooth polytope
/// (the smooth body holds the exact one shrunk by it) for which exact_start
/// moves the polytope's contact with an ellipsoid to the smooth contact
/// (exact_polytope_ellipsoid_contact's soft). On smoothing_polytope's grid
/// (the paper's polytope against a sphere) the correction raised the most
/// Newton steps of a cold solve at beta = 5 (shrink 0.72) from 5 to 13 and
/// at beta = 10 (0.36) from 5 to 8, and at beta = 20 (0.18) and above
/// changed no maximum: first order is not enough for rounder bodies.
inline constexpr double kExactStartMaxShrink = 0.2;

/// The least relative shrink of either polytope for which exact_start moves
/// two polytopes' vertex (exact_polytope_contact's soft1, soft2): a body
/// much sharper than that (beta above about 40 log m at b_min = L) is so
/// curved at its edges that the move puts the start beyond its rounding.
/// On 30,000 random poses of harness random_bodies' normal range in both
/// orders, solves of more than 40 Newton steps, without the move / with it
/// for any shrink / with it where both shrinks are at least this: box-polytope
/// 38 / 61 / 38, box-box 9 / 25 / 9, polytope-box 39 / 58 / 39; the paper's
/// pair (shrink 0.18) keeps it.
inline constexpr double kExactStartMinShrink = 0.05;

/// The polytope's relative shrink L log(m) / (beta b_min) at sharpness beta.
inline double relative_shrink(const SmoothPolytope& p, double sharp) {
  return log_start(static_cast<double>(p.num_halfspaces())) / (sharp * p.phi_scale());
}

/// The polytope's smoothing length L / beta at sharpness beta, or 0 (no
/// correction) where its relative shrink exceeds kExactStartMaxShrink or is
/// below min_shrink.
inline double smoothing_length(const SmoothPolytope& p, double sharp, double min_shrink = 0.0) {
  const double h = relative_shrink(p, sharp);
  return h >= min_shrink && h <= kExactStartMaxShrink ? p.L() / sharp : 0.0;
}

/// The two polytopes' moves (exact_polytope_contact's soft1, soft2): each
/// one's smoothing length where both have one (both bodies move, or
/// neither). exact_start's, and the batch's for its lanes.
inline void pair_smoothing_lengths(const SmoothPolytope& p1, const SmoothPolytope& p2, double sharp1, double sharp2,
                                   double& soft1, double& soft2) {
  const double l1 = smoothing_length(p1, sharp1, kExactStartMinShrink), l2 = smoothing_length(p2, sharp2, kExactStartMinShrink);
  const bool move = l1 > 0.0 && l2 > 0.0;
  soft1 = move ? l1 : 0.0;
  soft2 = move ? l2 : 0.0;
}

/// Whether exact_start can give the pair (S1, S2) a start at all: two
/// polytopes, or a polytope and a body that may be an ellipsoid.
template <class S1, class S2>
inline constexpr bool kHasExactStart =
    (std::is_same_v<S1, SmoothPolytope> && std::is_same_v<S2, SmoothPolytope>) ||
    (std::is_same_v<S1, SmoothPolytope> && (std::is_same_v<S2, Sphere> || std::is_same_v<S2, Superellipsoid>)) ||
    (std::is_same_v<S2, SmoothPolytope> && (std::is_same_v<S1, Sphere> || std::is_same_v<S1, Superellipsoid>));

/// Whether exact_start gives (S1, S2) at these sharpnesses a start to
/// look for: two polytopes of at most kExactStartMaxFaces faces together,
/// or a polytope and a body that is an ellipsoid at its sharpness. The
/// batch reads it once per pair (NewtonColdConsts::exact_start).
template <class S1, class S2>
inline bool exact_start_applies(const S1& s1, const S2& s2, double sharp1, double sharp2) {
  Vec3 ax;
  if constexpr (std::is_same_v<S1, SmoothPolytope> && std::is_same_v<S2, SmoothPolytope>) {
    (void)sharp1, (void)sharp2;
    return s1.num_halfspaces() + s2.num_halfspaces() <= kExactStartMaxFaces;
  } else if constexpr (std::is_same_v<S1, SmoothPolytope> && kHasExactStart<S1, S2>) {
    (void)s1, (void)sharp1;
    return ellipsoid_axes(s2, sharp2, ax);
  } else if constexpr (kHasExactStart<S1, S2>) {
    (void)s2, (void)sharp2;
    return ellipsoid_axes(s1, sharp1, ax);
  } else {
    (void)s1, (void)s2, (void)sharp1, (void)sharp2, (void)ax;
    return false;
  }
}

/// PairSolver::support_guess's start from the exact bodies, on the
/// surrogate problem's geometry (body 1 at the origin, body 2 at r_S turned
/// by R, each at its sharpness): alpha and the contact x in body 1's frame.
///   - Two polytopes of at most kExactStartMaxFaces faces together: the
///     polytopes' contact (exact_polytope_contact), where it is unique.
///   - A polytope and an ellipsoid (either order): their contact
///     (exact_polytope_ellipsoid_contact, in the polytope's frame), always
///     unique.
/// False for every other pair, and where the start is not found. The
/// batch's cold lanes run the same templates on W poses (formulas::
/// polytope_simplex, formulas::ball_contact), so that they start from the
/// same bits.
template <class S1, class S2>
inline bool exact_start(const S1& s1, const S2& s2, double sharp1, double sharp2, const Mat3& R, const Vec3& r_S,
                        double& alpha, Vec3& x) {
  if constexpr (std::is_same_v<S1, SmoothPolytope> && std::is_same_v<S2, SmoothPolytope>) {
    if (!exact_start_applies(s1, s2, sharp1, sharp2)) return false;
    double soft1, soft2, unique = 0.0;
    pair_smoothing_lengths(s1, s2, sharp1, sharp2, soft1, soft2);
    return exact_polytope_contact(s1, s2, R, r_S, alpha, x, nullptr, &unique, soft1, soft2) && unique > kExactStartUnique;
  } else if constexpr (kHasExactStart<S1, S2>) {
    // The ellipsoid in the polytope's frame (formulas::ball_frame), and its
    // contact back in body 1's.
    constexpr bool first = std::is_same_v<S1, SmoothPolytope>;
    const SmoothPolytope* p;
    Vec3 ax;
    if constexpr (first)
      p = &s1;
    else
      p = &s2;
    if (!(first ? ellipsoid_axes(s2, sharp2, ax) : ellipsoid_axes(s1, sharp1, ax))) return false;
    double Rm[3][3], rS[3] = {r_S[0], r_S[1], r_S[2]}, C[3][3], r[3], v[3], xa[3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Rm[i][j] = R(i, j);
    const double a3[3] = {ax[0], ax[1], ax[2]};
    formulas::ball_frame<ScalarNum>(Rm, rS, a3, first, C, r);
    if (!exact_polytope_ellipsoid_contact(*p, C, r, alpha, v, nullptr, smoothing_length(*p, first ? sharp1 : sharp2)))
      return false;
    formulas::ball_point<ScalarNum>(Rm, rS, v, first, xa);
    x = Vec3(xa[0], xa[1], xa[2]);
    return x.allFinite();
  } else {
    (void)s1, (void)s2, (void)sharp1, (void)sharp2, (void)R, (void)r_S, (void)alpha, (void)x;
    return false;
  }
}

}  // namespace idcol::detail
