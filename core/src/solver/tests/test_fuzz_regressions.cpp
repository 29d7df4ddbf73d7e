// Replays the fuzz corpus (core/fuzz/corpus/) through the same decoder and
// properties as the libFuzzer target, with whatever compiler and sanitizers
// this build uses, and keeps each crash the fuzzer found as a named test.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "idcol/derivatives.hpp"
#include "solve_case.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(FuzzRegressions, SolveCorpusHoldsEveryProperty) {
  const std::filesystem::path dir = std::filesystem::path(IDCOL_FUZZ_CORPUS_DIR) / "solve";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::vector<uint8_t> bytes = read_bytes(entry.path());
    EXPECT_EQ(fuzz::run_case(bytes.data(), bytes.size()), "") << entry.path().filename();
    ++n;
  }
  EXPECT_GT(n, 0);
  // The empty input decodes too (every read past the end returns 0).
  EXPECT_EQ(fuzz::run_case(nullptr, 0), "");
}

// fuzz_solve, corpus/solve/regression_gap_gradient_tiny_r: at |r| ~ 1e-300 the
// solve converges (alpha* = c |r|), but gap_gradient() and the gap itself
// used r.norm(), which squares the entries and underflows to 0 below
// |r| ~ 1e-154, and (1 - 1/alpha)/|r|, which overflows: the gradient came back
// NaN/Inf with Conditioning::reliable = true. Oracle: the gap and its
// rotational derivative depend on |r| only through |r| itself (alpha* is
// proportional to |r| along a fixed direction), so they match a solve at
// |r| ~ 1e-100 to many digits.
TEST(FuzzRegressions, GapAndItsGradientAtTinyTranslation) {
  const Shape a = Superellipsoid(0.49992904554818035, 1.000086976424811, 1.4999404898146029, 3.0001098649576559);
  const Shape b = SuperellipticCylinder(1.000086976424811, 2.0000984206912333, 4.0001213092240784);
  const Vec3 p(2.6724376343671691e-301, 5.3451811411215525e-301, 8.0179246478759397e-301);
  const SolverOptions o = test::with_derivatives();
  const SolveResult tiny = solve(a, b, Pose{Mat3::Identity(), p}, o);
  const SolveResult ref = solve(a, b, Pose{Mat3::Identity(), p * 1e201}, o);
  ASSERT_TRUE(tiny.converged());
  ASSERT_TRUE(ref.converged());
  const ContactKinematics kt = contact_kinematics(tiny), kr = contact_kinematics(ref);
  ASSERT_TRUE(kt.p1_1.allFinite() && kt.p2_1.allFinite() && std::isfinite(kt.gap));
  EXPECT_LT(kt.gap, 0.0);
  EXPECT_NEAR(kt.gap, kr.gap, 1e-8 * std::abs(kr.gap));
  const Row6 gt = gap_gradient(tiny), gr = gap_gradient(ref);
  ASSERT_TRUE(gt.allFinite()) << gt;
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(gt[j], gr[j], 1e-6 * gr.head<3>().norm()) << j;
  // The same through the full sensitivity.
  const SolutionSensitivity s = solution_sensitivity(tiny);
  const ContactKinematicsDerivatives d = contact_kinematics_derivatives(tiny, s);
  ASSERT_TRUE(d.valid);
  EXPECT_TRUE(d.dgap_dxi.allFinite() && d.dp1_1_dxi.allFinite() && d.dp2_1_dxi.allFinite());
  EXPECT_NEAR(d.dgap_dxi[1], gt[1], 1e-6 * gt.head<3>().norm());
}

// At a subnormal |r| alpha* is subnormal too: it keeps only a few of its 53
// bits, and 1/alpha overflows. Such an answer is not Converged but
// NumericalFailure (the README's promise for what doubles cannot represent),
// with no NaN in the result and no derivatives on offer.
TEST(FuzzRegressions, SubnormalAlphaIsNumericalFailureWithoutDerivatives) {
  const Shape a = Superellipsoid(0.5, 1.0, 1.5, 8.0), b = Sphere(0.7);
  const SolveResult r = solve(a, b, Pose{Mat3::Identity(), Vec3(0.3, -0.4, 0.5).normalized() * 4e-320}, test::with_derivatives());
  EXPECT_EQ(r.status, SolveStatus::NumericalFailure) << to_string(r.status);
  EXPECT_FALSE(std::isnan(r.alpha) || r.x_1.hasNaN() || std::isnan(r.lambda1) || std::isnan(r.lambda2));
  EXPECT_FALSE(conditioning(r).reliable);
  EXPECT_FALSE(solution_sensitivity(r).valid);
}

