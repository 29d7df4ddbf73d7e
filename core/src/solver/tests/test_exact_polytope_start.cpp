// exact_polytope_contact (src/solver/exact_polytope_start.hpp) against an oracle
// that shares no code with it: the linear program
//   min alpha  s.t.  a1_i . x <= alpha b1_i,  (R a2_j) . (x - r_S) <= alpha b2_j
// over the exact polytopes' half-spaces, solved by trying every 4-subset of
// its constraints as the active set (Gaussian elimination written here) and
// keeping the feasible vertex of least alpha. The function under test works
// on the vertex lists through a ray cast on the Minkowski difference; this
// works on the half-spaces through linear algebra.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/QR>

#include "src/solver/exact_polytope_start.hpp"
#include "idcol/shapes.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"
#include "examples/paper_shapes.hpp"

using namespace idcol;

namespace {

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// One constraint row g . (x, alpha) <= h, scaled to |g| = 1.
struct Row {
  double g[4];
  double h;
};

std::vector<Row> lp_rows(const SmoothPolytope& p1, const SmoothPolytope& p2, const Mat3& R, const Vec3& rS) {
  std::vector<Row> rows;
  auto push = [&](const Vec3& a, double b, double h) {
    const double n = std::sqrt(a.squaredNorm() + b * b);
    rows.push_back({{a.x() / n, a.y() / n, a.z() / n, -b / n}, h / n});
  };
  for (int i = 0; i < p1.num_halfspaces(); ++i) push(p1.normal(i), p1.offset(i), 0.0);
  for (int j = 0; j < p2.num_halfspaces(); ++j) {
    const Vec3 a = R * p2.normal(j);
    push(a, p2.offset(j), a.dot(rS));
  }
  return rows;
}

/// Solves the 4x4 system of rows i[0..3] (as equalities) by Gaussian
/// elimination with partial pivoting; false when a pivot is below 1e-10
/// (the rows have unit norm, so that is near-dependence).
bool solve4(const std::vector<Row>& rows, const int* i, double* z) {
  double M[4][5];
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) M[r][c] = rows[i[r]].g[c];
    M[r][4] = rows[i[r]].h;
  }
  for (int c = 0; c < 4; ++c) {
    int piv = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::abs(M[r][c]) > std::abs(M[piv][c])) piv = r;
    if (std::abs(M[piv][c]) < 1e-10) return false;
    for (int k = 0; k < 5; ++k) std::swap(M[c][k], M[piv][k]);
    for (int r = c + 1; r < 4; ++r) {
      const double f = M[r][c] / M[c][c];
      for (int k = c; k < 5; ++k) M[r][k] -= f * M[c][k];
    }
  }
  for (int c = 3; c >= 0; --c) {
    double s = M[c][4];
    for (int k = c + 1; k < 4; ++k) s -= M[c][k] * z[k];
    z[c] = s / M[c][c];
  }
  return true;
}

/// The oracle: alpha* and a vertex x of the LP, by brute force. False if no
/// 4-subset gives a feasible vertex.
bool brute_force_contact(const SmoothPolytope& p1, const SmoothPolytope& p2, const Mat3& R, const Vec3& rS, double& alpha, Vec3& x) {
  const std::vector<Row> rows = lp_rows(p1, p2, R, rS);
  const int m = static_cast<int>(rows.size());
  alpha = INFINITY;
  for (int a = 0; a < m; ++a)
    for (int b = a + 1; b < m; ++b)
      for (int c = b + 1; c < m; ++c)
        for (int d = c + 1; d < m; ++d) {
          const int idx[4] = {a, b, c, d};
          double z[4];
          if (!solve4(rows, idx, z) || !(z[3] > 0.0) || !(z[3] < alpha)) continue;
          // Feasible to 1e-11 of the problem's lengths (the rows' residuals are lengths).
          const double tol = 1e-11 * (std::sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]) + rS.norm() + z[3]);
          bool ok = true;
          for (int i = 0; i < m && ok; ++i)
            ok = rows[i].g[0] * z[0] + rows[i].g[1] * z[1] + rows[i].g[2] * z[2] + rows[i].g[3] * z[3] <= rows[i].h + tol;
          if (ok) alpha = z[3], x = Vec3(z[0], z[1], z[2]);
        }
  return std::isfinite(alpha);
}

