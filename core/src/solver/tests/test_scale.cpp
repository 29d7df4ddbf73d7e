// alpha* is scale-free: scaling both bodies and r by s leaves it unchanged,
// and x scales with s. Oracle: the same problem at s = 1 (covariance under
// uniform scaling), for every family pair and every decade of the double
// range. Also the shapes that only one body makes extreme, warm starts and
// derivatives of a rescaled problem.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

namespace idcol {
namespace {

/// Every family (and both ways of building a polytope) at size s, built
/// through the public constructors from parameters multiplied by s.
struct Family {
  const char* name;
  std::function<Shape(double)> make;
};

std::vector<Family> families() {
  return {
      {"sphere", [](double s) { return Shape(Sphere(0.8 * s)); }},
      {"ellipsoid", [](double s) { return Shape(Superellipsoid(0.5 * s, 1.0 * s, 1.5 * s, 1.0)); }},
      {"superellipsoid", [](double s) { return Shape(Superellipsoid(1.2 * s, 0.7 * s, 0.9 * s, 2.5)); }},
      {"cylinder", [](double s) { return Shape(SuperellipticCylinder(0.6 * s, 1.1 * s, 4.0)); }},
      {"polytope",
       [](double s) {
         const double c = 1.0 / std::sqrt(3.0);
         std::vector<double> b = {c, c, c, c, 5.0 / 3.0 * c, 5.0 / 3.0 * c, 5.0 / 3.0 * c, 5.0 / 3.0 * c};
         for (double& v : b) v *= s;
         return Shape(SmoothPolytope(test::octa_normals(), b, 20.0, s));
       }},
      {"polytope_hull",
       [](double s) {
         std::vector<Vec3> V = {{0.9, 0.1, -0.3}, {-0.7, 0.8, 0.2}, {-0.4, -0.9, 0.5}, {0.2, 0.3, 1.1},
                                {0.1, -0.2, -1.0}, {0.6, -0.7, 0.4}, {-0.8, -0.1, -0.6}};
         for (Vec3& v : V) v *= s;
         return Shape(SmoothPolytope::from_vertices(V, 10.0, 0.5 * s));
       }},
      {"cone", [](double s) { return Shape(SmoothTruncatedCone(1.2 * s, 0.2 * s, 0.8 * s, 1.0 * s, 15.0)); }},
  };
}

struct Outcome {
  int compared = 0, wrong = 0, unconverged = 0;
};

/// Solve the pair at scale 10^e for e = -300..300 against the unit answer:
/// every decade converges, to alpha within 1e-12 and x within 1e-10.
Outcome sweep(const Family& f1, const Family& f2, const Pose& X1) {
  Outcome out;
  const SolveResult ref = solve(f1.make(1.0), f2.make(1.0), X1);
  EXPECT_TRUE(ref.converged()) << f1.name << "-" << f2.name;
  if (!ref.converged()) return out;
  for (int e = -300; e <= 300; ++e) {
    const double s = std::pow(10.0, e);
    const Pose X{X1.R, X1.p * s};
    const SolveResult r = solve(f1.make(s), f2.make(s), X);
    ++out.compared;
    if (!r.converged()) {
      ++out.unconverged;
      ADD_FAILURE() << f1.name << "-" << f2.name << " at s = 1e" << e << ": " << to_string(r.status);
      continue;
    }
    const double da = std::abs(r.alpha - ref.alpha) / ref.alpha;
    const double dx = (r.x_1 / s - ref.x_1).norm() / std::max(1.0, ref.x_1.norm());
    if (!(da <= 1e-12) || !(dx <= 1e-10)) {
      ++out.wrong;
      ADD_FAILURE() << f1.name << "-" << f2.name << " at s = 1e" << e << ": alpha " << r.alpha << " vs " << ref.alpha
                    << " (rel " << da << "), x rel " << dx;
    }
  }
  return out;
}

TEST(Scale, EveryFamilyPairAtEveryDecade) {
  const auto fam = families();
  std::mt19937_64 rng(20261126);
  int compared = 0, wrong = 0, unconverged = 0;
  for (size_t i = 0; i < fam.size(); ++i)
    for (size_t j = i; j < fam.size(); ++j)
      for (int k = 0; k < 2; ++k) {
        const Pose X = test::random_pose(rng, 0.6, 4.0);
        const Outcome o = sweep(fam[i], fam[j], X);
        compared += o.compared;
        wrong += o.wrong;
        unconverged += o.unconverged;
      }
  std::printf("scale sweep: %d solves, %d wrong, %d unconverged\n", compared, wrong, unconverged);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(unconverged, 0);
}

/// The reproduction: alpha* of two rotated ellipsoids at every scale.
TEST(Scale, RotatedEllipsoidsKeepAlpha) {
  for (double s : {1.0, 1e-150, 1e-155, 1e-160, 1e-300, 1e160, 1e300}) {
    const Superellipsoid e(0.5 * s, 1.0 * s, 1.5 * s, 1.0);
    Pose X;
    X.R = Eigen::AngleAxisd(0.7, Vec3::UnitZ()).toRotationMatrix();
    X.p = Vec3(1.0, 0.4, 0.0) * s;
    const SolveResult r = solve(e, e, X);
    ASSERT_TRUE(r.converged()) << "s = " << s << ": " << to_string(r.status);
    EXPECT_NEAR(r.alpha, 0.92579049081126, 1e-13) << "s = " << s;
  }
}

/// Exactly one power of two apart, the answers are bit-identical: the
/// rescaled solve is the unit solve.
TEST(Scale, PowerOfTwoScalesAreBitIdentical) {
  const Superellipsoid e1(0.5, 1.0, 1.5, 1.0), e2(1.2, 0.7, 0.9, 2.5);
  Pose X;
  X.R = Eigen::AngleAxisd(0.7, Vec3(0.2, 0.3, 1.0).normalized()).toRotationMatrix();
  X.p = Vec3(1.0, 0.4, -0.3);
  const SolveResult ref = solve(e1, e2, X);
  ASSERT_TRUE(ref.converged());
  for (int k : {-1000, -600, -200, 200, 600, 1000}) {
    const double f = std::ldexp(1.0, k);
    const SolveResult r = solve(e1.scaled(f), e2.scaled(f), Pose{X.R, X.p * f});
    ASSERT_TRUE(r.converged()) << "2^" << k;
    EXPECT_EQ(r.alpha, ref.alpha) << "2^" << k;
    EXPECT_EQ(r.x_1 / f, ref.x_1) << "2^" << k;
    EXPECT_EQ(r.lambda1, ref.lambda1);
    EXPECT_EQ(r.iterations, ref.iterations);
  }
}

/// A warm-started ContactPair along a motion: the same answers at 1e-200
/// and 1e200 as at unit scale, and warm starts that still work.
TEST(Scale, WarmStartedPairAtExtremeScales) {
  const auto fam = families();
  for (double s : {1e-200, 1e200}) {
    ContactPair unit(fam[2].make(1.0), fam[6].make(1.0));
    ContactPair tiny(fam[2].make(s), fam[6].make(s));
    int warm_ok = 0;
    for (int q = 0; q < 50; ++q) {
      const double t = 0.02 * q;
      Pose X;
      X.R = Eigen::AngleAxisd(t, Vec3(0.3, -0.5, 1.0).normalized()).toRotationMatrix();
      X.p = Vec3(1.5 + 0.3 * std::cos(t), 0.8 * std::sin(t), 0.4);
      const SolveResult a = unit.solve(X);
      const SolveResult b = tiny.solve(Pose{X.R, X.p * s});
      ASSERT_TRUE(a.converged() && b.converged()) << q;
      EXPECT_NEAR(b.alpha, a.alpha, 1e-12 * a.alpha) << q;
      if (b.warm_started && !b.warm_start_fell_back) ++warm_ok;
    }
    EXPECT_EQ(warm_ok, 49) << "s = " << s;  // every query after the first, none fell back to cold
  }
}

/// Derivatives of a rescaled solve are those of the unit solve, scaled by
/// their units: d alpha / d v (rotation part first: xi = (w, v)) scales as
/// 1/s, d alpha / d w not at all; d gap / d v not at all, d gap / d w as s.
TEST(Scale, DerivativesScaleWithTheirUnits) {
  const auto fam = families();
  const SolverOptions o = test::with_derivatives();
  Pose X;
  X.R = Eigen::AngleAxisd(0.4, Vec3(1.0, 0.2, -0.3).normalized()).toRotationMatrix();
  X.p = Vec3(1.3, 0.5, -0.6);
  for (size_t i : {1, 3, 5}) {
    const SolveResult ref = solve(fam[i].make(1.0), fam[6].make(1.0), X, o);
    ASSERT_TRUE(ref.converged());
    const Row6 ga = alpha_gradient(ref), gg = gap_gradient(ref);
    for (double s : {1e-100, 1e-200, 1e100, 1e200}) {
      const SolveResult r = solve(fam[i].make(s), fam[6].make(s), Pose{X.R, X.p * s}, o);
      ASSERT_TRUE(r.converged());
      // Within 1e+-150 the curvatures are doubles in the caller's units, and
      // the derivatives must be right; beyond, right or flagged.
      const bool reliable = conditioning(r).reliable;
      if (s >= 1e-150 && s <= 1e150) EXPECT_TRUE(reliable) << fam[i].name << " s = " << s;
      if (!reliable) continue;
      const Row6 a = alpha_gradient(r), g = gap_gradient(r);
      for (int c = 0; c < 6; ++c) {
        const double ua = c < 3 ? 1.0 : 1.0 / s, ug = c < 3 ? s : 1.0;
        EXPECT_NEAR(a[c] / ua, ga[c], 1e-8 * ga.norm()) << fam[i].name << " s = " << s << " col " << c;
        EXPECT_NEAR(g[c] / ug, gg[c], 1e-8 * gg.norm()) << fam[i].name << " s = " << s << " col " << c;
      }
      const ContactKinematics k = contact_kinematics(r), k1 = contact_kinematics(ref);
      EXPECT_NEAR(k.gap / s, k1.gap, 1e-10 * std::abs(k1.gap) + 1e-12);
      EXPECT_LT((k.nhat_1 - k1.nhat_1).norm(), 1e-10);
    }
  }
}

/// One body extreme, the other not: nothing to rescale, but the answer must
/// be right or not Converged. A unit cube rounded over L = 1e-160 (beta / L^2
/// overflows) against a unit sphere: the exact cube's alpha* is 1.5359; at
/// L <= 1e-155 the solve used to report Converged 1.66502.
TEST(Scale, ExtremeRoundingIsRightOrNotConverged) {
  std::vector<Vec3> cube;
  for (int i = 0; i < 8; ++i) cube.push_back(Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  Pose X;
  X.p = Vec3(1.0, 2.0, 3.0);
  const double hard = 5.0 - std::sqrt(12.0);  // the exact cube: touches on the edge x = alpha, y = z
  for (double L : {1e-3, 1e-10, 1e-100, 1e-150, 1e-155, 1e-160, 1e-300}) {
    const SolveResult r = solve(SmoothPolytope::from_vertices(cube, 20.0, L), Sphere(1.0), X);
    if (r.converged()) EXPECT_NEAR(r.alpha, hard, 2.0 * L * std::log(6.0) / 20.0 * hard + 1e-9) << "L = " << L;
  }
  // A body 1e-160 times the size of its partner.
  for (double s : {1e-100, 1e-160, 1e-200, 1e-300}) {
    const SolveResult r = solve(Sphere(s), Superellipsoid(0.5, 1.0, 1.5, 1.0), Pose{Mat3::Identity(), Vec3(2.0, 0.0, 0.0)});
    if (r.converged()) EXPECT_NEAR(r.alpha, 2.0 / (0.5 + s), 1e-12) << "s = " << s;
  }
}

}  // namespace
}  // namespace idcol
