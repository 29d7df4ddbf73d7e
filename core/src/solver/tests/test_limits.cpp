// Limits of the input: eval at NaN points, the bounds on SolverOptions that
// keep a solve's work finite, and polytopes at the edges of the double range
// (accepted when valid, and an error that says what is wrong when not).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <memory>
#include <random>
#include <sstream>
#include <limits>
#include <string>
#include <vector>

#include "idcol/derivatives.hpp"
#include "idcol/options_fields.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

namespace idcol {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Limits, EvalAtANaNPointIsNaNForEveryFamily) {
  const std::vector<Vec3> points = {{kNaN, 0, 0}, {0, kNaN, 0}, {0, 0, kNaN}, {kNaN, kNaN, kNaN}, {kNaN, 0.3, -0.2}, {0.1, 0.2, kNaN}};
  for (const auto& s : test::catalogue())
    for (const Vec3& y : points) {
      ShapeEval e;
      eval(s.shape, y, e);
      EXPECT_TRUE(std::isnan(e.phi)) << s.name << " at (" << y.transpose() << "): phi = " << e.phi;
    }
  // The frame origin keeps its phi = -1.
  for (const auto& s : test::catalogue()) {
    ShapeEval e;
    eval(s.shape, Vec3::Zero(), e);
    EXPECT_LT(e.phi, 0.0) << s.name;
  }
}

TEST(Limits, EveryCountIsBoundedWithItsOwnError) {
  struct Count {
    const char* field;
    std::function<void(SolverOptions&, int)> set;
    int bound;
  };
  const std::vector<Count> counts = {
      {"max_iterations", [](SolverOptions& o, int v) { o.max_iterations = v; }, SolverOptions::kMaxIterationCount},
      {"max_iterations_extended", [](SolverOptions& o, int v) { o.max_iterations_extended = v; }, SolverOptions::kMaxIterationCount},
      {"max_restarts", [](SolverOptions& o, int v) { o.max_restarts = v; }, SolverOptions::kMaxIterationCount},
      {"max_backtracks", [](SolverOptions& o, int v) { o.max_backtracks = v; }, SolverOptions::kMaxTrialCount},
      {"lm_max_trials", [](SolverOptions& o, int v) { o.lm_max_trials = v; }, SolverOptions::kMaxTrialCount},
      {"lm_stall_limit", [](SolverOptions& o, int v) { o.lm_stall_limit = v; }, SolverOptions::kMaxIterationCount},
      {"barrier_max_stages", [](SolverOptions& o, int v) { o.barrier_max_stages = v; }, SolverOptions::kMaxTrialCount},
      {"barrier_max_newton", [](SolverOptions& o, int v) { o.barrier_max_newton = v; }, SolverOptions::kMaxIterationCount},
  };
  for (const Count& c : counts) {
    for (int v : {c.bound + 1, 2147483647}) {
      SolverOptions o;
      o.max_iterations_extended = SolverOptions::kMaxIterationCount;  // so that max_iterations is judged alone
      c.set(o, v);
      const std::string e = error_of([&] { o.validate(); });
      EXPECT_NE(e.find(std::string("'") + c.field + "'"), std::string::npos) << c.field << ": " << e;
      EXPECT_NE(e.find(std::to_string(v)), std::string::npos) << e;
    }
    SolverOptions o;
    o.max_iterations_extended = SolverOptions::kMaxIterationCount;
    c.set(o, c.bound);
    EXPECT_NO_THROW(o.validate()) << c.field;
  }
}