/// The largest violation of x in alpha P1 and of x in r_S + alpha R P2,
/// relative to alpha times each polytope's outer radius.
double infeasibility(const SmoothPolytope& p1, const SmoothPolytope& p2, const Mat3& R, const Vec3& rS, double alpha, const Vec3& x) {
  double worst = 0.0;
  for (int i = 0; i < p1.num_halfspaces(); ++i)
    worst = std::max(worst, (p1.normal(i).dot(x) - alpha * p1.offset(i)) / (alpha * p1.radii().outer));
  const Vec3 y2 = R.transpose() * (x - rS);
  for (int j = 0; j < p2.num_halfspaces(); ++j)
    worst = std::max(worst, (p2.normal(j).dot(y2) - alpha * p2.offset(j)) / (alpha * p2.radii().outer));
  return worst;
}

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q.toRotationMatrix();
}

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

/// A random polytope: the hull of 4 to 8 Gaussian points (stretched along
/// random axes, up to 4:1), a random box, a random tetrahedron, or the
/// paper's polytope, each moved so that its vertex centroid is its origin.
SmoothPolytope random_polytope(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> g;
  const int kind = static_cast<int>(4.0 * U(rng));
  if (kind == 0) return test::paper_poly();
  if (kind == 1) return test::box(0.2 + U(rng), 0.2 + U(rng), 0.2 + U(rng), 20.0);
  for (;;) {
    const int n = kind == 2 ? 4 : 5 + static_cast<int>(4.0 * U(rng));
    const Vec3 stretch(0.25 + U(rng), 0.25 + U(rng), 0.25 + U(rng));
    const Mat3 Q = random_rotation(rng);
    std::vector<Vec3> V(n);
    Vec3 mean = Vec3::Zero();
    for (Vec3& v : V) mean += (v = Q * Vec3(g(rng), g(rng), g(rng)).cwiseProduct(stretch)) / n;
    for (Vec3& v : V) v -= mean;
    try {
      return SmoothPolytope::from_vertices(V, 20.0);
    } catch (const std::invalid_argument&) {
      // a flat or needle-like draw: draw again
    }
  }
}

struct Tally {
  int cases = 0, worst_iterations = 0;
  long iterations = 0;
  double worst_alpha = 0.0, worst_x = 0.0;
};

void check_case(const SmoothPolytope& p1, const SmoothPolytope& p2, const Mat3& R, const Vec3& rS, Tally& T) {
  double alpha_ref = 0.0, alpha = 0.0;
  Vec3 x_ref, x;
  ASSERT_TRUE(brute_force_contact(p1, p2, R, rS, alpha_ref, x_ref));
  int its = 0;
  ASSERT_TRUE(detail::exact_polytope_contact(p1, p2, R, rS, alpha, x, &its))
      << "R = \n" << R << "\nr_S = " << rS.transpose() << "\nalpha_ref = " << alpha_ref;
  const double ea = std::abs(alpha - alpha_ref) / alpha_ref, ex = infeasibility(p1, p2, R, rS, alpha, x);
  EXPECT_LE(ea, 1e-9) << "alpha " << alpha << " oracle " << alpha_ref << " r_S = " << rS.transpose() << "\nR =\n" << R;
  EXPECT_LE(ex, 1e-9) << "x = " << x.transpose() << " alpha " << alpha << " r_S = " << rS.transpose() << "\nR =\n" << R;
  ++T.cases;
  T.iterations += its;
  T.worst_iterations = std::max(T.worst_iterations, its);
  T.worst_alpha = std::max(T.worst_alpha, ea);
  T.worst_x = std::max(T.worst_x, ex);
}

