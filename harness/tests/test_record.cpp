// The one record (record.hpp), the answer checks any pass can turn on
// (checks.hpp) and the kind of a scene as load_study reads it (studies/study.hpp).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include "idcol/solver.hpp"
#include "referee/checks.hpp"
#include "studies/study.hpp"
#include "io/record.hpp"
#include "scene/scene.hpp"

namespace idcol::harness {
namespace {

Pose pose_at(double x, double y, double z) {
  Pose X;
  X.R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  X.p = Vec3(x, y, z);
  return X;
}

TEST(Record, FailureRecordCarriesSiteSolveAndWarmStartThatReplays) {
  const Shape a = Sphere(1.0), b = Superellipsoid(0.5, 1.0, 1.5, 4.0);
  const Pose X = pose_at(0.7, -1.9, 2.3);
  WarmStart ws;
  const SolveResult r0 = solve(a, b, X, SolverOptions{}, &ws);
  ASSERT_TRUE(r0.converged());
  const SolveResult r1 = solve(a, b, X, SolverOptions{}, &ws);  // ws now carries a predictor history
  const nlohmann::json f = failure_record({"A", "B", &a, &b, "warm", 7, "paper"}, X, &r1, &ws);
  EXPECT_EQ(f.at("status"), to_string(r1.status));
  EXPECT_EQ(f.at("k"), 7);
  EXPECT_EQ(f.at("shape2"), describe(b));
  const Pose Y = pose_from_json(f.at("pose"));
  EXPECT_EQ((Y.R - X.R).norm(), 0.0);
  EXPECT_EQ((Y.p - X.p).norm(), 0.0);
  const WarmStart back = warm_start_from_json(f.at("warm_start"));
  EXPECT_EQ(back.valid, ws.valid);
  EXPECT_EQ(back.history, ws.history);
  EXPECT_EQ((back.z - ws.z).norm(), 0.0);
  for (int i = 0; i < ws.history; ++i) EXPECT_EQ((back.z_prev[i] - ws.z_prev[i]).norm(), 0.0);
  // The same warm start gives the same solve.
  WarmStart w1 = ws, w2 = back;
  const Pose X2 = pose_at(0.71, -1.88, 2.31);
  EXPECT_EQ(solve(a, b, X2, SolverOptions{}, &w1).iterations, solve(a, b, X2, SolverOptions{}, &w2).iterations);
  // A record without a solve has no status to compare.
  EXPECT_FALSE(failure_record({"A", "B", &a, &b, "cold", 0, "stress:touching"}, X).contains("status"));
}

TEST(Record, AppendedFailuresAreNumberedWithTheirReplayCommand) {
  nlohmann::json into = nlohmann::json::array({{{"k", 1}}});
  append_failures(into, nlohmann::json::array({{{"k", 2}}, {{"k", 3}}}), "f.json");
  ASSERT_EQ(into.size(), 3u);
  EXPECT_EQ(into[2].at("index"), 2);
  EXPECT_EQ(into[2].at("replay"), "idcol_harness replay f.json --index 2");
}

TEST(Record, EveryResultsFileHeaderHoldsEverySolverOption) {
  SolverOptions o;
  o.max_iterations = 17;
  const nlohmann::json h = results_header(kStressSchema, {{"git_revision", "x"}}, {"s.toml", "s", "name = \"s\""}, o);
  EXPECT_EQ(h.at("solver").at("max_iterations"), 17);
  EXPECT_EQ(h.at("scene").at("content"), "name = \"s\"");
  EXPECT_EQ(h.at("metadata").at("git_revision"), "x");
}

TEST(Checks, GenuineAnswerPassesAndAWrongOneIsNamed) {
  const Shape a = Sphere(1.0), b = Sphere(0.5);
  const AnswerChecker chk(a, b, OracleChoice::Auto, SolverOptions{});
  EXPECT_EQ(chk.oracle(), OracleChoice::ClosedForm);
  const Pose X = pose_at(0.4, 1.1, -0.9);
  SolveResult r = solve(a, b, X, SolverOptions{});
  ASSERT_TRUE(r.converged());
  const AnswerCheck good = chk.check(X, r, true);
  EXPECT_TRUE(good.genuine()) << good.problem;
  EXPECT_TRUE(good.oracle_checked);
  EXPECT_LT(good.oracle_error, chk.tolerances().closed_form);
  r.alpha *= 1.0 + 1e-6;  // off the oracle and the surfaces
  const AnswerCheck bad = chk.check(X, r, true);
  EXPECT_FALSE(bad.genuine());
  EXPECT_TRUE(bad.oracle_disagrees);
  EXPECT_NE(bad.problem.find("closed form"), std::string::npos) << bad.problem;
  const TouchReference ref = chk.reference(X);
  EXPECT_TRUE(ref.ok);
  EXPECT_DOUBLE_EQ(ref.lo, X.p.norm() / 1.5);
}

// A sharp millimetre cone against a 750 m sphere: the witness point's
// coordinates round by ~1e-13 m, which turns the cone's normal (curvature
// ~beta / size) by ~1e-6 however exact the answer. The normal check allows
// that turn, measured, and nothing on bodies of one size.
TEST(Checks, NormalCheckAllowsTheTurnOverTheWitnessPointsRounding) {
  const Shape big = *parse_shape_inline("{ family = \"sphere\", R = 752.55729304936233 }", "t", "s1").shape;
  const Shape cone = *parse_shape_inline(
      "{ family = \"smooth_truncated_cone\", Rb = 0.0011478711571599096, Rt = 0.0001219666668803416, "
      "a = 0.0014039623525651337, b = 0.0012814612655784171, beta = 10000 }", "t", "s2").shape;
  Pose X;
  X.R << 0.75198009705592261, -0.5309770169661715, -0.39062685658499124, 0.18428832351418273, 0.73830243909239179,
      -0.64880453315814379, 0.63290105660213358, 0.41590012729492043, 0.65304160408657874;
  X.p = Vec3(23.436990571921203, 43.454612436760883, 23.866259539793027);
  const SolveResult r = solve(big, cone, X, SolverOptions{});
  ASSERT_TRUE(r.converged()) << to_string(r.status);
  const AnswerChecker chk(big, cone, OracleChoice::None, SolverOptions{});
  const AnswerCheck c = chk.check(X, r, false);
  EXPECT_TRUE(c.genuine()) << c.problem;
  EXPECT_GT(c.normal_allowance, 1e-8);
  EXPECT_LT(c.normal_allowance, 1e-4);
  // The same cone against a sphere of its own size: no allowance to speak of.
  const Shape small = Sphere(0.001);
  Pose Y = X;
  Y.p = X.p.normalized() * 0.003;
  const SolveResult r2 = solve(small, cone, Y, SolverOptions{});
  ASSERT_TRUE(r2.converged());
  const AnswerCheck c2 = AnswerChecker(small, cone, OracleChoice::None, SolverOptions{}).check(Y, r2, false);
  EXPECT_TRUE(c2.genuine()) << c2.problem;
  EXPECT_LT(c2.normal_allowance, 1e-9);
  // A witness pair whose normals really differ still fails: x moved along body 1's surface.
  SolveResult moved = r2;
  moved.x_1 = Eigen::AngleAxisd(1e-4, Vec3::UnitZ()) * r2.x_1;
  EXPECT_FALSE(AnswerChecker(small, cone, OracleChoice::None, SolverOptions{}).check(Y, moved, false).genuine());
}

// A 2 mm cone deep inside a box 10^5 times larger: alpha* ~ 2e-5, and x is
// ~|p| = 5 while the cone's scaled witness point is ~1e-8 from p. The
// rounding of x, divided by alpha, moves the cone's witness point off its
// surface by ~1e-8 of its size however exact the answer (KKT residual 8e-15).
// The surface check allows that, measured, and nothing on bodies of one size.
TEST(Checks, SurfaceCheckAllowsTheWitnessPointsRounding) {
  const Shape box = *parse_shape_inline(
      "{ family = \"smooth_polytope\", normals = [[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]], "
      "offsets = [468.08874411324746, 468.08874411324746, 173827.38093188414, 173827.38093188414, 329693.96677327313, "
      "329693.96677327313], beta = 3786.0275065946839, L = 329693.96677327313 }", "t", "s1").shape;
  const Shape cone = *parse_shape_inline(
      "{ family = \"smooth_truncated_cone\", Rb = 0.0020659108327964449, Rt = 0.0014495962011730444, "
      "a = 0.0016858526925472841, b = 0.0013084245685380891, beta = 5 }", "t", "s2").shape;
  Pose X;
  X.R << 0.62073452948803687, -0.74608969877708797, 0.24091244318212338, 0.35665398627594547, 0.54235675035385833,
      0.76068856269769192, -0.69820239041036192, -0.38626327384870141, 0.60275542743383059;
  X.p = Vec3(0.0044977423090290574, -3.4275439420012956, -3.5694130779491458);
  const SolveResult r = solve(box, cone, X, SolverOptions{});
  ASSERT_TRUE(r.converged()) << to_string(r.status);
  EXPECT_LT(r.residual_norm, 1e-12);
  const AnswerChecker chk(box, cone, OracleChoice::None, SolverOptions{});
  const AnswerCheck c = chk.check(X, r, false);
  EXPECT_TRUE(c.genuine()) << c.problem;
  EXPECT_GT(c.surface_allowance, 1e-9);
  EXPECT_LT(c.surface_allowance, 1e-5);
  // A witness point really off the cone still fails: x moved by 1e-4 of the
  // cone's scaled size along the line of centres.
  SolveResult moved = r;
  moved.x_1 += 1e-4 * 0.002 * r.alpha * X.p.normalized();
  const AnswerCheck m = chk.check(X, moved, false);
  EXPECT_TRUE(m.surface_failed) << m.surface << " allowed " << m.surface_allowance;
  // The same cone against a box of its own size: no allowance to speak of.
  const Shape small = SmoothPolytope({Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()},
                                     {0.002, 0.002, 0.003, 0.003, 0.004, 0.004}, 20.0, 0.004);
  Pose Y = X;
  Y.p = X.p.normalized() * 0.01;
  const SolveResult r2 = solve(small, cone, Y, SolverOptions{});
  ASSERT_TRUE(r2.converged());
  const AnswerCheck c2 = AnswerChecker(small, cone, OracleChoice::None, SolverOptions{}).check(Y, r2, false);
  EXPECT_TRUE(c2.genuine()) << c2.problem;
  EXPECT_LT(c2.surface_allowance, 1e-12);
}

// The oracle's answer at one configuration judges both body orders: the
// verdict computed for (a, b) at X checks the answer of (b, a) at X^-1, and a
// verdict given to check() is the one it uses.
TEST(Checks, OneOracleVerdictJudgesBothBodyOrders) {
  const Shape a = Superellipsoid(0.5, 1.0, 1.5, 4.0), b = SmoothTruncatedCone(0.6, 0.3, 0.8, 0.5, 20.0);
  const Pose X = pose_at(0.9, -1.4, 1.2), Xi = X.inverse();
  const SolverOptions o;
  const AnswerChecker ab(a, b, OracleChoice::Auto, o), ba(b, a, OracleChoice::Auto, o);
  ASSERT_EQ(ab.oracle(), OracleChoice::SupportFunction);
  const OracleVerdict v = ab.oracle_verdict(X), w = ba.oracle_verdict(Xi);
  ASSERT_TRUE(v.ok && w.ok);
  EXPECT_LE(v.lo, v.hi);
  // The two orders' brackets hold the same alpha*: they overlap.
  EXPECT_LE(std::max(v.lo, w.lo), std::min(v.hi, w.hi) * (1.0 + 1e-9));
  const SolveResult r = solve(b, a, Xi, o);
  ASSERT_TRUE(r.converged());
  const AnswerCheck c = ba.check(Xi, r, true, std::numeric_limits<double>::quiet_NaN(), {}, &v);
  EXPECT_TRUE(c.genuine()) << c.problem;
  EXPECT_TRUE(c.oracle_checked);
  EXPECT_DOUBLE_EQ(c.oracle_alpha, v.alpha);
  // A verdict whose bracket excludes the answer is the one that judges it.
  OracleVerdict off = v;
  off.lo = r.alpha * 1.01, off.hi = r.alpha * 1.02;
  const AnswerCheck d = ba.check(Xi, r, true, std::numeric_limits<double>::quiet_NaN(), {}, &off);
  EXPECT_TRUE(d.oracle_disagrees);
  EXPECT_NE(d.problem.find("bracket"), std::string::npos) << d.problem;
  // An oracle that could not answer is counted so, not as agreement.
  const OracleVerdict none;
  const AnswerCheck e = ba.check(Xi, r, true, std::numeric_limits<double>::quiet_NaN(), {}, &none);
  EXPECT_TRUE(e.oracle_failed_to_answer);
  EXPECT_FALSE(e.oracle_checked);
}

TEST(Study, TheKindOfASceneComesFromItsTables) {
  const std::string dir = IDCOL_CONFIGS_DIR;
  EXPECT_STREQ(load_study(dir + "/quick.toml")->kind().name, "sweep");
  EXPECT_STREQ(load_study(dir + "/stress.toml")->kind().name, "stress");
  try {
    (void)load_study(dir + "/stress.toml", "sweep");
    FAIL() << "a stress scene was taken for a sweep";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("a stress scene, not a sweep scene"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace idcol::harness
