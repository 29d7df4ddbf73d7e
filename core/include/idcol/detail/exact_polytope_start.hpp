// The exact polytopes' contact, as a cold start for two smooth polytopes:
// the smallest uniform scaling alpha at which the exact polytopes (which hold
// the smooth bodies) touch, and a point where they do, by a dual simplex on
// the four-variable linear program of their half-spaces.
#pragma once

#include <algorithm>
#include <cmath>

#include "idcol/kkt.hpp"  // detail::Pair
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol::detail {

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
inline bool exact_polytope_contact(const SmoothPolytope& p1, const SmoothPolytope& p2, const Mat3& R, const Vec3& r_S, double& alpha,
                                   Vec3& x_1, int* pivots = nullptr, double* multiplier_ratio = nullptr) {
  using Vec4 = Eigen::Matrix<double, 4, 1>;
  if (!r_S.allFinite()) return false;
  const double rn = r_S.norm();
  // The faces in place: [a_x | a_y | a_z | b], n rows a column (m faces,
  // then padding).
  const double* F1 = p1.face_block();
  const double* F2 = p2.face_block();
  const int n1 = p1.face_block_rows(), n2 = p2.face_block_rows();
  const int m1 = p1.num_halfspaces();  // rows m1.. are body 2's
  const double size = p1.radii().outer + p2.radii().outer;

  // The artificial basis (K = -1..-4): rows (t_k, -B), t_k = (+-1, +-1, +-1)
  // / sqrt 3 with an even number of minus signs (sum t_k = 0, t_k . t_l =
  // -1/3). Its inverse in closed form: w_k = (3/4 t_k, -1 / (4B)).
  const double B = 2.0 * p1.radii().outer, s = 0.75 / std::sqrt(3.0);
  Vec4 w[4] = {Vec4(s, s, s, -0.25 / B), Vec4(s, -s, -s, -0.25 / B), Vec4(-s, s, -s, -0.25 / B), Vec4(-s, -s, s, -0.25 / B)};
  Vec4 y = Vec4::Constant(0.25 / B);  // multipliers, -G_K^-T e_alpha
  double h[4] = {0.0, 0.0, 0.0, 0.0};  // right-hand sides of the basis rows
  Vec4 z = Vec4::Zero();
  int it = 0;
  for (;; ++it) {
    // The most violated face of either body.
    const double a = z[3];
    double worst = kExactStartTol * (rn + a * size);
    int enter = -1;
    if (it > 0) most_violated(F1, n1, Vec3(z.head<3>()), a, 0, worst, enter);  // at z = 0 body 1's rows all read 0
    most_violated(F2, n2, Vec3(R.transpose() * (z.head<3>() - r_S)), a, m1, worst, enter);  // in body 2's frame
    if (enter < 0) break;  // primal feasible: optimal
    if (it == kExactStartMaxPivots) return false;
    // The entering row (g, he) in body 1's frame.
    Vec4 g;
    double he = 0.0;
    if (enter < m1) {
      g << F1[enter], F1[n1 + enter], F1[2 * n1 + enter], -F1[3 * n1 + enter];
    } else {
      const int j = enter - m1;
      const Vec3 n = R * Vec3(F2[j], F2[n2 + j], F2[2 * n2 + j]);
      g << n, -F2[3 * n2 + j];
      he = n.dot(r_S);
    }
    // Ratio test: g = sum rho_r g_r; the row whose multiplier y_r - theta
    // rho_r reaches 0 first leaves.
    Vec4 rho;
    int out = -1;
    double theta = 0.0;
    for (int r = 0; r < 4; ++r) {
      rho[r] = w[r].dot(g);
      if (rho[r] > 1e-13 && (out < 0 || y[r] < theta * rho[r])) out = r, theta = y[r] / rho[r];
    }
    if (out < 0) return false;  // no row can leave: the program would be infeasible, so rounding
    const Vec4 wo = w[out] / rho[out];
    for (int r = 0; r < 4; ++r)
      if (r != out) w[r] -= rho[r] * wo, y[r] -= theta * rho[r];
    w[out] = wo;
    y[out] = theta;
    h[out] = he;
    z = h[0] * w[0] + h[1] * w[1] + h[2] * w[2] + h[3] * w[3];
  }
  if (pivots) *pivots = it;
  if (multiplier_ratio) *multiplier_ratio = y.minCoeff() / y.maxCoeff();
  alpha = z[3];
  x_1 = z.head<3>();
  return alpha > 0.0 && std::isfinite(alpha) && x_1.allFinite();
}

}  // namespace idcol::detail
