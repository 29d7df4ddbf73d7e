// Derivatives w.r.t. shape parameters against oracles that share no code
// with them:
// (a) central finite differences in theta: each shape is re-constructed
//     with a perturbed parameter (through its constructor) and re-solved;
// (b) two spheres: alpha* = |r| / (R1 + R2) and x* = alpha* R1 r/|r|;
// (c) two ellipsoids: the Perram-Wertheim function
//     F(lambda) = lambda (1 - lambda) r^T C(lambda)^{-1} r,
//     C = (1 - lambda) A1^{-1} + lambda A2^{-1}, alpha*^2 = max F, evaluated
//     and maximised here, differentiated in the axes by the envelope theorem.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/LU>

#include "idcol/shape_derivatives.hpp"
#include "idcol/solver.hpp"
#include "fd_values.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

// Steps and tolerance as in test_derivatives.cpp: Richardson-extrapolated
// central differences (truncation O(h^4)) with relative step 1e-5, rounding
// ~1e-12 / 1e-5 = 1e-7, tolerance 1e-5 on dimensionless quantities.
constexpr double kH = 1e-5;
constexpr double kTol = 1e-5;

using test::kHertz, test::kN, test::pair_length, test::tight, test::Vals, test::values;
using JacX = Eigen::Matrix<double, kN, Eigen::Dynamic>;

/// Step for parameter j: relative to |theta_j|, at least h L^power.
double step(const VecX& theta, const VecX& pw, int j, double L) { return kH * std::max(std::abs(theta[j]), std::pow(L, pw[j])); }

/// Richardson-extrapolated differences of f(theta) in parameter j: central,
/// or second-order forward where theta - h is not a valid shape (n = 1).
template <class F, class V>
bool fd_param(const Shape& S, int j, double hj, const V& f0, F&& f, V& out) {
  const VecX theta = shape_params(S);
  auto at = [&](double dt) {
    VecX t = theta;
    t[j] += dt;
    return shape_with_params(S, t);
  };
  V d[2];
  for (int k = 0; k < 2; ++k) {
    const double h = hj / (1 + k);
    V vp, vm;
    bool central = true;
    Shape minus = S;
    try {
      minus = at(-h);
    } catch (const std::invalid_argument&) {
      central = false;
    }
    if (central) {
      if (!f(at(h), vp) || !f(minus, vm)) return false;
      d[k] = (vp - vm) / (2.0 * h);
    } else {
      if (!f(at(h), vp) || !f(at(2.0 * h), vm)) return false;
      d[k] = (-3.0 * f0 + 4.0 * vp - vm) / (2.0 * h);
    }
  }
  out = (4.0 * d[1] - d[0]) / 3.0;
  return true;
}

bool fd_jacobian(const Shape& A, const Shape& B, int body, const Pose& X, JacX& J) {
  const Shape& S = body == 1 ? A : B;
  const double L = pair_length(A, B);
  const VecX theta = shape_params(S), pw = param_length_powers(S);
  Vals f0;
  if (!values(A, B, X, f0)) return false;
  J.resize(kN, theta.size());
  for (int j = 0; j < theta.size(); ++j) {
    Vals col;
    auto f = [&](const Shape& s, Vals& v) { return body == 1 ? values(s, B, X, v) : values(A, s, X, v); };
    if (!fd_param(S, j, step(theta, pw, j, L), f0, f, col)) return false;
    J.col(j) = col;
  }
  return true;
}

JacX analytic_jacobian(const SolveResult& r, const ShapeSensitivity& s) {
  const ShapeKinematicsDerivatives d = shape_kinematics_derivatives(r, s);
  const ShapeWrenchDerivatives w = shape_wrench_derivatives(r, s, kHertz);
  JacX J(kN, s.dz_dtheta.cols());
  J << s.dz_dtheta, d.dp1_1, d.dp2_1, d.dnhat_1, d.dgap, w.dF1_1, w.dF2_2;
  return J;
}

struct Block {
  const char* name;
  int row, rows;
  double length_power;
};
const Block kBlocks[] = {{"x", 0, 3, 1},  {"alpha", 3, 1, 0}, {"lambda", 4, 2, 1}, {"p1", 6, 3, 1}, {"p2", 9, 3, 1},
                         {"nhat", 12, 3, 0}, {"gap", 15, 1, 1}, {"F1", 16, 6, 0},    {"F2", 22, 6, 0}};