/// Every field of the list in options_fields.hpp (which options.cpp checks
/// against SolverOptions, member for member) is held by validate() to exactly
/// its listed range: the values just outside each end are refused with a
/// message naming the field, what it must be and the value; the ends
/// themselves (or the nearest double inside an open end) pass. NaN and
/// infinities are refused except where +inf is listed as a value.
TEST(Limits, EveryListedFieldIsHeldToItsRange) {
  ASSERT_EQ(kSolverOptionFieldCount, solver_option_fields().size());
  SolverOptions base;
  base.max_iterations_extended = SolverOptions::kMaxIterationCount;  // so that max_iterations is judged alone
  auto refused = [&](const SolverOptionField& f, const SolverOptions& o, const std::string& value) {
    const std::string e = error_of([&] { o.validate(); });
    EXPECT_NE(e.find(std::string("field '") + f.name + "' must be " + f.expected(o) + ", got " + value), std::string::npos)
        << f.name << " = " << value << ": " << e;
  };
  auto text = [](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  int ranged = 0;
  for (const SolverOptionField& f : solver_option_fields()) {
    SCOPED_TRACE(f.name);
    const OptionRange& r = f.range;
    SolverOptions o = base;
    if (f.flag) {
      for (bool v : {false, true}) {
        o.*f.flag = v;
        EXPECT_NO_THROW(o.validate());
      }
      EXPECT_EQ(f.expected(), "true or false");
      continue;
    }
    ++ranged;
    if (f.integer) {
      const int lo = r.lo_option ? o.*r.lo_option : static_cast<int>(r.lo), hi = static_cast<int>(r.hi);
      for (int v : {lo, hi}) {
        o.*f.integer = v;
        EXPECT_NO_THROW(o.validate()) << v;
      }
      for (int v : {lo - 1, hi + 1}) {
        o.*f.integer = v;
        refused(f, o, std::to_string(v));
      }
      continue;
    }
    const double kInfD = std::numeric_limits<double>::infinity();
    std::vector<double> in, out = {kNaN, -kInfD};
    (std::isinf(r.lo) ? in : (r.lo_open ? out : in)).push_back(r.lo);
    if (std::isfinite(r.lo)) (r.lo_open ? in : out).push_back(std::nextafter(r.lo, r.lo_open ? kInfD : -kInfD));
    if (std::isfinite(r.hi)) {
      (r.hi_open ? out : in).push_back(r.hi);
      (r.hi_open ? in : out).push_back(std::nextafter(r.hi, r.hi_open ? -kInfD : kInfD));
    }
    (r.infinity_ok ? in : out).push_back(kInfD);
    for (double v : in)
      if (!std::isinf(v) || v > 0.0) {
        o.*f.real = v;
        EXPECT_NO_THROW(o.validate()) << text(v);
      }
    for (double v : out) {
      o.*f.real = v;
      std::ostringstream os;
      os << std::setprecision(17) << v;
      refused(f, o, os.str());
    }
  }
  EXPECT_GT(ranged, 0);
}

/// A ratio of 1 + 1e-7 passed and took 29 million iterations; near 1 + 1e-10
/// the stage count overflowed int.
TEST(Limits, ContinuationRatioNearOneIsRejected) {
  for (double v : {1.0 + 1e-7, 1.0 + 1e-9, 1.0 + 1e-10, 1.0 + 1e-15, 1.0099}) {
    SolverOptions o;
    o.continuation_ratio = v;
    const std::string e = error_of([&] { o.validate(); });
    EXPECT_NE(e.find("'continuation_ratio'"), std::string::npos) << e;
    EXPECT_NE(e.find("1.01"), std::string::npos) << e;
  }
  SolverOptions o;
  o.continuation_ratio = SolverOptions::kMinContinuationRatio;
  EXPECT_NO_THROW(o.validate());
}

/// At the smallest ratio, and for the sharpest bodies (n = 1e6, where the
/// stage count at ratio 1.01 is 1389 before the cap), a solve that goes
/// through the continuation stays within its bounded work.
TEST(Limits, ContinuationWorkIsBounded) {
  SolverOptions o;
  o.continuation_ratio = SolverOptions::kMinContinuationRatio;
  o.max_restarts = 0;
  o.support_guess = false;
  o.rounding_continuation = false;
  o.barrier = false;
  o.max_iterations = 1;  // the cold start fails at once, so the continuation runs
  o.max_iterations_extended = 1;
  const SolveResult r = solve(Superellipsoid(0.5, 1.0, 1.5, 1e6), test::box(0.6, 0.9, 0.4, 10.0),
                              Pose{test::random_rotation(*std::make_unique<std::mt19937_64>(7)), Vec3(1.2, 0.9, -0.4)}, o);
  EXPECT_TRUE(r.used_continuation);
  EXPECT_LE(r.iterations, 2 * (3 + 2 * (SolverOptions::kMaxContinuationStages + 8)));
}

/// Nearly concentric bodies, r = d u for d = 1e-1 .. 1e-300, every family
/// against itself and against an ellipsoid: each gap and alpha gradient
/// either matches central differences in the tangent space (X exp(h xi),
/// h relative to d for the translations) or is flagged unreliable. Two
/// ellipsoids along x have d gap / d v_x = 1 exactly; it came out 0.999756
/// (d = 1e-12), 2 (1e-16), -16384 (1e-20), all reported reliable.
TEST(Limits, ConcentricDerivativesAreRightOrFlagged) {
  const SolverOptions o = test::with_derivatives();
  const Vec3 u = Vec3(0.8, 0.36, 0.48);
  const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(0.2, -0.5, 1.0).normalized()).toRotationMatrix();
  int reliable = 0, flagged = 0, wrong = 0;
  auto gap_at = [&](const Shape& a, const Shape& b, const Pose& X) {
    const SolveResult r = solve(a, b, X);
    return r.converged() ? contact_kinematics(r).gap : std::numeric_limits<double>::quiet_NaN();
  };
  const Shape ellipsoid = Superellipsoid(0.5, 1.0, 1.5, 1.0);
  for (const auto& s : test::catalogue())
    for (const Shape* partner : {&s.shape, &ellipsoid})
      for (int e = -1; e >= -300; --e) {
        const double d = std::pow(10.0, e);
        const Pose X{R, d * u};
        const SolveResult r = solve(s.shape, *partner, X, o);
        if (!r.converged()) continue;
        if (!conditioning(r).reliable) {
          ++flagged;
          continue;
        }
        ++reliable;
        const Row6 g = gap_gradient(r), ga = alpha_gradient(r);
        for (int j = 0; j < 6; ++j) {
          const double h = j < 3 ? 1e-5 : 1e-4 * d;
          Vec3 w = Vec3::Zero(), v = Vec3::Zero();
          (j < 3 ? w : v)[j % 3] = h;
          const Pose Xp = X * test::se3_exp(w, v), Xm = X * test::se3_exp(-w, -v);
          const double fd = (gap_at(s.shape, *partner, Xp) - gap_at(s.shape, *partner, Xm)) / (2.0 * h);
          const SolveResult rp = solve(s.shape, *partner, Xp), rm = solve(s.shape, *partner, Xm);
          const double fda = (rp.alpha - rm.alpha) / (2.0 * h);
          const bool ok = std::abs(g[j] - fd) <= 1e-4 * std::max(1.0, g.norm()) && std::abs(ga[j] - fda) <= 1e-4 * ga.norm();
          if (!ok) {
            ++wrong;
            ADD_FAILURE() << s.name << " d = 1e" << e << " column " << j << ": gap " << g[j] << " vs fd " << fd << ", alpha " << ga[j]
                          << " vs fd " << fda;
          }
        }
      }
  std::printf("concentric sweep: %d reliable (checked against FD), %d flagged, %d wrong\n", reliable, flagged, wrong);
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(reliable, 100);  // d = 1e-1 .. 1e-8 of every family: not everything is flagged
}

