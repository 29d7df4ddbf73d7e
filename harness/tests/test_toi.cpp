// The time-of-impact study: its scene section, its oracle against a closed
// form, the CI scene (no contact missed), and a wrong answer that compare
// must fail.
#include <gtest/gtest.h>

#include <cmath>

#include "idcol/toi.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "report/compare.hpp"
#include "scene/scene.hpp"
#include "studies/toi/toi.hpp"
#include "studies/toi/toi_keys.hpp"
#include "studies/study.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

const char* kScene = R"(
name = "toi test"
[shapes]
ball = { family = "sphere", R = 0.3 }
small = { family = "sphere", R = 0.2 }
[toi]
pairs = [["ball", "small"]]
motions = 40
offset = 3.0
models = ["translation"]
oracle_samples = 200
fcl = []
)";

TEST(Toi, SceneSectionIsReadAndBadValuesNamed) {
  const Scene s = parse_scene(kScene, "t.toml");
  EXPECT_EQ(s.kind, "toi");
  const ToiSpec& toi = s.spec.as<ToiSpec>();
  EXPECT_EQ(toi.motions, 40u);
  EXPECT_EQ(toi.pairs.size(), 1u);
  std::string bad = kScene;
  bad.replace(bad.find("[\"translation\"]"), 15, "[\"spiral\"]");
  try {
    parse_scene(bad, "t.toml");
    FAIL() << "a motion model \"spiral\" was accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.field(), "toi.models");
    EXPECT_NE(std::string(e.what()).find("spiral"), std::string::npos);
  }
}

// Two spheres in translation: |p0 + t d| = R1 + R2 is a quadratic in t.
TEST(Toi, OracleMatchesTheSphereQuadratic) {
  const baselines::ToiOracle o(baselines::geom::make_sphere(0.3), baselines::geom::make_sphere(0.2), {400, 1e-3, 60});
  EXPECT_STREQ(o.method(), "closed_form");
  const Vec3 p0(1.1, 0.2, -0.1), p1(-0.9, 0.05, 0.15);
  baselines::geom::Pose X0(Mat3::Identity(), p0), X1(Mat3::Identity(), p1);
  const baselines::ToiOracleAnswer a = o.first_contact(X0, X1);
  const Vec3 d = p1 - p0;
  const double A = d.dot(d), B = 2 * p0.dot(d), C = p0.dot(p0) - 0.25;
  const double t = (-B - std::sqrt(B * B - 4 * A * C)) / (2 * A);
  ASSERT_TRUE(a.clear_hit);
  EXPECT_NEAR(a.t_lo, t, 1e-12);
  EXPECT_NEAR(a.t_hi, t, 1e-12);
  // The oracle's screw motion is core's (two independent writings).
  const Pose Y0{Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix(), p0};
  const Pose Y1{Eigen::AngleAxisd(-1.9, Vec3(-1, 0.5, 2).normalized()).toRotationMatrix(), p1};
  const baselines::OracleMotion m(Y0, Y1);
  for (double s : {0.0, 0.37, 0.8, 1.0}) {
    const Pose c = screw_interpolate(Y0, Y1, s);
    const baselines::geom::Pose g = m.at(s);
    EXPECT_LT((c.R - g.R).norm() + (c.p - g.p).norm(), 1e-12) << "t = " << s;
  }
}

/// The CI scene's results, run once for the tests that read them.
const json& ci_results() {
  static const json r = [] {
    std::unique_ptr<Study> st = load_study(IDCOL_CONFIGS_DIR "/ci_toi.toml", "toi");
    RecordSink sink;
    return st->run(StudyOptions{}, json::object(), sink);
  }();
  return r;
}

TEST(Toi, CiSceneMissesNoContact) {
  const json& r = ci_results();
  std::uint64_t hits = 0, misses = 0;
  for (const json& e : r.at(key::toi_pairs)) {
    const json& t = e.at(key::idcol_toi);
    EXPECT_EQ(t.at(key::missed_contacts), 0u) << e.at("name");
    EXPECT_EQ(t.at(key::false_impacts), 0u) << e.at("name");
    EXPECT_EQ(t.at(key::failures), 0u) << e.at("name");
    hits += e.at(key::oracle_verdicts).at(key::clear_hits).get<std::uint64_t>();
    misses += e.at(key::oracle_verdicts).at(key::clear_misses).get<std::uint64_t>();
  }
  // The scene has both kinds of motion, so both kinds of error are possible.
  EXPECT_GT(hits, 10u);
  EXPECT_GT(misses, 10u);
}