/// Worst relative error over the blocks, dimensionless: rows divided by
/// L^power (wrench rows by the force scale), columns times L^(param power).
void compare(const JacX& A, const JacX& B, const VecX& pw, double L, double force_scale, bool with_wrench,
             const std::string& what) {
  for (const Block& blk : kBlocks) {
    if (blk.row >= 16 && !with_wrench) continue;
    Eigen::MatrixXd a = A.middleRows(blk.row, blk.rows), b = B.middleRows(blk.row, blk.rows);
    const double s = blk.row >= 16 ? 1.0 / force_scale : std::pow(L, -blk.length_power);
    for (int j = 0; j < a.cols(); ++j) {
      a.col(j) *= s * std::pow(L, pw[j]);
      b.col(j) *= s * std::pow(L, pw[j]);
    }
    const double err = (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
    EXPECT_LT(err, kTol) << what << " block " << blk.name << "\nIFT\n" << a << "\nFD\n" << b;
  }
}

Pose with_alpha(const Shape& a, const Shape& b, const Pose& X, double target) {
  const SolveResult r = solve(a, b, X, tight());
  if (!r.converged()) return X;
  return Pose{X.R, X.p * (target / r.alpha)};
}

/// A strictly simplicial polytope: a perturbed octahedron (8 triangles).
std::vector<Vec3> octa_vertices() {
  return {{1.1, 0.05, -0.02}, {-0.9, 0.1, 0.03}, {0.04, 1.2, 0.1}, {-0.06, -0.8, 0.02}, {0.1, -0.05, 1.0}, {-0.03, 0.07, -1.3}};
}

}  // namespace

// ---------------------------------------------------------------------------
// The mixed derivatives of each family.