namespace {
/// Decodes one corpus file into its query, as fuzz_solve does.
struct Query {
  std::optional<Shape> a, b;
  Pose X;
};
Query decode(const char* name) {
  const std::vector<uint8_t> bytes = read_bytes(std::filesystem::path(IDCOL_FUZZ_CORPUS_DIR) / "solve" / name);
  fuzz::ByteReader in(bytes.data(), bytes.size());
  Query q;
  q.a = fuzz::read_shape(in);
  q.b = fuzz::read_shape(in);
  q.X = fuzz::read_pose(in);
  return q;
}
SolveResult solve_with_derivatives(const Query& q) { return solve(*q.a, *q.b, q.X, test::with_derivatives()); }
}  // namespace

// fuzz_solve found derivatives that overflowed while Conditioning said
// reliable: dz*/dxi with a NaN that maxCoeff() skipped
// (regression_nan_sensitivity_flag), and d gap/dv ~ L/alpha = 3e309
// (regression_gap_gradient_large_L: bodies of size 2e34 at |r| = 5.6e-241).
// Both are now flagged; whatever is reported reliable is finite.
TEST(FuzzRegressions, OverflowingDerivativesAreFlagged) {
  int checked = 0;
  for (const char* name : {"regression_nan_sensitivity_flag", "regression_gap_gradient_large_L", "regression_sphere_sphere_r1e-306",
                           "regression_gap_gradient_tiny_r"}) {
    SCOPED_TRACE(name);
    const Query q = decode(name);
    ASSERT_TRUE(q.a && q.b) << "the regression input no longer decodes to two shapes";
    const SolveResult r = solve_with_derivatives(q);
    // Two spheres at |r| = 9e-307 have a multiplier of 2e-309: a subnormal
    // answer, NumericalFailure by design, with no derivatives to check.
    if (std::string(name) == "regression_sphere_sphere_r1e-306") {
      EXPECT_EQ(r.status, SolveStatus::NumericalFailure) << to_string(r.status);
      EXPECT_FALSE(std::isnormal(r.lambda1) && std::isnormal(r.lambda2) && std::isnormal(r.alpha));
      continue;
    }
    ASSERT_TRUE(r.converged()) << to_string(r.status) << ": the regression's derivatives are no longer reached";
    ++checked;
    const SolutionSensitivity s = solution_sensitivity(r);
    const bool finite = s.dz_dxi.allFinite() && alpha_gradient(r).allFinite() && gap_gradient(r).allFinite();
    if (!s.dz_dxi.allFinite()) EXPECT_FALSE(s.cond.reliable);
    if (!finite) EXPECT_FALSE(conditioning(r).reliable);
  }
  EXPECT_EQ(checked, 3);
}

// fuzz_solve, corpus/solve/regression_witness_overflow_huge_r: at
// r = (-1.8e308, -10, -10) the solve converges with x_1 = (3.2e307, ...)
// on the other side of the origin, and the witness point p2 = r + (x - r)/alpha
// overflowed in x - r although p2 itself is finite. Oracle: the same formula
// in long double, whose range holds x - r.
TEST(FuzzRegressions, WitnessPointAtTranslationNearTheDoubleRange) {
  const Query q = decode("regression_witness_overflow_huge_r");
  ASSERT_TRUE(q.a && q.b);
  const SolveResult r = solve_with_derivatives(q);
  ASSERT_TRUE(r.converged()) << to_string(r.status);
  const ContactKinematics k = contact_kinematics(r);
  ASSERT_TRUE(k.p1_1.allFinite() && k.p2_1.allFinite() && std::isfinite(k.gap));
  for (int i = 0; i < 3; ++i) {
    const long double ri = q.X.p[i], xi = r.x_1[i], a = r.alpha;
    const long double p2 = ri + (xi - ri) / a;
    EXPECT_NEAR(static_cast<double>(k.p2_1[i] / p2), 1.0, 1e-12) << i;
  }
  // Whatever the derivatives are, non-finite ones are flagged.
  const SolutionSensitivity s = solution_sensitivity(r);
  const ContactKinematicsDerivatives d = contact_kinematics_derivatives(r, s);
  if (!d.dp2_1_dxi.allFinite()) EXPECT_FALSE(s.cond.reliable);
}