void report(const char* what, const Tally& T) {
  std::printf("%s: %d cases, pivots mean %.2f max %d, worst |alpha - oracle| / oracle %.2e, worst infeasibility %.2e\n", what,
              T.cases, static_cast<double>(T.iterations) / std::max(1, T.cases), T.worst_iterations, T.worst_alpha, T.worst_x);
}

TEST(ExactPolytopeStart, RandomPairsAgreeWithBruteForceLp) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Tally T;
  for (int k = 0; k < 3000 && !HasFatalFailure(); ++k) {
    const SmoothPolytope p1 = random_polytope(rng), p2 = random_polytope(rng);
    const Mat3 R = random_rotation(rng);
    // |r_S| from 1e-6 to 1e6 of the bodies' size, log-uniform, on one case in
    // three; else across the paper sweep's range (a tenth of the inner
    // radius to twice the outer one), where the bodies overlap or not.
    const double size = p1.radii().outer + p2.radii().outer;
    const double r = k % 3 == 0 ? size * std::pow(10.0, -6.0 + 12.0 * U(rng))
                                : (0.1 * std::min(p1.radii().inner, p2.radii().inner) + 2.0 * size * U(rng));
    check_case(p1, p2, R, r * random_unit(rng), T);
  }
  report("random pairs", T);
}

/// Parallel and touching faces, edges and vertices: boxes, the paper's
/// polytope and a tetrahedron turned by multiples of 90 degrees (or not at
/// all), r_S along axes, face diagonals and body diagonals, so that M's
/// facets are hit at their centres, edges and corners, and the contact is a
/// whole face (x not unique).
TEST(ExactPolytopeStart, AlignedDegenerateContactsAgreeWithBruteForceLp) {
  const std::vector<SmoothPolytope> bodies = {test::box(0.5, 0.5, 0.5, 20.0), test::box(1.0, 0.25, 0.5, 20.0), test::paper_poly(),
                                              SmoothPolytope::from_vertices({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, 20.0)};
  std::vector<Mat3> turns = {Mat3::Identity()};
  for (int axis = 0; axis < 3; ++axis)
    for (double a : {0.5 * M_PI, M_PI}) turns.push_back(Eigen::AngleAxisd(a, Vec3::Unit(axis)).toRotationMatrix());
  std::vector<Vec3> dirs;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int l = -1; l <= 1; ++l)
        if (i || j || l) dirs.push_back(Vec3(i, j, l));
  Tally T;
  for (const SmoothPolytope& p1 : bodies)
    for (const SmoothPolytope& p2 : bodies)
      for (const Mat3& R : turns)
        for (const Vec3& d : dirs)
          for (double r : {1e-3, 0.7, 1.0, 3.0})
            if (!HasFatalFailure()) check_case(p1, p2, R, r * d, T);
  report("aligned", T);
}

/// The paper's polytope against itself on the sweep's first 2,000 poses
/// (every tenth of the 20,000; core/examples/paper_shapes.hpp).
TEST(ExactPolytopeStart, PaperSweepAgreesWithBruteForceLp) {
  const SmoothPolytope P = test::paper_poly();
  const double rmin = 0.1 * P.radii().inner, rmax = 2.0 * P.radii().outer;
  Tally T;
  for (std::size_t k = 0; k < 20000 && !HasFatalFailure(); k += 10) {
    const Pose X = examples::paper_sweep_pose(k, rmin, rmax);
    check_case(P, P, X.R, X.p, T);
  }
  report("paper sweep", T);
}

