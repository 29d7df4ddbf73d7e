// The cost estimate `check` prints (Study::estimate, studies/cost_model.hpp):
// what it counts, never how fast this machine is. No timing here: each test
// compares estimates of scenes that differ in one thing, or reads the parts
// the line names.
#include <gtest/gtest.h>

#include <string>

#include "scene/scene.hpp"
#include "studies/study.hpp"

using namespace idcol::harness;

namespace {

const char* kShapes = R"(
[shapes]
Poly = { family = "smooth_polytope", normals = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1], [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], offsets = [1, 1, 1, 1, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667], beta = 20 }
Ellip = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 1 }

[sweep]
generator = "paper"
poses = 20000
warmup = 100
)";

/// A sweep of the paper's Poly and Ellip with `record`, any further sections and lines of [sweep].
std::unique_ptr<Study> sweep(const std::string& record, const std::string& more = "", const std::string& sweep_more = "") {
  const std::string text = std::string("name = \"cost\"\n") + kShapes + sweep_more + "\n[run]\npairs = [[\"Poly\", \"Ellip\"], [\"Ellip\", \"Ellip\"]]\n" +
                           "passes = [\"cold\", \"warm\"]\nrecord = [" + record + "]\n" + more;
  Scene s = parse_scene(text, "cost.toml");
  return study_kind_named(s.kind)->make(std::move(s));
}

const char* kBaselines = "[baselines]\nmethods = [\"fcl_collide\", \"fcl_distance\", \"ccd_gjk\", \"ccd_mpr\", \"oracle\"]\npairs = \"run\"\n";

std::unique_ptr<Study> config(const std::string& name) { return load_study(std::string(IDCOL_CONFIGS_DIR) + "/" + name); }

}  // namespace

TEST(Cost, BaselinesAndOraclesAddToASweepsEstimate) {
  const StudyOptions o;
  const auto plain = sweep("\"timing\"");
  const auto with = sweep("\"timing\", \"baselines\"", kBaselines);
  EXPECT_EQ(plain->solves(o), with->solves(o));  // the same passes: the difference is the agreement pass
  EXPECT_GT(with->estimated_seconds(o), 2 * plain->estimated_seconds(o));
  const std::string line = cost_line(*with, o);
  EXPECT_NE(line.find("solves ~"), std::string::npos) << line;
  EXPECT_NE(line.find("oracles ~"), std::string::npos) << line;
  EXPECT_NE(line.find("baselines ~"), std::string::npos) << line;
  EXPECT_EQ(cost_line(*plain, o).find("baselines ~"), std::string::npos) << cost_line(*plain, o);
}

TEST(Cost, EachRecordedExtraIsAPartOfItsOwn) {
  const StudyOptions o;
  const double plain = sweep("\"timing\"")->estimated_seconds(o);
  const auto checks = sweep("\"checks\"");
  EXPECT_GT(checks->estimated_seconds(o), plain);
  EXPECT_NE(cost_line(*checks, o).find("checks ~"), std::string::npos);
  const auto derivs = sweep("\"derivatives\"", "[derivatives]\nevery = 10\npairs = \"run\"\n");
  EXPECT_GT(derivs->estimated_seconds(o), plain);
  EXPECT_NE(cost_line(*derivs, o).find("derivatives ~"), std::string::npos);
}

TEST(Cost, TimingPosesOnlyCountWithTiming) {
  const StudyOptions o;
  // Without "timing" the agreement pass runs, the side-by-side timing does not.
  const auto untimed = sweep("\"baselines\"", kBaselines);
  const auto timed = sweep("\"baselines\", \"timing\"", kBaselines);
  EXPECT_GT(timed->estimated_seconds(o), untimed->estimated_seconds(o));
}

// A sweep's shard is whole warm-start chains (shard_range): of 200 chains of
// 100 poses, shard 0/4 runs 50 and costs a quarter; of the default two
// chains of 10^4 poses, shard 0/4 runs none and shard 1/4 one, as run()
// does (the estimate once took a quarter of the poses for every shard).
TEST(Cost, AShardCostsAShareOfTheWhole) {
  StudyOptions o;
  const auto s = sweep("\"baselines\"", kBaselines, "warm_chain = 100\n");
  const double whole = s->estimated_seconds(o);
  o.shard_count = 4;
  EXPECT_NEAR(s->estimated_seconds(o), whole / 4, whole * 0.02);
  EXPECT_EQ(s->solves(o), 2u * 2u * 5000u);
  const auto two_chains = sweep("\"iterations\"");
  EXPECT_EQ(two_chains->solves(o), 0u);
  o.shard_index = 1;
  EXPECT_EQ(two_chains->solves(o), 2u * 2u * 10000u);
}

TEST(Cost, SmoothingGridsHaveAnEstimateInParts) {
  StudyOptions o;
  const auto s = config("smoothing_polytope.toml");
  EXPECT_GT(s->estimated_seconds(o), 0.0);
  const std::string line = cost_line(*s, o);
  for (const char* part : {"solves ~", "accuracy pass ~", "geometry ~"}) EXPECT_NE(line.find(part), std::string::npos) << line;
  // More poses, more time; the fixed geometry keeps it from scaling in proportion.
  o.poses = 1000;
  const double short_run = s->estimated_seconds(o);
  o.poses = 10000;
  EXPECT_GT(s->estimated_seconds(o), short_run);
  EXPECT_LT(s->estimated_seconds(o), 10 * short_run);
  // The superellipsoid grid also cross-checks the support-function oracle.
  EXPECT_NE(cost_line(*config("smoothing_superellipsoid.toml"), StudyOptions{}).find("oracles ~"), std::string::npos);
}

TEST(Cost, TimeOfImpactHasAnEstimateDominatedByItsOracle) {
  const StudyOptions o;
  const auto s = config("ci_toi.toml");
  EXPECT_GT(s->estimated_seconds(o), 0.0);
  const std::vector<CostPart> parts = s->estimate(o);
  ASSERT_FALSE(parts.empty());
  EXPECT_EQ(parts.front().name, "oracle");
  for (const CostPart& p : parts) EXPECT_LE(p.seconds, parts.front().seconds) << p.name;
  const std::string line = cost_line(*s, o);
  for (const char* part : {"oracle ~", "solves ~", "fcl ~"}) EXPECT_NE(line.find(part), std::string::npos) << line;
}