// A wrong oracle (body 2 taken as 0.45 instead of 0.2) sees contacts the
// solver rightly does not report: the tally counts them as missed, and
// compare fails the results that carry them.
TEST(Toi, AWrongOracleShowsAMissAndCompareFails) {
  const Scene s = parse_scene(kScene, "t.toml");
  const baselines::ToiOracle wrong(baselines::geom::make_sphere(0.3), baselines::geom::make_sphere(0.45), {200, 1e-3, 60});
  const Shape b1 = Sphere(0.3), b2 = Sphere(0.2);
  ToiTally tally;
  const ToiSpec& toi = s.spec.as<ToiSpec>();
  for (std::uint64_t k = 0; k < toi.motions; ++k) {
    const ToiMotion m = toi_motion(toi, 0.5, false, k);
    const ToiResult r = time_of_impact(b1, b2, m.X0, m.X1);
    ToiAnswer a;
    a.hit = r.status == ToiStatus::Impact || r.status == ToiStatus::InitiallyInContact;
    a.initial = r.status == ToiStatus::InitiallyInContact;
    a.t = r.t;
    tally.add(wrong.first_contact(m.X0, m.X1), a);
  }
  EXPECT_GT(tally.missed, 0u);

  const json& good = ci_results();
  json bad = good;
  bad[key::toi_pairs][0][key::idcol_toi] = tally.to_json();
  bad[key::toi_pairs][0][key::idcol_toi][key::us_per_query] = good[key::toi_pairs][0][key::idcol_toi][key::us_per_query];
  EXPECT_EQ(compare_results(good, good, default_guards()).failed, 0);
  const CompareReport rep = compare_results(good, bad, default_guards());
  EXPECT_GT(rep.failed, 0);
  bool miss_failed = false;
  for (const CompareRow& row : rep.rows)
    if (row.metric == "idcol.missed_contacts" && row.verdict == "FAIL") miss_failed = true;
  EXPECT_TRUE(miss_failed) << rep.text();
}

TEST(Toi, ShardsMergeToTheWholeRun) {
  std::string text = kScene;
  text.replace(text.find("pairs = "), std::string("pairs = [[\"ball\", \"small\"]]").size(),
               "pairs = [[\"ball\", \"small\"], [\"small\", \"ball\"]]");
  text.replace(text.find("models = "), std::string("models = [\"translation\"]").size(), "models = [\"translation\", \"screw\"]");
  text.replace(text.find("fcl = []"), 8, "fcl = [\"naive\"]");
  std::unique_ptr<Study> st = study_kind_named("toi")->make(parse_scene(text, "t.toml"));
  RecordSink sink;
  const json whole = st->run(StudyOptions{}, json::object(), sink);
  std::vector<json> shards;
  for (int i = 0; i < 2; ++i) {
    StudyOptions o;
    o.shard_index = i;
    o.shard_count = 2;
    RecordSink sk;
    shards.push_back(st->run(o, json::object(), sk));
  }
  const json merged = st->kind().merge(shards, json::object(), {"a", "b"}, false);
  ASSERT_EQ(whole.at(key::toi_pairs).size(), 4u);
  ASSERT_EQ(merged.at(key::toi_pairs).size(), whole.at(key::toi_pairs).size());
  for (std::size_t i = 0; i < whole.at(key::toi_pairs).size(); ++i) {
    json a = whole[key::toi_pairs][i], b = merged[key::toi_pairs][i];
    for (json* e : {&a, &b}) {
      e->erase("wall_seconds");
      (*e)[key::idcol_toi].erase(key::us_per_query);
      for (auto& [m, t] : (*e)[key::fcl_methods].items()) t.erase(key::us_per_query);
    }
    EXPECT_EQ(a, b) << i;
  }
  EXPECT_THROW(st->kind().merge({shards[0], shards[0]}, json::object(), {"a", "a"}, false), std::invalid_argument);
}

}  // namespace
}  // namespace idcol::harness