// The two polytopes' start moved kExactStartPolytopeStep of the way to the
// smooth contact (soft1, soft2): on the paper's sweep, nearer the smooth
// bodies' alpha* (the solver's answer, tight tolerance) than the exact
// polytopes' vertex, by about that fraction of the gap; the exact
// polytopes' alpha stays a lower bound of it.
TEST(ExactPolytopeStart, MovedStartIsNearerTheSmoothContact) {
  const SmoothPolytope P = test::paper_poly();
  const double soft = P.L() / P.beta();
  ASSERT_EQ(detail::smoothing_length(P, P.beta()), soft);
  SolverOptions o;
  o.tolerance = 1e-12;
  const double rmin = 0.1 * P.radii().inner, rmax = 2.0 * P.radii().outer;
  std::vector<double> gap[2];  // [moved]
  for (std::size_t k = 0; k < 20000 && !HasFatalFailure(); k += 10) {
    const Pose X = examples::paper_sweep_pose(k, rmin, rmax);
    const SolveResult res = solve(Shape(P), Shape(P), X, o);
    ASSERT_TRUE(res.converged());
    double alpha[2] = {0.0, 0.0}, unique = 0.0;
    Vec3 x;
    ASSERT_TRUE(detail::exact_polytope_contact(P, P, X.R, X.p, alpha[0], x, nullptr, &unique));
    ASSERT_TRUE(detail::exact_polytope_contact(P, P, X.R, X.p, alpha[1], x, nullptr, nullptr, soft, soft));
    ASSERT_LE(alpha[0], res.alpha * (1.0 + 1e-12));
    if (unique > detail::kExactStartUnique && alpha[1] != alpha[0])
      for (int c = 0; c < 2; ++c) gap[c].push_back(std::abs(alpha[c] - res.alpha) / res.alpha);
  }
  ASSERT_GT(gap[1].size(), 1000u);
  const double m0 = median(gap[0]), m1 = median(gap[1]);
  std::printf("Poly-Poly: %zu poses moved, median |alpha - alpha*| / alpha*: exact vertex %.3g, moved %.3g\n", gap[1].size(),
              m0, m1);
  EXPECT_LE(m1, (1.0 - 0.5 * detail::kExactStartPolytopeStep) * m0);
}

// exact_start moves two polytopes' vertex only where both are within
// [kExactStartMinShrink, kExactStartMaxShrink]: the paper's pair (0.18 each)
// moves; against the same polytope at beta = 1000 (0.004) or 5 (0.72), no
// body moves.
TEST(ExactPolytopeStart, MoveOnlyWhereBothPolytopesAreInTheShrinkRange) {
  const SmoothPolytope P = test::paper_poly();
  EXPECT_GE(detail::relative_shrink(P, P.beta()), detail::kExactStartMinShrink);
  EXPECT_LE(detail::relative_shrink(P, P.beta()), detail::kExactStartMaxShrink);
  const Pose X = examples::paper_sweep_pose(7, 0.1 * P.radii().inner, 2.0 * P.radii().outer);
  double exact = 0.0;
  Vec3 x;
  ASSERT_TRUE(detail::exact_polytope_contact(P, P, X.R, X.p, exact, x));
  int moved = 0;
  for (double b2 : {P.beta(), 1000.0, 5.0}) {
    double a = 0.0;
    ASSERT_TRUE(detail::exact_start(P, P, P.beta(), b2, X.R, X.p, a, x)) << b2;
    moved += a != exact;
    if (b2 != P.beta()) EXPECT_EQ(a, exact) << b2;
  }
  EXPECT_EQ(moved, 1);
}

// log_start (the starts' cheap logarithm) against std::log: within 1e-9
// absolute from the smallest multiplier ratio a start keeps to the face
// counts that the shrink reads.
TEST(ExactPolytopeStart, CheapLogIsWithinItsBound) {
  double worst = 0.0;
  for (double x = 1e-12; x < 1e4; x *= 1.0007) worst = std::max(worst, std::abs(detail::log_start(x) - std::log(x)));
  for (int m = 1; m <= 1024; ++m) worst = std::max(worst, std::abs(detail::log_start(m) - std::log(static_cast<double>(m))));
  std::printf("log_start: largest error %.3g\n", worst);
  EXPECT_LE(worst, 1e-9);
}

