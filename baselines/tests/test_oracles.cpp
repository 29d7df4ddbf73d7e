// The exact oracles against closed forms, against each other, and against
// idcol::solve (which they share no code with).
#include <cmath>
#include <iomanip>
#include <random>

#include <gtest/gtest.h>

#include "idcol/solver.hpp"
#include "idcol_baselines/baselines.hpp"
#ifdef IDCOL_BASELINES_WITH_FCL
#include "idcol_baselines/fcl_adapter.hpp"
#endif
#include "measured.hpp"
#include "test_util.hpp"

namespace idcol::baselines {
namespace {

using test::measured;
using test::random_pose;
using test::random_rotation;

Mat3 rot_z(double t) { return Eigen::AngleAxisd(t, Vec3::UnitZ()).toRotationMatrix(); }

TEST(PerramWertheim, SpheresMatchClosedForm) {
  std::mt19937_64 rng(11);
  for (int k = 0; k < 200; ++k) {
    const double R1 = 0.3 + 0.01 * k, R2 = 1.7 - 0.005 * k;
    const Pose X = random_pose(rng, 0.05, 20.0);
    const OracleAnswer o = perram_wertheim(Vec3::Constant(R1), Vec3::Constant(R2), X);
    ASSERT_TRUE(o.ok) << o.error;
    const double expect = X.p.norm() / (R1 + R2);
    EXPECT_NEAR(o.alpha, expect, 1e-15 * expect) << "k=" << k;
  }
}

TEST(PerramWertheim, CoaxialEllipsoidsMatchClosedForm) {
  const Vec3 A(0.7, 1.3, 0.45), B(0.35, 0.9, 1.85);
  for (double d : {0.13, 1.0, 3.7, 41.0}) {
    for (int axis = 0; axis < 3; ++axis) {
      Pose X;
      X.p = d * Vec3::Unit(axis);
      EXPECT_NEAR(perram_wertheim(A, B, X).alpha, d / (A[axis] + B[axis]), 1e-15 * d) << "axis " << axis;
      // Body 2 turned 90 degrees about z: its y axis now lies along body 1's x.
      X.R = rot_z(M_PI / 2);
      const double b2 = axis == 0 ? B[1] : axis == 1 ? B[0] : B[2];
      EXPECT_NEAR(perram_wertheim(A, B, X).alpha, d / (A[axis] + b2), 1e-15 * d) << "turned, axis " << axis;
    }
  }
}

TEST(PerramWertheim, ContactPointOnBothScaledSurfacesAndGradientMatchesFiniteDifferences) {
  const Vec3 A(0.5, 1.0, 1.5), B(0.8, 0.6, 1.1);
  std::mt19937_64 rng(12);
  for (int k = 0; k < 200; ++k) {
    const Pose X = random_pose(rng, 0.1, 10.0);
    const OracleAnswer o = perram_wertheim(A, B, X);
    ASSERT_TRUE(o.ok);
    const Vec3 y1 = o.x_1.cwiseQuotient(A) / o.alpha;
    const Vec3 y2 = (X.R.transpose() * (o.x_1 - X.p)).cwiseQuotient(B) / o.alpha;
    EXPECT_NEAR(y1.norm(), 1.0, 1e-12);
    EXPECT_NEAR(y2.norm(), 1.0, 1e-12);
    // alpha* is homogeneous of degree 1 in r: d alpha/dr . r = alpha.
    EXPECT_NEAR(o.dalpha_dr.dot(X.p), o.alpha, 1e-12 * o.alpha);
    const double h = 1e-6 * X.p.norm();
    for (int i = 0; i < 3; ++i) {
      Pose Xp = X, Xm = X;
      Xp.p[i] += h;
      Xm.p[i] -= h;
      const double fd = (perram_wertheim(A, B, Xp).alpha - perram_wertheim(A, B, Xm).alpha) / (2 * h);
      EXPECT_NEAR(o.dalpha_dr[i], fd, 1e-7 * (1.0 + std::abs(fd)));
    }
  }
}

// iDCOL on exact ellipsoids (n = 1, no smoothing) must agree with PW to its
// solver tolerance.
TEST(PerramWertheim, AgreesWithIdcolOnExactEllipsoids) {
  const Superellipsoid E1(0.5, 1.0, 1.5, 1.0), E2(1.2, 0.4, 0.7, 1.0);
  std::mt19937_64 rng(13);
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const Pose X = random_pose(rng, 0.05, 30.0);
    const SolveResult s = solve(E1, E2, X);
    ASSERT_TRUE(s.converged()) << to_string(s.status) << " k=" << k;
    const OracleAnswer o = perram_wertheim(Vec3(0.5, 1.0, 1.5), Vec3(1.2, 0.4, 0.7), X);
    const double rel = std::abs(s.alpha - o.alpha) / o.alpha;
    worst = std::max(worst, rel);
    EXPECT_LT(rel, 1e-9) << "k=" << k;
    EXPECT_LT((s.x_1 - o.x_1).norm() / X.p.norm(), 1e-7) << "k=" << k;
  }
  std::printf("PW vs iDCOL on exact ellipsoids: worst relative alpha error %.3g over 2000 poses\n", worst);
  measured("worst_rel_alpha_err", worst);
}

// Axis-aligned boxes: alpha* = max_k |r_k| / (h1_k + h2_k).
TEST(PolytopeLP, AxisAlignedBoxesMatchClosedForm) {
  const Vec3 h1(0.6, 0.9, 0.4), h2(0.3, 1.7, 0.25);
  const auto P1 = std::get<ExactPolytope>(to_exact(test::box(h1[0], h1[1], h1[2], 50.0)));
  const auto P2 = std::get<ExactPolytope>(to_exact(test::box(h2[0], h2[1], h2[2], 50.0)));
  std::mt19937_64 rng(21);
  for (int k = 0; k < 300; ++k) {
    Pose X = random_pose(rng, 0.01, 50.0);
    X.R.setIdentity();
    const OracleAnswer o = polytope_lp(P1, P2, X);
    ASSERT_TRUE(o.ok) << o.error;
    const double expect = X.p.cwiseAbs().cwiseQuotient(h1 + h2).maxCoeff();
    EXPECT_NEAR(o.alpha, expect, 4e-16 * expect) << "k=" << k;
    // A quarter turn about z swaps body 2's x and y extents.
    X.R = rot_z(M_PI / 2);
    const double expect2 = X.p.cwiseAbs().cwiseQuotient(h1 + Vec3(h2[1], h2[0], h2[2])).maxCoeff();
    EXPECT_NEAR(polytope_lp(P1, P2, X).alpha, expect2, 1e-15 * expect2) << "turned, k=" << k;
  }
}

TEST(PolytopeLP, ContactPointIsFeasibleAndTouchesBoth) {
  const auto P = std::get<ExactPolytope>(to_exact(test::paper_poly()));
  std::mt19937_64 rng(22);
  for (int k = 0; k < 300; ++k) {
    const Pose X = random_pose(rng, 0.05, 20.0);
    const OracleAnswer o = polytope_lp(P, P, X);
    ASSERT_TRUE(o.ok) << o.error;
    double m1 = -1e300, m2 = -1e300;
    for (size_t i = 0; i < P.normals.size(); ++i) {
      m1 = std::max(m1, P.normals[i].dot(o.x_1) - o.alpha * P.offsets[i]);
      m2 = std::max(m2, P.normals[i].dot(X.R.transpose() * (o.x_1 - X.p)) - o.alpha * P.offsets[i]);
    }
    // Both max-constraints are <= 0 and at least one is active ... in fact
    // at the optimum both bodies are touched.
    const double tol = 1e-13 * std::max(1.0, X.p.norm());
    EXPECT_NEAR(m1, 0.0, tol) << "k=" << k;
    EXPECT_NEAR(m2, 0.0, tol) << "k=" << k;
  }
}

// The smoothing bracket: iDCOL's smooth alpha* lies in
// [alpha_exact, alpha_exact / (1 - delta)].
void check_bracket(const Shape& s1, const Shape& s2, int n, uint64_t seed, double* tightness = nullptr) {
  const BaselinePair pair(s1, s2);
  std::mt19937_64 rng(seed);
  int failed_solves = 0;
  double worst_pos = 0.0;
  for (int k = 0; k < n; ++k) {
    const Pose X = random_pose(rng, 0.05, 20.0);
    const SolveResult s = solve(s1, s2, X);
    if (!s.converged()) {
      ++failed_solves;
      continue;
    }
    const OracleAnswer o = pair.oracle(X);
    ASSERT_TRUE(o.ok) << o.error;
    const auto br = pair.smoothing_bracket(o);
    // Every oracle here is exact or a certified bracket; the slack is the
    // solver's (its relative KKT tolerance, 1e-10): at beta >= 50 a face of
    // the smooth body is within 1e-11 of P's.
    const double slack = 1e-10 * o.alpha;
    EXPECT_GE(s.alpha, br[0] - slack) << pair.name() << " k=" << k << std::setprecision(17) << " alpha " << s.alpha << " bracket " << br[0] << " " << br[1] << " exact " << o.alpha_lo << " " << o.alpha_hi;
    EXPECT_LE(s.alpha, br[1] + slack) << pair.name() << " k=" << k;
    worst_pos = std::max(worst_pos, (s.alpha - br[0]) / (br[1] - br[0]));
  }
  EXPECT_EQ(failed_solves, 0);
  if (tightness) *tightness = worst_pos;
}

TEST(SmoothingBracket, IdcolPolyPolyBeta20) {
  double t;
  check_bracket(test::paper_poly(20.0), test::paper_poly(20.0), 1000, 31, &t);
  std::printf("Poly-Poly beta=20: worst position inside the bracket %.3f\n", t);
}
TEST(SmoothingBracket, IdcolPolyPolyBeta1000) {
  double t;
  check_bracket(test::paper_poly(1000.0), test::box(0.6, 0.9, 0.4, 1000.0), 1000, 32, &t);
  std::printf("Poly-Box beta=1000: worst position inside the bracket %.3f\n", t);
}
TEST(SmoothingBracket, IdcolPolyEllipBeta20) {
  double t;
  check_bracket(test::paper_poly(20.0), Superellipsoid(0.5, 1.0, 1.5, 1.0), 300, 33, &t);
  std::printf("Poly-Ellip beta=20: worst position inside the bracket %.3f\n", t);
}
TEST(SmoothingBracket, IdcolEllipPolyDifferentL) {
  check_bracket(Superellipsoid(0.5, 1.0, 1.5, 1.0), test::paper_poly(50.0), 300, 34);
  // L != 1: the shrink scales with L.
  const double s = 1.0 / std::sqrt(3.0);
  const SmoothPolytope P(test::octa_normals(), {s, s, s, s, 5.0 / 3 * s, 5.0 / 3 * s, 5.0 / 3 * s, 5.0 / 3 * s},
                         40.0, 2.0);
  check_bracket(P, test::paper_poly(20.0), 300, 35);
}

// Bisection over FCL's boolean against PW: measures the bisection oracle.
TEST(Bisection, OverFclBooleanMatchesPerramWertheim) {
#ifndef IDCOL_BASELINES_WITH_FCL
  GTEST_SKIP() << "built without FCL";
#else
  const Superellipsoid E1(0.5, 1.0, 1.5, 1.0), E2(1.2, 0.4, 0.7, 1.0);
  const BaselinePair pair(E1, E2);
  const FclPair fcl(pair.exact1(), pair.exact2());
  std::mt19937_64 rng(41);
  double worst = 0.0;
  for (int k = 0; k < 200; ++k) {
    const Pose X = random_pose(rng, 0.05, 20.0);
    const OracleAnswer pw = pair.oracle(X);
    const auto b = alpha_bounds(pair.exact1(), pair.exact2(), X.p);
    const OracleAnswer bi =
        bisect_alpha([&](const Vec3& rs) { return fcl.intersects(Pose{X.R, rs}); }, X.p, b[0], b[1]);
    ASSERT_TRUE(bi.ok);
    const double rel = std::abs(bi.alpha - pw.alpha) / pw.alpha;
    worst = std::max(worst, rel);
    EXPECT_LT(rel, 1e-9) << "k=" << k;
  }
  std::printf("bisection(FCL boolean) vs PW: worst relative error %.3g\n", worst);
  measured("worst_rel_alpha_err", worst);
#endif
}

// Core's certified radii against the independent support functions (not by
// sampling, which underestimates a maximum): R_out >= max_u h_outer(u) >=
// max_u h(u) and R_in <= min_u h_inner(u) <= min_u h(u), with max/min of h in
// closed form (geom::radii). For the smooth polytope, whose inner body is
// conservative, the ball of radius R_in is certified directly instead: on it
// a_i.y <= R_in, so phi <= smax_beta((R_in - b_i)/L), which must be <= 0.
TEST(CoreShapes, RadiiAreCertifiedBySupportFunctions) {
  int checked = 0;
  for (const auto& [name, s] : test::catalogue()) {
    const Radii r = radii(s);
    const geom::Desc d = to_desc(s);
    const double hmax = geom::radii(geom::outer_body(d))[1];
    EXPECT_GE(r.outer, hmax * (1 - 1e-15)) << name << ": outer radius below the body's farthest point";
    EXPECT_GT(r.inner, 0.0) << name;
    if (const auto* p = std::get_if<geom::PolytopeDesc>(&d)) {
      long double m = -1e300L, sum = 0.0L;
      for (double b : p->offsets) m = std::max(m, static_cast<long double>((r.inner - b) / p->L));
      for (double b : p->offsets) sum += std::exp(static_cast<long double>(p->beta) * ((r.inner - b) / p->L - m));
      EXPECT_LE(static_cast<double>(m + std::log(sum) / p->beta), 1e-15) << name << ": inner ball leaves the body";
    } else {
      EXPECT_LE(r.inner, geom::radii(geom::inner_body(d))[0] * (1 + 1e-15)) << name << ": inner ball leaves the body";
    }
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(test::catalogue().size()));
}

// core's Solver.HardCasesConvergeToGenuineAnswers checks its answers with
// core's own eval. The same hard pairs here, checked with nothing of the
// solver or of core's shapes: witness points on the surfaces and opposite
// normals by the independent phi and grad phi, and alpha* inside the
// independent bracket (the LP's smoothing bracket for two polytopes, the
// support-function bracket otherwise).
TEST(IndependentChecks, HardCasesAgreeWithIndependentGeometry) {
  std::mt19937_64 rng(5);
  const std::vector<std::pair<Shape, Shape>> hard = {
      {Superellipsoid(1e-3, 2e-3, 1.5e-3, 1.0), Superellipsoid(1e3, 2e3, 1.5e3, 1.0)},
      {Superellipsoid(1e3, 2e3, 1.5e3, 2.0), Sphere(1e-3)},
      {test::box(1e-3, 2e-3, 1e-3, 2e4), Superellipsoid(1e3, 2e3, 1.5e3, 1.0)},
      {test::paper_poly(1000.0), test::paper_poly(1000.0)},
      {test::paper_poly(1000.0), Superellipsoid(0.5, 1.0, 1.5, 8.0)},
      {SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 1000.0), Superellipsoid(0.5, 1.0, 1.5, 64.0)},
  };
  int checked = 0;
  double worst_surface = 0.0, worst_normal = 0.0, worst_outside = 0.0;
  for (std::size_t h = 0; h < hard.size(); ++h) {
    const auto& [a, b] = hard[h];
    const geom::Desc da = to_desc(a), db = to_desc(b);
    const double L = radii(a).outer + radii(b).outer, rin = std::min(radii(a).inner, radii(b).inner);
    const bool lp = std::holds_alternative<SmoothPolytope>(a) && std::holds_alternative<SmoothPolytope>(b);
    const ExactShape xa = lp ? to_exact(a) : ExactShape{}, xb = lp ? to_exact(b) : ExactShape{};
    const SupportOracle so(da, db);
    for (int i = 0; i < 100; ++i) {
      const Pose X = test::random_pose(rng, 1e-3 * rin, 3 * L);
      const SolveResult r = solve(a, b, X);
      ASSERT_TRUE(r.converged()) << "hard case " << h << " pose " << i << ": " << to_string(r.status);
      const geom::PhiGrad e1 = geom::eval(da, r.x_1 / r.alpha), e2 = geom::eval(db, X.R.transpose() * (r.x_1 - X.p) / r.alpha);
      const double s1 = std::abs(static_cast<double>(e1.phi)) / e1.grad.norm() / L;
      const double s2 = std::abs(static_cast<double>(e2.phi)) / e2.grad.norm() / L;
      const double nerr = (e1.grad.normalized() + X.R * e2.grad.normalized()).norm();
      std::array<double, 2> br{};
      if (lp) {
        const OracleAnswer o = polytope_lp(std::get<ExactPolytope>(xa), std::get<ExactPolytope>(xb), X);
        ASSERT_TRUE(o.ok) << o.error;
        br = smoothing_bracket(xa, xb, o.alpha_lo, o.alpha_hi);
      } else {
        const AlphaBracket o = so.bracket(X);
        ASSERT_TRUE(o.ok) << o.error;
        br = {o.lo, o.hi};
      }
      const double out = std::max({0.0, br[0] / r.alpha - 1.0, r.alpha / br[1] - 1.0});
      EXPECT_LT(std::max(s1, s2), 1e-8) << "hard case " << h << " pose " << i;
      EXPECT_LT(nerr, 1e-7) << "hard case " << h << " pose " << i;
      EXPECT_LT(out, 1e-9) << "hard case " << h << " pose " << i << ": alpha " << r.alpha << " bracket " << br[0] << " "
                           << br[1];
      worst_surface = std::max({worst_surface, s1, s2});
      worst_normal = std::max(worst_normal, nerr);
      worst_outside = std::max(worst_outside, out);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 600);
  std::printf("hard cases, independent checks: surface %.2g, normals %.2g, outside the bracket by %.2g\n", worst_surface,
              worst_normal, worst_outside);
}

// The support-function oracle (Poly-Ellip's oracle) against bisection over
// FCL's boolean on the same exact bodies: two methods sharing no code.
TEST(SupportOracle, PolyEllipAgreesWithBisectionOverFcl) {
#ifndef IDCOL_BASELINES_WITH_FCL
  GTEST_SKIP() << "built without FCL";
#else
  const BaselinePair pair(test::paper_poly(20.0), Superellipsoid(0.5, 1.0, 1.5, 1.0));
  const FclPair fcl(pair.exact1(), pair.exact2());
  ASSERT_EQ(oracle_for(test::paper_poly(20.0), Superellipsoid(0.5, 1.0, 1.5, 1.0)), OracleMethod::SupportFunction);
  std::mt19937_64 rng(42);
  double worst_out = 0.0, worst_width = 0.0;
  int checked = 0;
  for (int k = 0; k < 300; ++k) {
    const Pose X = random_pose(rng, 0.05, 20.0);
    const OracleAnswer o = pair.oracle(X);
    ASSERT_TRUE(o.ok) << o.error;
    const auto b = alpha_bounds(pair.exact1(), pair.exact2(), X.p);
    const OracleAnswer bi =
        bisect_alpha([&](const Vec3& rs) { return fcl.intersects(Pose{X.R, rs}); }, X.p, b[0], b[1]);
    ASSERT_TRUE(bi.ok);
    worst_out = std::max({worst_out, o.alpha_lo / bi.alpha - 1.0, bi.alpha / o.alpha_hi - 1.0});
    worst_width = std::max(worst_width, o.alpha_hi / o.alpha_lo - 1.0);
    ++checked;
  }
  EXPECT_EQ(checked, 300);
  EXPECT_LT(worst_out, 1e-9);  // FCL's boolean at gjk_tolerance 1e-12
  EXPECT_LT(worst_width, 1e-11);  // measured 4.5e-13
  std::printf("Poly-Ellip support bracket: widest %.3g, bisection(FCL) outside it by %.3g\n", worst_width, worst_out);
  measured("widest_rel_bracket", worst_width);
  measured("bisection_outside", std::max(0.0, worst_out));
#endif
}

}  // namespace
}  // namespace idcol::baselines