std::vector<Vec3> cube(double s) {
  std::vector<Vec3> V;
  for (int i = 0; i < 8; ++i) V.push_back(s * Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  return V;
}

/// A valid cube at any scale is a polytope (1e100 was "all 8 points
/// coplanar": its cross products overflowed); its half-spaces are the unit
/// cube's.
TEST(Limits, PolytopeFromVerticesAtAnyScale) {
  for (double s : {1e-300, 1e-160, 1e-100, 1.0, 1e100, 1e160, 1e300}) {
    SCOPED_TRACE(s);
    const SmoothPolytope P = SmoothPolytope::from_vertices(cube(s), 20.0, s);
    ASSERT_EQ(P.num_halfspaces(), 6);
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(P.offset(i) / s, 1.0, 1e-14);
      EXPECT_NEAR(P.normal(i).cwiseAbs().maxCoeff(), 1.0, 1e-14);
    }
    EXPECT_NEAR(P.radii().outer / s, std::sqrt(3.0), 1e-14);
  }
}

/// Rows scaled by 1e300 (or 1e-300) describe the same polytope: accepted
/// (1e300 was "b = 1e+300 <= 0": the row norm overflowed).
TEST(Limits, PolytopeRowsOfAnyMagnitude) {
  const std::vector<Vec3> A = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const std::vector<double> b = {1, 2, 1, 2, 1, 2};
  const SmoothPolytope ref(A, b, 10.0);
  for (double k : {1e300, 1e-300, 1e200}) {
    std::vector<Vec3> Ak = A;
    std::vector<double> bk = b;
    for (int i = 0; i < 6; ++i) Ak[i] *= k, bk[i] *= k;
    const SmoothPolytope P(Ak, bk, 10.0);
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(P.offset(i), ref.offset(i), 1e-14);
      EXPECT_LT((P.normal(i) - ref.normal(i)).norm(), 1e-15);
    }
  }
}

/// The frame origin 1e-11 from a face (relative to a unit box): a valid
/// polytope, accepted; and one whose origin is too close to a face for the
/// vertex enumeration says so, not "unbounded".
TEST(Limits, PolytopeOriginNearAFace) {
  const std::vector<Vec3> A = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (double d : {1e-3, 1e-8, 1e-11, 1e-14}) {
    SCOPED_TRACE(d);
    const std::vector<double> b = {1, 1, 1, 1, 1, d};
    std::string e;
    try {
      const SmoothPolytope P(A, b, 1e4 / d);  // sharp enough that the smooth body holds its origin
      EXPECT_EQ(P.num_halfspaces(), 6);
      EXPECT_NEAR(P.radii().outer, std::sqrt(3.0), 1e-6);
    } catch (const std::invalid_argument& ex) {
      e = ex.what();
    }
    if (!e.empty()) {
      EXPECT_EQ(e.find("unbounded"), std::string::npos) << e;
      EXPECT_NE(e.find("origin"), std::string::npos) << e;
    }
  }
}

}  // namespace
}  // namespace idcol