TEST(ExactPolytopeStart, ZeroOrNonFiniteOffsetIsRefused) {
  const SmoothPolytope P = test::paper_poly();
  double alpha = 0.0;
  Vec3 x;
  EXPECT_FALSE(detail::exact_polytope_contact(P, P, Mat3::Identity(), Vec3::Zero(), alpha, x));
  EXPECT_FALSE(detail::exact_polytope_contact(P, P, Mat3::Identity(), Vec3(INFINITY, 0, 0), alpha, x));
  EXPECT_FALSE(detail::exact_polytope_contact(P, P, Mat3::Identity(), Vec3(NAN, 0, 0), alpha, x));
}

// exact_polytope_ellipsoid_contact against an oracle that shares no code
// with it: every set U of 1 to 3 faces taken as active, y(alpha) the
// least-norm solution of g_i . y = alpha b_i - h_i (i in U) by Eigen's
// complete orthogonal decomposition, both roots of |y(alpha)| = alpha, and
// the least alpha whose point meets every face. (Any such point is
// feasible, so its alpha bounds alpha* from above; the optimum is one of
// them.) No multipliers, no active-set walk.
bool brute_force_ellipsoid(const SmoothPolytope& p, const Mat3& C, const Vec3& r, double& alpha, Vec3& v) {
  const int m = p.num_halfspaces();
  std::vector<Vec3> g(m);
  std::vector<double> b(m), h(m);
  for (int i = 0; i < m; ++i) g[i] = C.transpose() * p.normal(i), b[i] = p.offset(i), h[i] = p.normal(i).dot(r);
  const double size = p.radii().outer + C.colwise().norm().maxCoeff();
  alpha = INFINITY;
  auto consider = [&](const std::vector<int>& U) {
    const int u = static_cast<int>(U.size());
    Eigen::MatrixXd G(u, 3);
    Eigen::VectorXd bu(u), hu(u);
    for (int j = 0; j < u; ++j) G.row(j) = g[U[j]].transpose(), bu[j] = b[U[j]], hu[j] = h[U[j]];
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(G);
    if (cod.rank() < u) return;
    const Vec3 P = cod.solve(bu), Q = cod.solve(hu);
    // (P.P - 1) a^2 - 2 P.Q a + Q.Q = 0
    const double A = P.squaredNorm() - 1.0, B = P.dot(Q), Cq = Q.squaredNorm();
    std::vector<double> roots;
    if (std::abs(A) < 1e-14) {
      if (B > 0.0) roots.push_back(Cq / (2.0 * B));
    } else {
      const double D = B * B - A * Cq;
      if (D < 0.0) return;
      roots.push_back((B + std::sqrt(D)) / A);
      roots.push_back((B - std::sqrt(D)) / A);
    }
    for (double a : roots) {
      if (!(a > 0.0) || !(a < alpha)) continue;
      const Vec3 y = a * P - Q;
      const double tol = 1e-10 * (r.norm() + a * size);
      bool ok = true;
      for (int i = 0; i < m && ok; ++i) ok = g[i].dot(y) + h[i] - a * b[i] <= tol;
      if (ok) alpha = a, v = r + C * y;
    }
  };
  for (int i = 0; i < m; ++i) {
    consider({i});
    for (int j = i + 1; j < m; ++j) {
      consider({i, j});
      for (int k = j + 1; k < m; ++k) consider({i, j, k});
    }
  }
  return std::isfinite(alpha);
}

/// How far v is from the polytope scaled by alpha (largest face violation)
/// and from the ellipsoid's boundary (|C^-1 (v - r)| - alpha), relative to
/// alpha times the bodies' size.
double ellipsoid_contact_error(const SmoothPolytope& p, const Mat3& C, const Vec3& r, double alpha, const Vec3& v) {
  double worst = 0.0;
  const double size = p.radii().outer + C.colwise().norm().maxCoeff();
  for (int i = 0; i < p.num_halfspaces(); ++i) worst = std::max(worst, (p.normal(i).dot(v) - alpha * p.offset(i)) / (alpha * size));
  return std::max(worst, std::abs((C.inverse() * (v - r)).norm() - alpha) / alpha);
}