// fuzz_solve, corpus/solve/regression_wrench_moment_overflow: a body of size
// 4.6e233 penetrated at |r| = 1.8e84 gives f_n = 1.3e298, finite, but the
// moment of the reaction about body 2's origin, |r| f_n ~ 1e382, is not a
// double; F2_2 came out Inf and NaN with nothing said. The wrench now says
// so, and its derivatives are flagged.
TEST(FuzzRegressions, WrenchBeyondTheDoubleRangeSaysSo) {
  const Query q = decode("regression_wrench_moment_overflow");
  ASSERT_TRUE(q.a && q.b);
  const SolveResult r = solve_with_derivatives(q);
  ASSERT_TRUE(r.converged()) << to_string(r.status);
  const ContactWrench w = contact_wrench(r, HertzModel{});
  ASSERT_TRUE(w.valid && w.active);
  EXPECT_TRUE(std::isfinite(w.f_n));
  EXPECT_GT(w.f_n, std::numeric_limits<double>::max() / q.X.p.norm());  // the moment |r| f_n is not a double
  EXPECT_FALSE(w.representable);
  const ContactWrenchDerivatives d = contact_wrench_derivatives(r, solution_sensitivity(r), HertzModel{});
  EXPECT_FALSE(d.cond.reliable);
  // A wrench that fits is representable (the same shapes at an ordinary pose).
  const SolveResult r2 =
      solve(Superellipsoid(1, 1, 1, 2), Sphere(1), Pose{Mat3::Identity(), Vec3(1.5, 0.2, 0)}, test::with_derivatives());
  const ContactWrench w2 = contact_wrench(r2, HertzModel{});
  ASSERT_TRUE(w2.active);
  EXPECT_TRUE(w2.representable);
}

// fuzz_solve, corpus/solve/regression_kinematics_overflow_huge_bodies: spheres
// of radius 1e300 and 1.8e308 (the largest double) penetrating at
// |r| = 7.5e240. |r| / alpha* is R1 + R2, beyond the double range, so p2 came
// out Inf although p2 = r + R2 r/|r| is ~1.8e308, a double; and the gap
// |r| - (R1 + R2) is genuinely not a double. p2 is now finite and the
// kinematics say that the gap does not fit (representable = false). Oracle:
// the closed form of two spheres, in long double.
TEST(FuzzRegressions, KinematicsBeyondTheDoubleRangeSayWhatDoesNotFit) {
  const Query q = decode("regression_kinematics_overflow_huge_bodies");
  ASSERT_TRUE(q.a && q.b);
  const SolveResult r = solve_with_derivatives(q);
  ASSERT_TRUE(r.converged()) << to_string(r.status);
  const ContactKinematics k = contact_kinematics(r);
  ASSERT_TRUE(k.valid);
  EXPECT_FALSE(k.representable);
  EXPECT_TRUE(k.p1_1.allFinite());
  EXPECT_TRUE(k.p2_1.allFinite());
  EXPECT_FALSE(std::isfinite(k.gap));
  const long double R1 = std::get<Sphere>(*q.a).R(), R2 = std::get<Sphere>(*q.b).R(), rx = q.X.p[0];
  ASSERT_LT(rx, 0.0L);  // r along -x: body 1's witness at -R1 e_x, body 2's at r + R2 e_x
  EXPECT_NEAR(static_cast<double>(k.p1_1[0] / -R1), 1.0, 1e-12);
  EXPECT_NEAR(static_cast<double>(k.p2_1[0] / (rx + R2)), 1.0, 1e-12);
  EXPECT_LT(-(R1 + R2) - rx, -static_cast<long double>(std::numeric_limits<double>::max()));  // the exact gap
  // The wrench of that contact cannot fit either, and says so.
  EXPECT_FALSE(contact_wrench(r, HertzModel{}).representable);
  // Kinematics that fit are representable (the same shapes at an ordinary pose).
  const SolveResult r2 = solve(Sphere(1), Sphere(2), Pose{Mat3::Identity(), Vec3(2.5, 0.2, 0)}, test::with_derivatives());
  EXPECT_TRUE(contact_kinematics(r2).representable);
}
