// The declared metrics (studies/metric.hpp): every figure compare reads is
// declared once with its guard and merge rule, the default guards are read
// off the declarations, and a merge of shards equals the single run in every
// metric not declared as timing.
#include <gtest/gtest.h>

#include <fnmatch.h>

#include <cmath>
#include <set>

#include "report/compare.hpp"
#include "scene/scene.hpp"
#include "studies/sweep/sweep.hpp"
#include "studies/metric.hpp"
#include "studies/study.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

// Each kind's entry with every metric, as compare reads it.
std::vector<std::pair<std::string, double>> all_metrics(const StudyKind& k) {
  return entry_metrics(k.metrics(), json::parse(k.full_entry));
}

TEST(Metrics, EveryMetricCompareReadsIsDeclaredOnce) {
  for (const StudyKind& k : study_kinds()) {
    SCOPED_TRACE(k.name);
    std::set<std::string> names;
    for (const auto& [name, value] : all_metrics(k)) {
      EXPECT_TRUE(names.insert(name).second) << name << " read twice";
      const Metric* m = find_metric(k.metrics(), name);
      ASSERT_NE(m, nullptr) << name << " has no declaration";
      EXPECT_NE(std::string(m->unit), "") << name;
    }
    EXPECT_GT(names.size(), 4u);
  }
}

// The guards compare applied before the metrics were declared, written out
// here as they were: the declared defaults must still guard those metrics,
// at least as tightly (guards are only ever added or tightened).
TEST(Metrics, DefaultGuardsAreReadOffTheDeclarations) {
  struct Old {
    const char* pattern;
    bool higher;
    double rel;
    bool fail;
    double abs = 0.0;
  };
  const Old before[] = {{"*.convergence_rate", true, 0.0, true},  {"*.genuine_rate", true, 0.0, true},
                        {"*.converged_fraction", true, 0.0, true}, {"*.failures", false, 0.0, true},
                        {"*.false_convergence.total", false, 0.0, true}, {"*.time.median_us", false, 0.3, false},
                        {"*.time.p99_us", false, 0.5, false},
                        // the time-of-impact study's (studies/toi/toi_metrics.cpp)
                        {"idcol.missed_contacts", false, 0.0, true}, {"idcol.false_impacts", false, 0.0, true},
                        {"idcol.t_error.max", false, 0.0, true, 1e-8}, {"idcol.us_per_query", false, 0.5, false}};
  const std::vector<Guard> now = default_guards();
  std::size_t guarded = 0, declared = 0;
  for (const StudyKind& k : study_kinds())
    for (const auto& [name, value] : all_metrics(k)) {
      SCOPED_TRACE(std::string(k.name) + ": " + name);
      const Old* o = nullptr;
      for (const Old& g : before)
        if (!o && fnmatch(g.pattern, name.c_str(), 0) == 0) o = &g;
      const Guard* n = nullptr;
      for (const Guard& g : now)
        if (!n && fnmatch(g.pattern.c_str(), name.c_str(), 0) == 0) n = &g;
      declared += n != nullptr;
      if (!o) continue;
      ASSERT_NE(n, nullptr);
      ++guarded;
      EXPECT_EQ(n->higher_is_better, o->higher);
      EXPECT_LE(n->rel, o->rel);
      EXPECT_LE(n->abs, o->abs);
      EXPECT_GE(n->fail, o->fail);
    }
  EXPECT_GE(guarded, 10u);
  EXPECT_GT(declared, guarded);
}

// A shard merge gives every declared metric of the single run but timing.
TEST(Metrics, SweepShardsMergeToTheSingleRunInEveryNonTimingMetric) {
  const Scene s = parse_scene(R"(
name = "metrics_merge"
[shapes]
Poly = { family = "smooth_polytope", normals = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1], [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], offsets = [1, 1, 1, 1, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667], beta = 20 }
SE = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
[sweep]
generator = "paper"
poses = 151
dt = 1e-3
warm_chain = 50
warmup = 10
[run]
pairs = "all"
passes = ["cold", "warm"]
record = ["timing", "iterations", "checks"]
)",
                              "metrics_merge.toml");
  auto run = [&](int i, int n) {
    StudyOptions o;
    o.shard_index = i;
    o.shard_count = n;
    return make_results(s, run_scene(s, o), json{{"test", true}});
  };
  const json whole = run(0, 1);
  const json merged = merge_results({run(0, 3), run(1, 3), run(2, 3)}, json{});
  const StudyKind& k = *study_kind_named("sweep");
  ASSERT_EQ(whole.at("pairs").size(), merged.at("pairs").size());
  std::size_t compared = 0;
  for (std::size_t p = 0; p < whole.at("pairs").size(); ++p) {
    const auto a = entry_metrics(k.metrics(), whole["pairs"][p]);
    const auto b = entry_metrics(k.metrics(), merged["pairs"][p]);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].first, b[i].first);
      if (find_metric(k.metrics(), a[i].first)->timing) continue;
      ++compared;
      if (std::isnan(a[i].second)) EXPECT_TRUE(std::isnan(b[i].second)) << a[i].first;
      else EXPECT_EQ(a[i].second, b[i].second) << a[i].first;
    }
  }
  EXPECT_GE(compared, 3u * 6u);
}

}  // namespace
}  // namespace idcol::harness