void check_ellipsoid_case(const SmoothPolytope& p, const Mat3& C, const Vec3& r, Tally& T) {
  double alpha_ref = 0.0, alpha = 0.0;
  Vec3 v_ref, v;
  ASSERT_TRUE(brute_force_ellipsoid(p, C, r, alpha_ref, v_ref));
  int steps = 0;
  ASSERT_TRUE(detail::exact_polytope_ellipsoid_contact(p, C, r, alpha, v, &steps))
      << "C = \n" << C << "\nr = " << r.transpose() << "\nalpha_ref = " << alpha_ref;
  const double ea = std::abs(alpha - alpha_ref) / alpha_ref, ex = ellipsoid_contact_error(p, C, r, alpha, v);
  const double ev = (v - v_ref).norm() / (alpha * (p.radii().outer + C.colwise().norm().maxCoeff()));
  EXPECT_LE(ea, 1e-9) << "alpha " << alpha << " oracle " << alpha_ref << " r = " << r.transpose() << "\nC =\n" << C;
  EXPECT_LE(ex, 1e-9) << "v = " << v.transpose() << " alpha " << alpha << " r = " << r.transpose() << "\nC =\n" << C;
  EXPECT_LE(ev, 1e-6) << "v = " << v.transpose() << " oracle " << v_ref.transpose() << " r = " << r.transpose();
  ++T.cases;
  T.iterations += steps;
  T.worst_iterations = std::max(T.worst_iterations, steps);
  T.worst_alpha = std::max(T.worst_alpha, ea);
  T.worst_x = std::max(T.worst_x, ex);
}

TEST(ExactPolytopeEllipsoidStart, RandomPairsAgreeWithBruteForce) {
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Tally T;
  for (int k = 0; k < 3000 && !HasFatalFailure(); ++k) {
    const SmoothPolytope p = random_polytope(rng);
    // Semi-axes 0.05 to 2 (up to 40:1), or a sphere on one case in four.
    Vec3 ax(0.05 + 1.95 * U(rng), 0.05 + 1.95 * U(rng), 0.05 + 1.95 * U(rng));
    if (k % 4 == 1) ax.setConstant(ax[0]);
    const Mat3 C = random_rotation(rng) * ax.asDiagonal();
    const double size = p.radii().outer + ax.maxCoeff();
    const double rr = k % 3 == 0 ? size * std::pow(10.0, -6.0 + 12.0 * U(rng))
                                 : (0.1 * std::min(p.radii().inner, ax.minCoeff()) + 2.0 * size * U(rng));
    check_ellipsoid_case(p, C, rr * random_unit(rng), T);
  }
  report("polytope and ellipsoid, random", T);
}

