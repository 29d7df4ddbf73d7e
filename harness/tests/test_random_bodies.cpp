// The random-body generator (random_bodies.hpp) and the stress suite's
// kind = "random_bodies": pose k is a pure function of (case, k), every
// parameter lies in its documented range, a small case runs through the
// stress checks, a wrong answer is caught by them, and a failure record
// replays with the generated bodies.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>

#include "idcol/solver.hpp"
#include "gen/random_bodies.hpp"
#include "studies/stress/stress.hpp"
#include "io/files.hpp"
#include "studies/stress/stress_tally.hpp"

namespace idcol::harness {
namespace {

bool same_pose(const Pose& a, const Pose& b) { return a.R == b.R && a.p == b.p; }

TEST(RandomBodies, PoseKIsAPureFunctionOfCaseAndK) {
  const RandomBodyCase c{BodyFamily::Polytope, BodyFamily::Cone, BodyRange::Normal, 3};
  const RandomBodyPose p5 = random_body_pose(c, 5);
  (void)random_body_pose(c, 4);
  const RandomBodyPose again = random_body_pose(c, 5);  // after another draw: no hidden state
  EXPECT_EQ(describe(p5.body1), describe(again.body1));
  EXPECT_EQ(describe(p5.body2), describe(again.body2));
  EXPECT_TRUE(same_pose(p5.X_12, again.X_12));
  EXPECT_TRUE(same_pose(p5.X_12_near, again.X_12_near));
  // Another index, seed, range or family order draws other bodies.
  EXPECT_NE(describe(random_body_pose(c, 6).body1), describe(p5.body1));
  RandomBodyCase other = c;
  other.seed = 4;
  EXPECT_NE(describe(random_body_pose(other, 5).body1), describe(p5.body1));
  other = c;
  other.range = BodyRange::Wide;
  EXPECT_NE(describe(random_body_pose(other, 5).body1), describe(p5.body1));
  other = c;
  std::swap(other.family1, other.family2);
  EXPECT_NE(describe(random_body_pose(other, 5).body2), describe(p5.body1));
}

TEST(RandomBodies, NamesRoundTripAndBadNamesAreRejected) {
  for (int f = 0; f < kNumBodyFamilies; ++f)
    EXPECT_EQ(body_family_from_string(to_string(static_cast<BodyFamily>(f))), static_cast<BodyFamily>(f));
  EXPECT_THROW(body_family_from_string("ellipsoid"), std::invalid_argument);
  EXPECT_EQ(body_range_from_string("wide"), BodyRange::Wide);
  EXPECT_THROW(body_range_from_string("huge"), std::invalid_argument);
}

/// x in [lo, hi], with a relative slack for the rounding of 10^u.
bool in(double x, double lo, double hi) { return x >= lo * (1 - 1e-12) && x <= hi * (1 + 1e-12); }

TEST(RandomBodies, ParametersLieInTheDocumentedRanges) {
  const std::set<double> n_normal{1, 1.5, 2, 3, 4, 8, 16}, n_wide{1, 1.5, 2, 3, 4, 32, 64};
  const std::set<double> beta_normal{5, 20, 100, 1000}, beta_wide{5, 20, 100, 1e4};
  for (const BodyRange range : {BodyRange::Normal, BodyRange::Wide}) {
    const bool wide = range == BodyRange::Wide;
    const double smin = wide ? 1e-3 : std::pow(10.0, -0.5), smax = wide ? 1e3 : std::pow(10.0, 0.5);
    const double amax = wide ? 1000.0 : 10.0;
    const std::set<double>& ns = wide ? n_wide : n_normal;
    const std::set<double>& betas = wide ? beta_wide : beta_normal;
    std::set<double> n_seen, beta_seen;
    bool cone_pointed = false, cone_flat = false, cone_top = false;
    for (int f = 0; f < kNumBodyFamilies; ++f) {
      const RandomBodyCase c{static_cast<BodyFamily>(f), BodyFamily::Sphere, range, 11};
      for (std::uint64_t k = 0; k < 300; ++k) {
        const RandomBodyPose P = random_body_pose(c, k);
        const Shape& b = P.body1;
        SCOPED_TRACE(describe(b));
        switch (c.family1) {
          case BodyFamily::Sphere: EXPECT_TRUE(in(std::get<Sphere>(b).R(), smin, smax)); break;
          case BodyFamily::Superellipsoid: {
            const auto& e = std::get<Superellipsoid>(b);
            EXPECT_TRUE(in(e.a(), smin, smax));
            EXPECT_TRUE(in(e.b() / e.a(), 1.0, amax));
            EXPECT_TRUE(in(e.c() / e.a(), 1.0, amax));
            EXPECT_EQ(ns.count(e.n()), 1u) << e.n();
            n_seen.insert(e.n());
            break;
          }
          case BodyFamily::Cylinder: {
            const auto& y = std::get<SuperellipticCylinder>(b);
            EXPECT_TRUE(in(y.R(), smin, smax));
            EXPECT_TRUE(in(y.h() / y.R(), 1.0, amax));
            EXPECT_EQ(ns.count(y.n()), 1u) << y.n();
            break;
          }
          case BodyFamily::Box: {
            const auto& p = std::get<SmoothPolytope>(b);
            ASSERT_EQ(p.num_halfspaces(), 6);
            double hmin = 1e300, hmax = 0.0;
            for (int i = 0; i < 6; ++i) hmin = std::min(hmin, p.offset(i)), hmax = std::max(hmax, p.offset(i));
            EXPECT_TRUE(in(hmin, smin, smax));
            EXPECT_TRUE(in(hmax / hmin, 1.0, amax));
            if (wide) {
              EXPECT_TRUE(in(p.beta(), 5.0, 1e4));
              EXPECT_DOUBLE_EQ(p.L(), hmax);
            } else {
              EXPECT_EQ(betas.count(p.beta()), 1u) << p.beta();
              EXPECT_DOUBLE_EQ(p.L(), hmin);
            }
            beta_seen.insert(p.beta());
            break;
          }
          case BodyFamily::Polytope: {
            const auto& p = std::get<SmoothPolytope>(b);
            EXPECT_GE(p.num_halfspaces(), 4);
            EXPECT_LE(p.vertices().size(), 31u);  // 6..25 random points and 6 axis points
            // Every vertex on an ellipsoid with axes in [s, s amax], s in [smin, smax].
            for (const Vec3& v : p.vertices()) EXPECT_LE(v.norm(), smax * amax * (1 + 1e-12));
            if (wide) EXPECT_TRUE(in(p.beta(), 5.0, 1e4));
            else EXPECT_EQ(betas.count(p.beta()), 1u) << p.beta();
            break;
          }
          case BodyFamily::Cone: {
            const auto& t = std::get<SmoothTruncatedCone>(b);
            EXPECT_TRUE(in(t.Rb(), smin, smax));
            EXPECT_TRUE(in(t.Rt() / t.Rb(), wide ? 0.01 : 0.1, 1.0));
            EXPECT_TRUE(in(t.a() / t.Rb(), wide ? 0.5 * std::pow(10.0, -1.5) : 0.5, 0.5 * amax));
            EXPECT_TRUE(in(t.b() / t.a(), wide ? std::pow(10.0, -1.5) : 0.3, 1.0));
            if (wide) {  // the widened corners are reached
              cone_pointed |= t.Rt() / t.Rb() < 0.05;
              cone_flat |= t.a() / t.Rb() < 0.1;
              cone_top |= t.b() / t.a() < 0.1;
            }
            EXPECT_EQ(betas.count(t.beta()), 1u) << t.beta();
            break;
          }
        }
        // The pose: a rotation, |r| = (inner1 + inner2) 10^U(-3, 3), and the nearby pose.
        EXPECT_LT((P.X_12.R.transpose() * P.X_12.R - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_NEAR(P.X_12.R.determinant(), 1.0, 1e-12);
        EXPECT_TRUE(in(P.X_12.p.norm() / (radii(P.body1).inner + radii(P.body2).inner), 1e-3, 1e3));
        EXPECT_LT((P.X_12_near.p - 1.01 * P.X_12.p).norm(), 1e-12 * P.X_12.p.norm());
        EXPECT_NEAR(Eigen::AngleAxisd(P.X_12.R.transpose() * P.X_12_near.R).angle(), 0.02, 1e-12);
      }
    }
    EXPECT_EQ(n_seen, ns);  // every documented value is drawn
    if (!wide) EXPECT_EQ(beta_seen, betas);
    if (wide) EXPECT_TRUE(cone_pointed && cone_flat && cone_top);
  }
}

const char* kScene = R"(name = "rb"
[[case]]
name = "box-cone"
kind = "random_bodies"
family1 = "box"
family2 = "cone"
range = "normal"
seed = 2
poses = 6
passes = ["cold", "warm"]
)";

TEST(RandomBodies, SmallCaseRunsThroughEveryCheckInBothOrders) {
  const Scene s = parse_scene(kScene, "rb.toml");
  ASSERT_EQ(s.spec.as<StressSpec>().cases.size(), 1u);
  EXPECT_EQ(s.spec.as<StressSpec>().cases[0].kind, StressKind::RandomBodies);
  const StressOutput out = run_stress(s, StudyOptions{});
  const nlohmann::json res = make_stress_results(s, out, nlohmann::json::object());
  const auto& passes = res["cases"][0]["passes"];
  ASSERT_EQ(passes.size(), 4u);
  for (const char* name : {"cold", "warm", "cold_swapped", "warm_swapped"}) {
    SCOPED_TRACE(name);
    const auto& p = passes.at(name);
    EXPECT_EQ(p["solves"], 6);
    EXPECT_EQ(p["genuine"], 6);
    EXPECT_EQ(p["oracle"]["checked"], 6);  // every answer against its bracket
    EXPECT_EQ(p["false_convergence"]["total"], 0);
    EXPECT_GT(p["worst_surface_error"].get<double>(), 0.0);  // the surface check ran
  }
  const std::string md = stress_markdown(res, "rb.json");
  EXPECT_NE(md.find("| box-cone | box x cone | random_bodies | warm_swapped | 6 |"), std::string::npos) << md;
  // Threads split the poses; the figures do not change.
  StudyOptions two;
  two.threads = 2;
  const nlohmann::json res2 = make_stress_results(s, run_stress(s, two), nlohmann::json::object());
  for (const char* name : {"cold", "warm_swapped"}) {
    EXPECT_EQ(res2["cases"][0]["passes"][name]["iterations"], passes[name]["iterations"]);
    EXPECT_EQ(res2["cases"][0]["passes"][name]["worst_residual"], passes[name]["worst_residual"]);
  }
}

TEST(RandomBodies, WrongAnswersAreCaughtByTheChecks) {
  const Scene s = parse_scene(kScene, "rb.toml");
  const StressCase& c = s.spec.as<StressSpec>().cases[0];
  for (std::uint64_t k = 0; k < 4; ++k) {
    const RandomBodyPose P = random_body_pose(c.random, k);
    const AnswerChecker checker(P.body1, P.body2, OracleChoice::SupportFunction, s.solver);
    const SolveResult r = solve(P.body1, P.body2, P.X_12, s.solver);
    ASSERT_TRUE(r.converged());
    StressTally tally;
    EXPECT_EQ(tally.check(checker, P.X_12, r, k, true).problem, "");
    // alpha 0.1% too large: the witness points leave the surfaces.
    SolveResult big = r;
    big.alpha *= 1.001;
    const std::string why = tally.check(checker, P.X_12, big, k, true).problem;
    EXPECT_NE(why.find("off its surface"), std::string::npos) << why;
    // alpha a factor of 3 off either way: outside the support bracket as well
    // (at beta = 5 the smoothing bracket of a box or a cone is wide, well
    // inside a factor of 3).
    for (const double f : {3.0, 1.0 / 3.0}) {
      SolveResult off = r;
      off.alpha *= f;
      const std::string w = tally.check(checker, P.X_12, off, k, true).problem;
      EXPECT_NE(w.find("outside the support_function bracket"), std::string::npos) << w;
    }
    // The answer of another pose: its witness points are not on these surfaces.
    const SolveResult other = solve(P.body1, P.body2, P.X_12_near, s.solver);
    EXPECT_NE(tally.check(checker, P.X_12, other, k, true).problem, "");
    // A Converged answer of the right size in the wrong place: alpha is kept, x moved.
    SolveResult moved = r;
    moved.x_1 += 0.01 * r.alpha * radii(P.body1).inner * Vec3(0.6, 0.0, 0.8);
    EXPECT_NE(tally.check(checker, P.X_12, moved, k, true).problem, "");
    const nlohmann::json st = tally.to_json();
    EXPECT_EQ(st["solves"], 6);
    EXPECT_EQ(st["genuine"], 1);
    EXPECT_EQ(st["false_convergence"]["total"], 5);
  }
}

// The wide range's needle cones (Rt / Rb = 0.01, 1000:1, beta = 10^4)
// beside spheres 10^4 to 10^5 times their size, which ended
// line_search_failed in idcol_check_random_bodies 3000 1 11 (seed 11): the
// tip's rounding radius is 10^8 times shorter than its distance from the
// cone's origin, so the normals align only to the rounding floor (1-2e-8).
// Regenerated from the generator and checked as the stress suite checks
// (the independent geometry, the support-function bracket), in the order
// that failed and swapped.
TEST(RandomBodies, NeedleConesBesideHugeSpheresConverge) {
  struct Replay {
    RandomBodyCase c;
    std::uint64_t k;
    bool near;  // the nearby pose (the check's third solve), else the pose
    const char* cone;
  };
  const char* cone448 =
      "{ family = \"smooth_truncated_cone\", Rb = 0.0014156838538206286, Rt = 1.5158395178837327e-05, a = 0.68798323207487855, "
      "b = 0.099743577675115741, beta = 10000 }";
  const char* cone1391 =
      "{ family = \"smooth_truncated_cone\", Rb = 0.0020260163461932722, Rt = 4.3101568665168089e-05, a = 0.98290533903104294, "
      "b = 0.6704712330560979, beta = 10000 }";
  const Replay replays[] = {
      {{BodyFamily::Sphere, BodyFamily::Cone, BodyRange::Wide, 11}, 448, false, cone448},
      {{BodyFamily::Cone, BodyFamily::Sphere, BodyRange::Wide, 11}, 1391, false, cone1391},
      {{BodyFamily::Cone, BodyFamily::Sphere, BodyRange::Wide, 11}, 1391, true, cone1391},
  };
  SolverOptions o;
  o.derivatives = true;  // the stress checks take the answer's derivatives too
  for (const Replay& rp : replays) {
    const RandomBodyPose P = random_body_pose(rp.c, rp.k);
    const Pose& X = rp.near ? P.X_12_near : P.X_12;
    // The generator still draws the bodies that failed.
    const bool cone_first = rp.c.family1 == BodyFamily::Cone;
    ASSERT_EQ(describe(cone_first ? P.body1 : P.body2), rp.cone);
    for (const bool swapped : {false, true}) {
      const std::string what = std::string(to_string(rp.c.family1)) + "-" + to_string(rp.c.family2) + " pose " + std::to_string(rp.k) +
                               (rp.near ? " (nearby)" : "") + (swapped ? ", swapped" : "");
      const Shape& a = swapped ? P.body2 : P.body1;
      const Shape& b = swapped ? P.body1 : P.body2;
      const Pose Xs = swapped ? X.inverse() : X;
      const SolveResult r = solve(a, b, Xs, o);
      ASSERT_EQ(r.status, SolveStatus::Converged) << what << ": " << to_string(r.status) << ", residual " << r.residual_norm;
      const AnswerChecker checker(a, b, OracleChoice::SupportFunction, o);
      StressTally tally;
      const AnswerCheck chk = tally.check(checker, Xs, r, rp.k, true);
      EXPECT_EQ(chk.problem, "") << what;
      EXPECT_TRUE(chk.oracle_checked) << what;
    }
  }
}

TEST(RandomBodies, SceneErrorsNameTheField) {
  auto error_of = [](const std::string& text) {
    try {
      (void)parse_scene(text, "rb.toml");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string t = kScene;
  EXPECT_NE(error_of(std::string(kScene).replace(t.find("\"cone\""), 6, "\"cube\"")).find("case[0].family2: unknown body family \"cube\""),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kScene).replace(t.find("\"normal\""), 8, "\"huge\"")).find("case[0].range: unknown range \"huge\""),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kScene) + "derivative_samples = 4\n").find("case[0].derivative_samples"), std::string::npos);
  EXPECT_NE(error_of(std::string(kScene) + "body1 = \"A\"\n").find("case[0].body1"), std::string::npos);  // not a field of this kind
  // An ordinary case naming a shape still needs [shapes].
  EXPECT_NE(error_of("name = \"x\"\n[[case]]\nname = \"c\"\nbody1 = \"A\"\nbody2 = \"A\"\nkind = \"shell\"\nposes = 1\npasses = [\"cold\"]\n")
                .find("unknown shape \"A\""),
            std::string::npos);
}

TEST(RandomBodies, FailureRecordsReplayWithTheGeneratedBodies) {
  // Two Newton iterations, without continuation or the barrier, are too few
  // for most poses: failures, each recorded.
  char templ[] = "/tmp/idcol_rb_test.XXXXXX";
  const std::string dir = ::mkdtemp(templ);
  std::ofstream(dir + "/s.toml") << kScene << "[solver]\nmax_iterations = 2\nmax_iterations_extended = 2\nmax_restarts = 0\n"
                                     "barrier = false\ncontinuation = false\n";
  const std::string exe = IDCOL_HARNESS_EXE;
  const std::string out = dir + "/r.json", fails = dir + "/r.failures.json";
  ASSERT_EQ(std::system((exe + " stress " + dir + "/s.toml -o " + out + " --no-progress > /dev/null").c_str()), 0);
  const nlohmann::json f = read_json_file(fails);
  ASSERT_GT(f["failures"].size(), 0u);
  std::set<std::string> passes;
  for (std::size_t i = 0; i < f["failures"].size(); ++i) {
    const auto& rec = f["failures"][i];
    passes.insert(rec["pass"].get<std::string>());
    // The record holds what regenerates it, and the bodies it was solved with.
    const auto& g = rec["random_bodies"];
    RandomBodyCase c{body_family_from_string(g["family1"]), body_family_from_string(g["family2"]),
                     body_range_from_string(g["range"]), g["seed"].get<std::uint64_t>()};
    const RandomBodyPose P = random_body_pose(c, g["k"].get<std::uint64_t>());
    const bool swapped = g["swapped"].get<bool>();
    EXPECT_EQ(rec["shape1"], describe(swapped ? P.body2 : P.body1));
    EXPECT_EQ(rec["shape2"], describe(swapped ? P.body1 : P.body2));
    if (i % 3 == 0) {
      const int rc = std::system((exe + " replay " + fails + " --index " + std::to_string(i) + " > /dev/null").c_str());
      EXPECT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 0) << "replay of failure " << i << ": " << rec.dump();
    }
  }
  // Both body orders fail at two iterations, and both are recorded.
  EXPECT_EQ(passes.count("cold"), 1u);
  EXPECT_EQ(passes.count("cold_swapped"), 1u);
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace
}  // namespace idcol::harness
