// The certified early exit SolverOptions::alpha_max: the lower bound on
// alpha* it returns with SolveStatus::Separated never exceeds the true alpha*,
// checked against oracles that share no code with core (Perram-Wertheim for
// ellipsoids, the support-function bracket for every family).
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "idcol/derivatives.hpp"
#include "idcol/shape_derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol_baselines/baselines.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/support_oracle.hpp"
#include "test_util.hpp"

namespace idcol::baselines {
namespace {

/// alpha_max below every possible bound: every valid, non-concentric pose
/// comes back Separated, carrying the bound.
SolverOptions bound_only() {
  SolverOptions o;
  o.alpha_max = std::numeric_limits<double>::min();
  return o;
}

TEST(AlphaMax, ValidationNamesTheOptionAndValue) {
  for (const double bad : {std::nan(""), 0.0, -1.0, -std::numeric_limits<double>::infinity()}) {
    SolverOptions o;
    o.alpha_max = bad;
    try {
      o.validate();
      ADD_FAILURE() << "alpha_max = " << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("alpha_max"), std::string::npos) << msg;
      EXPECT_NE(msg.find(std::isnan(bad) ? "nan" : "got"), std::string::npos) << msg;
    }
  }
  SolverOptions o;
  EXPECT_TRUE(std::isinf(o.alpha_max));  // off by default
  EXPECT_NO_THROW(o.validate());
  o.alpha_max = 1.0;
  EXPECT_NO_THROW(o.validate());
  EXPECT_THROW(ContactPair(Sphere(1.0), Sphere(1.0), [] {
                 SolverOptions b;
                 b.alpha_max = std::nan("");
                 return b;
               }()),
               std::invalid_argument);
}

TEST(AlphaMax, SpheresGiveTheClosedFormExactly) {
  std::mt19937_64 rng(3);
  int checked = 0;
  for (int k = 0; k < 1000; ++k) {
    const double R1 = 0.2 + 0.001 * k, R2 = 1.3;
    const Pose X = test::random_pose(rng, 0.01, 100.0);
    const SolveResult r = solve(Sphere(R1), Sphere(R2), X, bound_only());
    ASSERT_EQ(r.status, SolveStatus::Separated);
    const double exact = X.p.norm() / (R1 + R2);
    EXPECT_LE(r.alpha, exact);
    EXPECT_GE(r.alpha, exact * (1.0 - 1e-12));
    ++checked;
  }
  EXPECT_EQ(checked, 1000);
}

// 10^5 ellipsoid poses against Perram-Wertheim: the bound is below alpha*,
// and above the bound from the outer radii alone (so it is not vacuous).
TEST(AlphaMax, EllipsoidBoundNeverExceedsPerramWertheim) {
  const Vec3 ax1(0.5, 1.0, 1.5), ax2(0.3, 0.9, 2.0);
  const Superellipsoid e1(ax1[0], ax1[1], ax1[2], 1.0), e2(ax2[0], ax2[1], ax2[2], 1.0);
  const double radii_ratio = (0.5 + 0.3) / (1.5 + 2.0);  // alpha*_lower / alpha* >= r_in / r_out
  std::mt19937_64 rng(17);
  const SolverOptions o = bound_only();
  int checked = 0;
  double worst = 0.0, loosest = 1.0;
  for (int k = 0; k < 100000; ++k) {
    const Pose X = test::random_pose(rng, 0.05, 20.0);
    const OracleAnswer pw = perram_wertheim(ax1, ax2, X);
    ASSERT_TRUE(pw.ok) << pw.error;
    const SolveResult r = solve(e1, e2, X, o);
    ASSERT_EQ(r.status, SolveStatus::Separated) << k;
    const double q = r.alpha / pw.alpha;
    worst = std::max(worst, q);
    loosest = std::min(loosest, q);
    ASSERT_LE(q, 1.0 + 1e-12) << "pose " << k << ": bound " << r.alpha << " > alpha* " << pw.alpha;
    ASSERT_GE(q, radii_ratio * (1.0 - 1e-12)) << k;
    ++checked;
  }
  EXPECT_EQ(checked, 100000);
  // Two-sided: the bound is attained (contact on the line of centres) to
  // within a few percent somewhere in the sample.
  EXPECT_GT(worst, 0.97);
  RecordProperty("bound_over_alpha_max", std::to_string(worst));
  RecordProperty("bound_over_alpha_min", std::to_string(loosest));
}

// Every family, every pair of the catalogue, against the support-function
// bracket's upper end (a certified upper bound on the smooth pair's alpha*).
TEST(AlphaMax, BoundNeverExceedsTheSupportOracleForEveryPair) {
  const auto cat = test::catalogue();
  const SolverOptions o = bound_only();
  std::mt19937_64 rng(29);
  SupportOracleOptions so;
  so.covering = 100;
  int checked = 0;
  for (std::size_t i = 0; i < cat.size(); ++i)
    for (std::size_t j = 0; j < cat.size(); ++j) {
      const SupportOracle oracle(to_desc(cat[i].shape), to_desc(cat[j].shape), so);
      for (int k = 0; k < 40; ++k) {
        const Pose X = test::random_pose(rng, 0.05, 20.0);
        const AlphaBracket b = oracle.bracket(X);
        ASSERT_TRUE(b.ok) << b.error;
        const SolveResult r = solve(cat[i].shape, cat[j].shape, X, o);
        ASSERT_EQ(r.status, SolveStatus::Separated);
        EXPECT_LE(r.alpha, b.hi * (1.0 + 1e-12)) << cat[i].name << "-" << cat[j].name << " pose " << k;
        EXPECT_GT(r.alpha, 0.0);
        ++checked;
      }
    }
  EXPECT_EQ(checked, static_cast<int>(cat.size() * cat.size() * 40));
}

// alpha_max never turns a pose with alpha* <= alpha_max into Separated, and
// otherwise leaves the solve as it was.
TEST(AlphaMax, ExitOnlyAboveTheThreshold) {
  const Superellipsoid e(0.5, 1.0, 1.5, 1.0);
  SolverOptions o;
  o.alpha_max = 1.0;
  std::mt19937_64 rng(5);
  int separated = 0, solved = 0;
  for (int k = 0; k < 5000; ++k) {
    const Pose X = test::random_pose(rng, 0.3, 6.0);
    const OracleAnswer pw = perram_wertheim(Vec3(0.5, 1.0, 1.5), Vec3(0.5, 1.0, 1.5), X);
    ASSERT_TRUE(pw.ok);
    const SolveResult r = solve(e, e, X, o);
    if (r.status == SolveStatus::Separated) {
      EXPECT_GT(pw.alpha, 1.0) << k;
      EXPECT_GT(r.alpha, 1.0);
      EXPECT_LE(r.alpha, pw.alpha * (1.0 + 1e-12));
      ++separated;
    } else {
      ASSERT_EQ(r.status, SolveStatus::Converged) << k;
      const SolveResult full = solve(e, e, X);
      EXPECT_EQ(r.alpha, full.alpha);
      EXPECT_EQ(r.iterations, full.iterations);
      ++solved;
    }
  }
  EXPECT_GT(separated, 500);
  EXPECT_GT(solved, 500);
}

TEST(AlphaMax, SeparatedCarriesNoSolutionAndRefusesDerivatives) {
  const Superellipsoid e(0.5, 1.0, 1.5, 1.0);
  SolverOptions o;
  o.alpha_max = 1.0;
  o.derivatives = true;
  WarmStart warm;
  const Pose X{Mat3::Identity(), Vec3(10.0, 0.0, 0.0)};
  const SolveResult r = solve(e, e, X, o, &warm);
  ASSERT_EQ(r.status, SolveStatus::Separated);
  EXPECT_STREQ(to_string(r.status), "separated");
  EXPECT_FALSE(r.converged());
  // Both supports along the x axis are 0.5 and the contact lies on that axis,
  // so the bound is alpha* = 10 itself.
  EXPECT_LE(r.alpha, 10.0);
  EXPECT_GE(r.alpha, 10.0 * (1.0 - 1e-12));
  EXPECT_EQ(r.x_1, Vec3::Zero());
  EXPECT_EQ(r.lambda1, 0.0);
  EXPECT_EQ(r.lambda2, 0.0);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_FALSE(r.internal.factorised);
  EXPECT_FALSE(warm.valid);
  auto names_status = [](const std::invalid_argument& ex) { return std::string(ex.what()).find("Separated") != std::string::npos; };
  int thrown = 0;
  auto expect_throw = [&](auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& ex) {
      EXPECT_TRUE(names_status(ex)) << ex.what();
      ++thrown;
    }
  };
  expect_throw([&] { alpha_gradient(r); });
  expect_throw([&] { gap_gradient(r); });
  expect_throw([&] { solution_sensitivity(r); });
  expect_throw([&] { contact_kinematics(r); });
  expect_throw([&] { conditioning(r); });
  expect_throw([&] { contact_wrench(r, HertzModel{}); });
  expect_throw([&] { shape_sensitivity(r, e, e, 1); });
  EXPECT_EQ(thrown, 7);
}

}  // namespace
}  // namespace idcol::baselines