/// Axis-aligned boxes against spheres and ellipsoids whose centres lie on
/// the boxes' axes, face diagonals and body diagonals: contacts exactly at
/// face centres, edges and corners, where multipliers vanish and faces are
/// parallel to the ellipsoid's axes.
TEST(ExactPolytopeEllipsoidStart, AlignedContactsAgreeWithBruteForce) {
  const std::vector<SmoothPolytope> bodies = {test::box(0.5, 0.5, 0.5, 20.0), test::box(1.0, 0.25, 0.5, 20.0), test::paper_poly(),
                                              SmoothPolytope::from_vertices({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, 20.0)};
  const std::vector<Vec3> axes = {Vec3(0.5, 0.5, 0.5), Vec3(0.5, 1.0, 1.5), Vec3(2.0, 0.1, 0.3)};
  std::vector<Mat3> turns = {Mat3::Identity()};
  for (int axis = 0; axis < 3; ++axis) turns.push_back(Eigen::AngleAxisd(0.5 * M_PI, Vec3::Unit(axis)).toRotationMatrix());
  Tally T;
  for (const SmoothPolytope& p : bodies)
    for (const Vec3& ax : axes)
      for (const Mat3& R : turns)
        for (int i = -1; i <= 1; ++i)
          for (int j = -1; j <= 1; ++j)
            for (int l = -1; l <= 1; ++l)
              for (double rr : {1e-3, 0.7, 3.0})
                if ((i || j || l) && !HasFatalFailure()) check_ellipsoid_case(p, R * ax.asDiagonal(), rr * Vec3(i, j, l), T);
  report("polytope and ellipsoid, aligned", T);
}

/// The paper's polytope and ellipsoid on the sweep's first 2,000 poses, in
/// both orders of the pair (body 2 turned by R at r_S in body 1's frame):
/// the brute force agrees, and the exact alpha* is below the smooth
/// bodies' (the smooth polytope lies inside the exact one) by less than
/// the smoothing's shrink, 1 - L log(m) / (beta b_min).
TEST(ExactPolytopeEllipsoidStart, PaperSweepAgreesWithBruteForceAndBoundsTheSmoothContact) {
  const SmoothPolytope P = test::paper_poly();
  const Superellipsoid E(0.5, 1.0, 1.5, 1.0);
  const Vec3 ax(0.5, 1.0, 1.5);
  const double rmin = 0.1 * E.radii().inner, rmax = 2.0 * P.radii().outer;
  Tally T;
  double worst_gap = 0.0;
  for (std::size_t k = 0; k < 20000 && !HasFatalFailure(); k += 10) {
    const Pose X = examples::paper_sweep_pose(k, rmin, rmax);
    // Poly-Ellip: the ellipsoid at X.p turned by X.R, in the polytope's frame.
    check_ellipsoid_case(P, X.R * ax.asDiagonal(), X.p, T);
    // Ellip-Poly: the polytope at X.p turned by X.R; in its frame the
    // ellipsoid sits at -R^T p, turned by R^T.
    check_ellipsoid_case(P, X.R.transpose() * ax.asDiagonal(), -(X.R.transpose() * X.p), T);
    double alpha = 0.0;
    Vec3 v;
    ASSERT_TRUE(detail::exact_polytope_ellipsoid_contact(P, X.R * ax.asDiagonal(), X.p, alpha, v));
    const SolveResult res = solve(Shape(P), Shape(E), X);
    ASSERT_TRUE(res.converged());
    EXPECT_LE(alpha, res.alpha * (1.0 + 1e-12));
    worst_gap = std::max(worst_gap, 1.0 - alpha / res.alpha);
  }
  double bmin = INFINITY;
  for (int i = 0; i < P.num_halfspaces(); ++i) bmin = std::min(bmin, P.offset(i));
  EXPECT_LE(worst_gap, P.L() * std::log(double(P.num_halfspaces())) / (P.beta() * bmin));
  std::printf("paper sweep: smooth alpha* above the exact by at most %.3g relative\n", worst_gap);
  report("polytope and ellipsoid, paper sweep", T);
}

/// A sphere of 1e-3 against a box of 1e3, touching a face: alpha* =
/// a.r / (b + rho) in closed form, which the active-set steps must keep to
/// rounding although |P| is 1e6 there (the quadratic's discriminant formed
/// as a difference of products lost 5e-11 of alpha).
TEST(ExactPolytopeEllipsoidStart, SmallSphereOnALargeFaceMatchesTheClosedForm) {
  const SmoothPolytope box = test::box(1e3, 1e3, 1e3, 20.0);
  double worst = 0.0;
  for (const double rho : {1e-3, 1.0, 1e3})
    for (const Vec3& r : {Vec3(3e3, 500.0, -700.0), Vec3(-2.5e3, 10.0, 1e3), Vec3(1.0, 5e3, -2.0), Vec3(1e-2, -2.0, 7e3)}) {
      int axis = 0;
      r.cwiseAbs().maxCoeff(&axis);
      const double expected = std::abs(r[axis]) / (1e3 + rho);
      double alpha = 0.0;
      Vec3 v;
      ASSERT_TRUE(detail::exact_polytope_ellipsoid_contact(box, rho * Mat3::Identity(), r, alpha, v));
      worst = std::max(worst, std::abs(alpha - expected) / expected);
      EXPECT_LE(std::abs(alpha - expected), 1e-14 * expected) << "rho " << rho << " r " << r.transpose();
    }
  std::printf("small sphere on a large face: worst |alpha - closed form| / alpha %.2e\n", worst);
}

/// The first-order smoothing correction (soft > 0) moves the exact contact
/// towards the smooth bodies': on the paper's sweep, where an edge or a
/// vertex of the polytope touches the ellipsoid, alpha from the corrected
/// start is nearer the solver's alpha* than the exact contact's (median
/// relative gap at most a fifth).
TEST(ExactPolytopeEllipsoidStart, CorrectedStartIsNearerTheSmoothContact) {
  const SmoothPolytope P = test::paper_poly();
  const Superellipsoid E(0.5, 1.0, 1.5, 1.0);
  const Vec3 ax(0.5, 1.0, 1.5);
  const double soft = P.L() / P.beta();
  ASSERT_EQ(detail::smoothing_length(P, P.beta()), soft);
  const double rmin = 0.1 * E.radii().inner, rmax = 2.0 * P.radii().outer;
  std::vector<double> gap[2];  // [corrected]
  for (std::size_t k = 0; k < 20000 && !HasFatalFailure(); k += 10) {
    const Pose X = examples::paper_sweep_pose(k, rmin, rmax);
    const SolveResult res = solve(Shape(P), Shape(E), X);
    ASSERT_TRUE(res.converged());
    double alpha[2] = {0.0, 0.0};
    Vec3 x;
    ASSERT_TRUE(detail::exact_polytope_ellipsoid_contact(P, X.R * ax.asDiagonal(), X.p, alpha[0], x));
    ASSERT_TRUE(detail::exact_polytope_ellipsoid_contact(P, X.R * ax.asDiagonal(), X.p, alpha[1], x, nullptr, soft));
    // (A face against the ellipsoid has no correction.)
    if (alpha[1] != alpha[0])
      for (int c = 0; c < 2; ++c) gap[c].push_back(std::abs(alpha[c] - res.alpha) / res.alpha);
  }
  ASSERT_GT(gap[1].size(), 1000u);
  const double m0 = median(gap[0]), m1 = median(gap[1]);
  std::printf("Poly-Ellip: %zu poses corrected, median |alpha - alpha*| / alpha*: exact contact %.3g, corrected %.3g\n",
              gap[1].size(), m0, m1);
  EXPECT_LE(m1, 0.2 * m0);
}

/// The correction is left out for rounder polytopes (relative shrink above
/// kExactStartMaxShrink), where first order is not enough.
TEST(ExactPolytopeEllipsoidStart, NoCorrectionForRoundPolytopes) {
  const SmoothPolytope P = test::paper_poly();
  EXPECT_GT(detail::smoothing_length(P, 20.0), 0.0);
  EXPECT_EQ(detail::smoothing_length(P, 10.0), 0.0);
  EXPECT_EQ(detail::smoothing_length(P, 5.0), 0.0);
}

TEST(ExactPolytopeEllipsoidStart, ZeroOrNonFiniteOffsetIsRefused) {
  const SmoothPolytope P = test::paper_poly();
  double alpha = 0.0;
  Vec3 v;
  EXPECT_FALSE(detail::exact_polytope_ellipsoid_contact(P, Mat3::Identity(), Vec3::Zero(), alpha, v));
  EXPECT_FALSE(detail::exact_polytope_ellipsoid_contact(P, Mat3::Identity(), Vec3(INFINITY, 0, 0), alpha, v));
  EXPECT_FALSE(detail::exact_polytope_ellipsoid_contact(P, Mat3::Identity(), Vec3(NAN, 0, 0), alpha, v));
}

}  // namespace