TEST(ShapeParams, MixedDerivativesMatchFiniteDifferences) {
  auto cat = test::catalogue();
  cat.push_back({"Hull_b15", SmoothPolytope::from_vertices(octa_vertices(), 15.0)});
  cat.push_back({"SE_n1.5", Superellipsoid(0.7, 1.3, 0.9, 1.5)});
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0.3, 1.6);
  using V4 = Eigen::Matrix<double, 4, 1>;
  int checked = 0;
  for (const auto& S : cat) {
    const double Ro = radii(S.shape).outer;
    for (int t = 0; t < 20; ++t) {
      const Vec3 y = U(rng) * Ro * test::random_unit(rng);
      ShapeEval e;
      ShapeParamEval d;
      eval_params(S.shape, y, e, d);
      ShapeEval e0;
      eval(S.shape, y, e0);
      ASSERT_EQ(e.phi, e0.phi);
      ASSERT_EQ(d.dphi.size(), num_params(S.shape));
      const VecX theta = shape_params(S.shape), pw = param_length_powers(S.shape);
      const V4 f0(e.phi, e.grad.x(), e.grad.y(), e.grad.z());
      for (int j = 0; j < theta.size(); ++j) {
        auto f = [&](const Shape& s, V4& v) {
          ShapeEval ej;
          eval(s, y, ej);
          v << ej.phi, ej.grad;
          return true;
        };
        V4 fd;
        ASSERT_TRUE(fd_param(S.shape, j, step(theta, pw, j, Ro), f0, f, fd));
        V4 an;
        an << d.dphi[j], d.dgrad.col(j);
        const double scale = std::pow(Ro, pw[j]);
        const double err = (an - fd).cwiseAbs().maxCoeff() * scale / std::max(1.0, fd.cwiseAbs().maxCoeff() * scale);
        EXPECT_LT(err, 1e-6) << S.name << " param " << param_names(S.shape)[j] << " y " << y.transpose()
                             << "\nanalytic " << an.transpose() << "\nfd " << fd.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 20 * (1 + 4 * 3 + 3 * 2 + 33 + 25 + 5 * 2 + 33 + 4));
}

// Overflow-safe like phi: wherever eval gives a finite phi (any |y| for the
// superquadrics and the polytope; |y| up to ~1e100 L for the cone, see
// SmoothTruncatedCone; up to ~1e154 for the sphere, whose |y| squares), the
// parameter derivatives are finite too.
TEST(ShapeParams, FiniteWherePhiIsFinite) {
  std::mt19937_64 rng(8);
  int checked = 0;
  for (const auto& S : test::catalogue()) {
    const bool cone = std::holds_alternative<SmoothTruncatedCone>(S.shape);
    for (double scale : {1e-300, 1e-150, 1e-8, 1.0, 1e8, 1e100, 1e250}) {
      if (cone && scale > 1e100) continue;
      for (int t = 0; t < 5; ++t) {
        const Vec3 y = scale * test::random_unit(rng);
        ShapeEval e;
        ShapeParamEval d;
        eval_params(S.shape, y, e, d);
        if (!std::isfinite(e.phi)) continue;  // beyond phi's own range
        EXPECT_TRUE(d.dphi.allFinite() && d.dgrad.allFinite()) << S.name << " |y| = " << scale << "\n"
                                                               << d.dphi.transpose() << "\n" << d.dgrad;
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 10 * 7 * 5 - 2 * 5 - 5);  // all but the cone beyond 1e100 and the sphere at 1e250
}

TEST(ShapeParams, OrderNamesAndRoundTrip) {
  const Superellipsoid se(0.5, 1.0, 1.5, 8.0);
  EXPECT_EQ(shape_params(se), (VecX(4) << 0.5, 1.0, 1.5, 8.0).finished());
  EXPECT_EQ(param_names(SuperellipticCylinder(1, 2, 3)), (std::vector<std::string>{"R", "h", "n"}));
  const SmoothPolytope P = test::box(0.6, 0.9, 0.4, 10.0);
  EXPECT_EQ(num_params(P), 25);
  EXPECT_EQ(param_names(P)[7], "b1");
  EXPECT_EQ(param_names(P)[24], "beta");
  for (const auto& S : test::catalogue()) {
    EXPECT_EQ(describe(shape_with_params(S.shape, shape_params(S.shape))), describe(S.shape)) << S.name;
    EXPECT_EQ(static_cast<int>(param_names(S.shape).size()), num_params(S.shape));
  }
}

TEST(ShapeParams, BadInputIsRejected) {
  EXPECT_THROW(shape_with_params(Sphere(1.0), VecX::Ones(2)), std::invalid_argument);
  EXPECT_THROW(shape_with_params(Sphere(1.0), (VecX(1) << -1.0).finished()), std::invalid_argument);
  const SolveResult r = solve(Sphere(1.0), Sphere(0.5), Pose{Mat3::Identity(), Vec3(2, 0, 0)}, test::with_derivatives());
  ASSERT_TRUE(r.converged());
  try {
    shape_sensitivity(r, Sphere(1.0), Sphere(0.5), 3);
    ADD_FAILURE() << "body 3 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'body'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(shape_sensitivity(r, Sphere(1.0), Sphere(0.7), 2), std::invalid_argument);   // not the solved shapes
  EXPECT_THROW(shape_sensitivity(r, Sphere(1.0), Superellipsoid(0.6, 0.5, 0.5, 1), 2), std::invalid_argument);
  const SolveResult nf = solve(Sphere(1.0), Sphere(0.5), Pose{Mat3::Identity(), Vec3(2, 0, 0)});
  EXPECT_THROW(shape_sensitivity(nf, Sphere(1.0), Sphere(0.5), 1), std::invalid_argument);  // no factorisation
  // A box from vertices has square faces: no vertex derivatives.
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.push_back(Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  EXPECT_THROW(polytope_vertex_jacobian(cube, SmoothPolytope::from_vertices(cube, 10.0)), std::invalid_argument);
  EXPECT_THROW(polytope_vertex_jacobian(octa_vertices(), test::paper_poly()), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// The solution, kinematics and wrench.

// Every family and pair of the catalogue, both bodies, at alpha* in
// {2, 1.3, 1, 0.95, 0.6}: all 28 outputs against central differences in
// every parameter.
TEST(ShapeDerivatives, AgreeWithFiniteDifferencesForEveryPair) {
  const auto cat = test::catalogue();
  std::mt19937_64 rng(17);
  int checked = 0, skipped = 0;
  for (const auto& A : cat)
    for (const auto& B : cat) {
      const double L = pair_length(A.shape, B.shape);
      for (double target : {2.0, 1.3, 1.0, 0.95, 0.6}) {
        const Pose X = with_alpha(A.shape, B.shape, test::random_pose(rng, 0.3, 6.0), target);
        const SolveResult r = solve(A.shape, B.shape, X, tight());
        ASSERT_TRUE(r.converged()) << A.name << "-" << B.name;
        for (int body : {1, 2}) {
          const ShapeSensitivity s = shape_sensitivity(r, A.shape, B.shape, body);
          ASSERT_TRUE(s.valid);
          if (!s.cond.reliable) {
            ++skipped;
            continue;
          }
          JacX fd;
          ASSERT_TRUE(fd_jacobian(A.shape, B.shape, body, X, fd)) << A.name << "-" << B.name;
          const ContactWrench w = contact_wrench(r, kHertz);
          const double fscale = std::max(w.f_n, kHertz.stiffness * std::pow(1e-3 * L, kHertz.exponent));
          // f_n = k delta^1.5 is not C^2 at delta = 0 (see test_derivatives.cpp).
          const bool with_wrench = std::abs(contact_kinematics(r).gap) > 1e3 * kH * L;
          compare(analytic_jacobian(r, s), fd, param_length_powers(body == 1 ? A.shape : B.shape), L, fscale, with_wrench,
                  A.name + "-" + B.name + " body " + std::to_string(body) + " alpha=" + std::to_string(r.alpha));
          ++checked;
        }
      }
    }
  EXPECT_GE(checked, 990);
  EXPECT_LE(skipped, 10);
}

TEST(ShapeDerivatives, TwoSpheresClosedForm) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.2, 3.0);
  int checked = 0;
  for (int t = 0; t < 200; ++t) {
    const double R1 = U(rng), R2 = U(rng);
    const Pose X = test::random_pose(rng, 0.05, 10.0);
    const SolveResult r = solve(Sphere(R1), Sphere(R2), X, tight());
    ASSERT_TRUE(r.converged());
    const double nr = X.p.norm(), S = R1 + R2;
    const Vec3 u = X.p / nr;
    const ShapeSensitivity s1 = shape_sensitivity(r, Sphere(R1), Sphere(R2), 1);
    const ShapeSensitivity s2 = shape_sensitivity(r, Sphere(R1), Sphere(R2), 2);
    // alpha = |r| / (R1 + R2), x = alpha R1 u.
    EXPECT_NEAR(s1.dz_dtheta(3, 0), -nr / (S * S), 1e-10 * nr / (S * S));
    EXPECT_NEAR(s2.dz_dtheta(3, 0), -nr / (S * S), 1e-10 * nr / (S * S));
    EXPECT_LT((s1.dx_dtheta().col(0) - nr * R2 / (S * S) * u).norm(), 1e-10 * nr / S);
    EXPECT_LT((s2.dx_dtheta().col(0) + nr * R1 / (S * S) * u).norm(), 1e-10 * nr / S);
    // gap = |r| - (R1 + R2): d gap / d R_i = -1; the normal does not move.
    const ShapeKinematicsDerivatives d = shape_kinematics_derivatives(r, s1);
    EXPECT_NEAR(d.dgap[0], -1.0, 1e-10);
    EXPECT_LT(d.dnhat_1.norm(), 1e-10);
    ++checked;
  }
  EXPECT_EQ(checked, 200);
}

namespace {
/// Perram-Wertheim for two exact ellipsoids with axes a1 (body 1 at the
/// identity) and a2 (body 2 at X): alpha*^2 = max_lambda F(lambda). Returns
/// alpha and d alpha / d(a1, a2) by the envelope theorem.
struct PW {
  double alpha;
  Vec3 da1, da2;
};
PW perram_wertheim(const Vec3& a1, const Vec3& a2, const Pose& X) {
  const Mat3 C1 = a1.cwiseAbs2().asDiagonal();
  const Mat3 C2 = X.R * a2.cwiseAbs2().asDiagonal() * X.R.transpose();
  const Vec3 r = X.p;
  auto F = [&](double l) { return l * (1 - l) * r.dot(((1 - l) * C1 + l * C2).partialPivLu().solve(r)); };
  // F is concave on [0, 1]: golden-section search, then Newton on F' by
  // central differences of F' (both to about 1e-13 in lambda).
  double lo = 0.0, hi = 1.0;
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 60; ++i) {
    const double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
    (F(m1) < F(m2) ? lo : hi) = (F(m1) < F(m2) ? m1 : m2);
  }
  double l = 0.5 * (lo + hi);
  // F'(l) in closed form: with u = C^{-1} r,
  //   F' = (1 - 2l) r^T u - l(1-l) u^T (C2 - C1) u.
  for (int i = 0; i < 20; ++i) {
    auto dF = [&](double x) {
      const Vec3 u = ((1 - x) * C1 + x * C2).partialPivLu().solve(r);
      return (1 - 2 * x) * r.dot(u) - x * (1 - x) * u.dot((C2 - C1) * u);
    };
    const double e = 1e-7;
    const double d2 = (dF(l + e) - dF(l - e)) / (2 * e);
    const double step = dF(l) / d2;
    l -= step;
    if (std::abs(step) < 1e-15) break;
  }
  const Vec3 u = ((1 - l) * C1 + l * C2).partialPivLu().solve(r);
  const double F2 = l * (1 - l) * r.dot(u);
  PW out;
  out.alpha = std::sqrt(F2);
  // dF/dC = -l(1-l) u u^T; dC/da1_i = (1-l) 2 a1_i e_i e_i^T; dC/da2_i = l 2 a2_i R e_i e_i^T R^T.
  const Vec3 v = X.R.transpose() * u;
  for (int i = 0; i < 3; ++i) {
    out.da1[i] = -l * (1 - l) * (1 - l) * 2 * a1[i] * u[i] * u[i] / (2 * out.alpha);
    out.da2[i] = -l * (1 - l) * l * 2 * a2[i] * v[i] * v[i] / (2 * out.alpha);
  }
  return out;
}
}  // namespace

TEST(ShapeDerivatives, TwoEllipsoidsPerramWertheim) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> U(0.3, 2.0);
  int checked = 0;
  for (int t = 0; t < 200; ++t) {
    const Vec3 a1(U(rng), U(rng), U(rng)), a2(U(rng), U(rng), U(rng));
    const Pose X = test::random_pose(rng, 0.2, 8.0);
    const Superellipsoid E1(a1[0], a1[1], a1[2], 1.0), E2(a2[0], a2[1], a2[2], 1.0);
    const SolveResult r = solve(E1, E2, X, tight());
    ASSERT_TRUE(r.converged());
    const PW pw = perram_wertheim(a1, a2, X);
    ASSERT_NEAR(r.alpha, pw.alpha, 1e-9 * pw.alpha);
    const ShapeSensitivity s1 = shape_sensitivity(r, E1, E2, 1), s2 = shape_sensitivity(r, E1, E2, 2);
    if (!s1.cond.reliable || !s2.cond.reliable) continue;
    const double scale = pw.alpha / std::min(a1.minCoeff(), a2.minCoeff());
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(s1.dz_dtheta(3, i), pw.da1[i], 1e-7 * scale) << t << " a1_" << i;
      EXPECT_NEAR(s2.dz_dtheta(3, i), pw.da2[i], 1e-7 * scale) << t << " a2_" << i;
    }
    ++checked;
  }
  EXPECT_GE(checked, 195);
}

// Vertices of a simplicial polytope, through the hull's faces: chained
// sensitivity against re-building the polytope from perturbed vertices.
TEST(ShapeDerivatives, PolytopeVerticesThroughTheHull) {
  const std::vector<Vec3> V = octa_vertices();
  const double beta = 15.0;
  const SmoothPolytope P = SmoothPolytope::from_vertices(V, beta);
  const Eigen::MatrixXd M = polytope_vertex_jacobian(V, P);
  ASSERT_EQ(M.rows(), num_params(P));
  ASSERT_EQ(M.cols(), 3 * 6 + 1);
  const Shape other = Superellipsoid(0.5, 1.0, 1.5, 4.0);
  std::mt19937_64 rng(41);
  int checked = 0;
  for (double target : {2.0, 1.3, 0.95, 0.6})
    for (int body : {1, 2}) {
      const Shape A = body == 1 ? Shape(P) : other, B = body == 1 ? other : Shape(P);
      const Pose X = with_alpha(A, B, test::random_pose(rng, 0.5, 4.0), target);
      const SolveResult r = solve(A, B, X, tight());
      ASSERT_TRUE(r.converged());
      const ShapeSensitivity s = chain_params(shape_sensitivity(r, A, B, body), M);
      ASSERT_TRUE(s.cond.reliable);
      const double L = pair_length(A, B);
      for (int j = 0; j < M.cols(); ++j) {
        Eigen::Matrix<double, 4, 1> d[2];
        for (int k = 0; k < 2; ++k) {
          const double h = kH / (1 + k);
          auto at = [&](double dt) {
            std::vector<Vec3> W = V;
            double bt = beta;
            if (j < 18) W[j / 3][j % 3] += dt; else bt += dt * beta;
            const Shape Q = SmoothPolytope::from_vertices(W, bt);
            const SolveResult q = body == 1 ? solve(Q, other, X, tight()) : solve(other, Q, X, tight());
            EXPECT_TRUE(q.converged());
            return Eigen::Matrix<double, 4, 1>(q.x_1[0], q.x_1[1], q.x_1[2], q.alpha);
          };
          d[k] = (at(h) - at(-h)) / (2 * h);
          if (j == 18) d[k] /= beta;
        }
        const Eigen::Matrix<double, 4, 1> fd = (4 * d[1] - d[0]) / 3;
        const Eigen::Matrix<double, 4, 1> an = s.dz_dtheta.col(j).head<4>();
        const double err = ((an - fd).head<3>() / L).cwiseAbs().maxCoeff() + std::abs(an[3] - fd[3]);
        EXPECT_LT(err, kTol * std::max(1.0, fd.cwiseAbs().maxCoeff())) << "body " << body << " alpha " << target << " column "
                                                                       << j << "\n" << an.transpose() << "\n" << fd.transpose();
        ++checked;
      }
    }
  EXPECT_EQ(checked, 8 * 19);
}

// A subset of the sweep run by idcol_check_shape_derivatives (10^4 poses
// per pair and body there): 200 poses for every ordered pair of a sphere and
// the paper's four shapes, body 1 and body 2 (10^4 checks, ~2 s).
TEST(ShapeDerivatives, SweepSubsetAgreesOrIsFlagged) {
  auto shapes = test::paper_shapes();
  shapes.push_back({"Sph", Sphere(0.8)});
  std::mt19937_64 rng(99);
  long agree = 0, compared = 0;
  for (const auto& A : shapes)
    for (const auto& B : shapes)
      for (int body : {1, 2}) {
        std::vector<Pose> P;
        for (int i = 0; i < 200; ++i) P.push_back(test::random_pose(rng, 0.2, 8.0));
        const DerivativeCheckReport rep = check_shape_derivatives(A.shape, B.shape, body, P);
        EXPECT_EQ(rep.disagree_unflagged, 0) << A.name << "-" << B.name << " body " << body << "\n"
                                             << (rep.failures.empty() ? "" : rep.failures[0]);
        EXPECT_EQ(rep.converged, rep.poses);
        agree += rep.agree;
        compared += rep.converged - rep.fd_failed;
      }
  EXPECT_GE(compared, 9990);
  EXPECT_GE(agree, compared - 1);  // >= 99.99%
}

// The two poses of the 5 x 10^4-pose sweep (seed 1) on which steps h = 1e-5
// disagreed before the check refined them: x* slides ~130 L per unit of the
// cone's radii (a flat n = 8 face against the cone's rim), so the O(h^4)
// truncation at h = 1e-5 exceeded the tolerance; at h = 1e-6 they agree.
TEST(ShapeDerivatives, SweepRegressionsAgreeAtFinerSteps) {
  const Shape TC = SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0), SE = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  Pose X1, X2;
  X1.R << -0.76552242007812277, 0.47228744073845519, -0.43694392967342488, 0.14575926740993961, 0.78875076756916762,
      0.59718210172707509, 0.62668146639409439, 0.39346766065303151, -0.67264666779697846;
  X1.p << -4.6136125721705419, 3.6648666172906283, -4.3662492169134675;
  X2.R << -0.16436604303719715, 0.7984719731876686, -0.57916000546488478, -0.27525226856135693, -0.60095014355508658,
      -0.7503966375277461, -0.94721697226565837, 0.036075379345363756, 0.31855701916135393;
  X2.p << -0.18338333327732276, -0.21495154760905125, -0.44821333484266207;
  const DerivativeCheckReport r1 = check_shape_derivatives(test::paper_poly(), TC, 2, {X1});
  const DerivativeCheckReport r2 = check_shape_derivatives(TC, SE, 1, {X2});
  EXPECT_EQ(r1.agree, 1) << (r1.failures.empty() ? "" : r1.failures[0]);
  EXPECT_EQ(r2.agree, 1) << (r2.failures.empty() ? "" : r2.failures[0]);
}
