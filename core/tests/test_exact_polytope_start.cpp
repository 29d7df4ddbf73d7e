// exact_polytope_contact (detail/exact_polytope_start.hpp) against an oracle
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

#include "idcol/detail/exact_polytope_start.hpp"
#include "idcol/shapes.hpp"
#include "test_util.hpp"
#include "../examples/paper_shapes.hpp"

using namespace idcol;

namespace {

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

TEST(ExactPolytopeStart, ZeroOrNonFiniteOffsetIsRefused) {
  const SmoothPolytope P = test::paper_poly();
  double alpha = 0.0;
  Vec3 x;
  EXPECT_FALSE(detail::exact_polytope_contact(P, P, Mat3::Identity(), Vec3::Zero(), alpha, x));
  EXPECT_FALSE(detail::exact_polytope_contact(P, P, Mat3::Identity(), Vec3(INFINITY, 0, 0), alpha, x));
  EXPECT_FALSE(detail::exact_polytope_contact(P, P, Mat3::Identity(), Vec3(NAN, 0, 0), alpha, x));
}

}  // namespace
