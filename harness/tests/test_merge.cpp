// Sharding: the merged statistics of shards equal the unsharded ones exactly
// (timing aside, which is measured, not computed).
#include <gtest/gtest.h>

#include "studies/sweep/sweep.hpp"
#include "referee/methods.hpp"
#include "scene/scene.hpp"
#include "stats/stats.hpp"
#include "io/files.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

std::string scene_text(const std::string& solver) {
  return R"(
name = "merge_test"
[shapes]
Poly = { family = "smooth_polytope", normals = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1], [-1, -1, -1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]], offsets = [1, 1, 1, 1, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667, 1.6666666666666667], beta = 20 }
SE = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
[sweep]
generator = "paper"
poses = 3001
dt = 1e-3
warm_chain = 250
warmup = 10
[run]
pairs = "all"
passes = ["cold", "warm"]
record = ["timing", "iterations", "residuals", "failures"]
)" + solver;
}

json run_json(const Scene& s, int i, int n) {
  StudyOptions o;
  o.shard_index = i;
  o.shard_count = n;
  return make_results(s, run_scene(s, o), json{{"test", true}});
}

json strip_failure(json f) {
  f.erase("index");
  f.erase("replay");
  return f;
}

void check_merge(const Scene& s, int n) {
  const json whole = run_json(s, 0, 1);
  std::vector<json> parts;
  std::uint64_t covered = 0;
  for (int i = 0; i < n; ++i) {
    parts.push_back(run_json(s, i, n));
    covered += parts.back()["shard"]["poses"][1].get<std::uint64_t>() - parts.back()["shard"]["poses"][0].get<std::uint64_t>();
  }
  EXPECT_EQ(covered, s.poses);
  const json merged = merge_results(parts, json{{"test", true}});
  EXPECT_EQ(without_timing(merged["pairs"]), without_timing(whole["pairs"])) << "shards = " << n;
  // Timing is measured, so only its counts must agree.
  for (std::size_t p = 0; p < whole["pairs"].size(); ++p)
    for (const char* pass : {"cold", "warm"})
      EXPECT_EQ(merged["pairs"][p]["passes"][pass]["time"]["all"]["count"], whole["pairs"][p]["passes"][pass]["time"]["all"]["count"]);
  // Shards give merge the whole sweep back, and refuse anything else.
  EXPECT_EQ(merged["shard"]["poses"][1].get<std::uint64_t>(), s.poses);
  if (n > 1) {
    std::vector<json> missing(parts.begin(), parts.end() - 1);
    EXPECT_THROW(merge_results(missing, json{}), std::invalid_argument);
    std::vector<json> twice = parts;
    twice.back() = parts.front();
    EXPECT_THROW(merge_results(twice, json{}), std::invalid_argument);
  }
}

TEST(ShardMerge, ReproducesUnshardedAggregatesExactly) {
  const Scene s = parse_scene(scene_text(""), "merge_test.toml");
  check_merge(s, 3);
  check_merge(s, 5);  // 13 chains over 5 shards: uneven
}

// record = ["checks"]: every converged answer of a sweep is checked (surfaces,
// normals, the pair's oracle), counted per pass, and the counts merge
// exactly across shards.
TEST(ShardMerge, SweepAnswerChecksCountEveryConvergedSolveAndMerge) {
  std::string text = scene_text("");
  text.replace(text.find("\"timing\", "), 10, "");
  text.replace(text.find("\"failures\"]"), 11, "\"failures\", \"checks\"]");
  // 2 warm-start chains of 100 (and 51): a shard each.
  text.replace(text.find("poses = 3001"), 12, "poses = 151");
  text.replace(text.find("warm_chain = 250"), 16, "warm_chain = 100");
  const Scene s = parse_scene(text, "checks.toml");
  ASSERT_TRUE(s.spec.as<SweepSpec>().record.checks);
  const json whole = run_json(s, 0, 1);
  for (const auto& p : whole.at("pairs"))
    for (const auto& [name, pass] : p.at("passes").items()) {
      const json& c = pass.at("checks");
      EXPECT_EQ(c.at("checked").get<std::uint64_t>(), pass.at("status").at("converged").get<std::uint64_t>()) << name;
      EXPECT_GT(c.at("checked").get<std::uint64_t>(), 0u);
      EXPECT_EQ(c.at("false_convergence").at("total"), 0) << p.at("body1") << "-" << p.at("body2") << " " << name << " " << c;
      EXPECT_LT(c.at("worst_surface_error").get<double>(), 1e-8);
    }
  // Poly-Poly is judged by the LP's smoothing bracket where the oracles are built.
  if (baselines_available()) EXPECT_EQ(whole.at("pairs")[0].at("passes").at("cold").at("checks").at("oracle_failed"), 0);
  const json merged = merge_results({run_json(s, 0, 2), run_json(s, 1, 2)}, json{});
  EXPECT_EQ(without_timing(merged["pairs"]), without_timing(whole["pairs"]));
}

TEST(ShardMerge, ReproducesFailureCountsAndRecords) {
  // A starved solver fails often, so the failure statistics are exercised.
  const Scene s = parse_scene(scene_text("[solver]\nmax_iterations = 5\nmax_restarts = 0\ncontinuation = false\nbarrier = false\n"), "merge_test.toml");
  StudyOptions o;
  o.max_traced_failures = std::size_t(-1);
  const RunOutput whole = run_scene(s, o);
  ASSERT_GT(whole.failures.size(), 0u);
  json shard_failures = json::array();
  std::vector<json> parts;
  for (int i = 0; i < 4; ++i) {
    o.shard_index = i;
    o.shard_count = 4;
    const RunOutput r = run_scene(s, o);
    parts.push_back(make_results(s, r, json{}));
    for (const auto& f : r.failures) shard_failures.push_back(f);
  }
  const json merged = merge_results(parts, json{});
  EXPECT_EQ(without_timing(merged["pairs"]), without_timing(make_results(s, whole, json{})["pairs"]));
  // The same failures, pair by pair and pass by pass (the order differs).
  auto key = [](const json& f) {
    return f["body1"].get<std::string>() + f["body2"].get<std::string>() + f["pass"].get<std::string>() +
           std::to_string(f["k"].get<std::uint64_t>());
  };
  std::map<std::string, json> a, b;
  for (const auto& f : whole.failures) a[key(f)] = strip_failure(f);
  for (const auto& f : shard_failures) b[key(f)] = strip_failure(f);
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [k, f] : a) {
    ASSERT_TRUE(b.count(k)) << k;
    for (const auto& [field, v] : f.items()) EXPECT_EQ(v, b[k][field]) << k << " field " << field;
  }
  // Every failure record's trace re-solve reproduces its status.
  for (const auto& f : whole.failures) EXPECT_EQ(f["trace_status"], f["status"]);
}

// Merge errors name the input they cannot use and, for a lost shard, which
// shard to rerun: a sweep spread over a scheduler must be repairable from the
// message alone.
std::string merge_error(const std::vector<json>& parts, const std::vector<std::string>& names) {
  try {
    merge_results(parts, json{}, names);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ShardMerge, ErrorsNameTheInputAndTheMissingShard) {
  const Scene s = parse_scene(scene_text(""), "merge_test.toml");
  std::vector<json> parts;
  std::vector<std::string> names;
  for (int i = 0; i < 4; ++i) {
    parts.push_back(run_json(s, i, 4));
    names.push_back("out/s" + std::to_string(i) + ".json");
  }
  // A killed shard: its file is simply absent.
  std::vector<json> lost = parts;
  std::vector<std::string> lost_names = names;
  lost.erase(lost.begin() + 2);
  lost_names.erase(lost_names.begin() + 2);
  EXPECT_NE(merge_error(lost, lost_names).find("shard 2/4 is missing"), std::string::npos) << merge_error(lost, lost_names);
  EXPECT_NE(merge_error(lost, lost_names).find("--shard i/4"), std::string::npos);
  // Several lost shards are all named.
  std::vector<json> two(parts.begin(), parts.begin() + 2);
  EXPECT_NE(merge_error(two, {}).find("shards 2/4, 3/4 are missing"), std::string::npos) << merge_error(two, {});
  // A failures file picked up by a glob (the README recipe's old bug).
  std::vector<json> with_failures = parts;
  with_failures.insert(with_failures.begin(), json{{"schema", kFailuresSchema}, {"schema_version", 1}, {"failures", json::array()}});
  std::vector<std::string> with_failures_names = names;
  with_failures_names.insert(with_failures_names.begin(), "out/s0.failures.json");
  const std::string e = merge_error(with_failures, with_failures_names);
  EXPECT_NE(e.find("out/s0.failures.json is not a results file"), std::string::npos) << e;
  EXPECT_NE(e.find("a failures file"), std::string::npos) << e;
  // The same shard twice names both files.
  std::vector<json> twice = parts;
  twice[3] = parts[1];
  EXPECT_NE(merge_error(twice, names).find("shard 1/4 given twice: out/s1.json and out/s3.json"), std::string::npos)
      << merge_error(twice, names);
  // A results file with a key cut out names the file and the key.
  std::vector<json> damaged = parts;
  damaged[1].erase("shard");
  EXPECT_NE(merge_error(damaged, names).find("out/s1.json is a damaged results file"), std::string::npos)
      << merge_error(damaged, names);
  // A shard of another sweep.
  std::vector<json> other = parts;
  other[2] = run_json(s, 1, 3);
  EXPECT_NE(merge_error(other, names).find("out/s2.json is shard 1/3"), std::string::npos) << merge_error(other, names);
  // Shards of another build: refused by name and field, merged with allow_mixed.
  std::vector<json> mixed = parts;
  for (json& p : mixed) p["metadata"] = {{"git_revision", "aaaa"}, {"cpu_model", "X"}};
  mixed[3]["metadata"]["git_revision"] = "bbbb";
  const std::string m = merge_error(mixed, names);
  EXPECT_NE(m.find("out/s3.json was made with git_revision \"bbbb\", out/s0.json with \"aaaa\""), std::string::npos) << m;
  EXPECT_NE(m.find("--allow-mixed"), std::string::npos) << m;
  const json ok = merge_results(mixed, json{{"merge", true}}, names, true);
  EXPECT_EQ(ok["metadata"]["mixed_shards"], json::array({"git_revision"}));
  EXPECT_EQ(ok["shard"]["merged_from"][3]["metadata"]["git_revision"], "bbbb");
  // Another CPU matters for a timed sweep (this scene records timing).
  mixed[3]["metadata"]["git_revision"] = "aaaa";
  mixed[2]["metadata"]["cpu_model"] = "Y";
  EXPECT_NE(merge_error(mixed, names).find("out/s2.json was made with cpu_model \"Y\""), std::string::npos) << merge_error(mixed, names);
  // Without names, the position stands in for the path.
  EXPECT_NE(merge_error(damaged, {}).find("results file 1 (counting from 0)"), std::string::npos);
}

// Merge takes the shards by their index, in whatever order they are given
// (a shell glob sorts s10.json before s2.json).
TEST(ShardMerge, ShardsGivenInAnyOrderMergeTheSame) {
  const Scene s = parse_scene(scene_text(""), "merge_test.toml");
  const std::vector<json> parts = {run_json(s, 0, 3), run_json(s, 1, 3), run_json(s, 2, 3)};
  const json in_order = merge_results(parts, json{});
  const json reversed = merge_results({parts[2], parts[1], parts[0]}, json{});
  EXPECT_EQ(without_timing(reversed["pairs"]), without_timing(in_order["pairs"]));
  EXPECT_EQ(reversed["shard"]["poses"], in_order["shard"]["poses"]);
}

// A shard written before a count existed cannot be merged (0 would claim a
// count nobody made): the error names that file, where, the count, and why.
TEST(ShardMerge, AFileWithoutACountNamesTheFileAndTheCount) {
  const Scene s = parse_scene(scene_text(""), "merge_test.toml");
  const std::vector<json> parts = {run_json(s, 0, 2), run_json(s, 1, 2)};
  const std::vector<std::string> names = {"out/s0.json", "out/s1.json"};
  for (std::size_t k : {0, 1}) {
    std::vector<json> old = parts;
    old[k]["pairs"][1]["passes"]["warm"].erase("restarts");
    const std::string e = merge_error(old, names);
    EXPECT_NE(e.find(names[k] + ": pairs[1].passes.warm: no \"restarts\": the file predates that field"), std::string::npos) << e;
  }
}

// Pairs are matched by name: a shard whose pairs come in another order
// (its SE-TC figures once landed in SE-SE) merges as if in order; a shard
// with another pair, or the same pair twice, is refused by name.
TEST(ShardMerge, PairsAreMatchedByNameNotPosition) {
  const Scene s = parse_scene(scene_text(""), "merge_test.toml");
  const std::vector<json> parts = {run_json(s, 0, 2), run_json(s, 1, 2)};
  const std::vector<std::string> names = {"out/s0.json", "out/s1.json"};
  const json in_order = merge_results(parts, json{}, names);
  ASSERT_EQ(parts[1]["pairs"].size(), 3u);
  std::vector<json> reordered = parts;
  std::swap(reordered[1]["pairs"][0], reordered[1]["pairs"][2]);
  EXPECT_EQ(without_timing(merge_results(reordered, json{}, names)["pairs"]), without_timing(in_order["pairs"]));
  std::vector<json> renamed = parts;
  renamed[1]["pairs"][2]["body2"] = "TC";
  std::string e = merge_error(renamed, names);
  EXPECT_NE(e.find("out/s1.json has no pair [SE, SE], which out/s0.json holds"), std::string::npos) << e;
  std::vector<json> twice = parts;
  twice[1]["pairs"][2] = twice[1]["pairs"][1];
  e = merge_error(twice, names);
  EXPECT_NE(e.find("out/s1.json holds the pair [Poly, SE] twice"), std::string::npos) << e;
  std::vector<json> fewer = parts;
  fewer[1]["pairs"].erase(2);
  e = merge_error(fewer, names);
  EXPECT_NE(e.find("out/s1.json holds 2 pairs, out/s0.json 3"), std::string::npos) << e;
}

// A count is an integer in [0, 2^64): a negative one, one of 2^64 or more
// (read as a float) and a sum past 2^64 - 1 are refused naming the file and
// the count, never wrapped.
TEST(ShardMerge, NegativeOrOverflowingCountsAreRefused) {
  const Scene s = parse_scene(scene_text(""), "merge_test.toml");
  const std::vector<json> parts = {run_json(s, 0, 2), run_json(s, 1, 2)};
  const std::vector<std::string> names = {"out/s0.json", "out/s1.json"};
  auto with_count = [&](std::size_t k, const char* key, const json& v) {
    std::vector<json> p = parts;
    p[k]["pairs"][1]["passes"]["warm"][key] = v;
    return merge_error(p, names);
  };
  std::string e = with_count(1, "solves", -5);
  EXPECT_NE(e.find("out/s1.json: pairs[1].passes.warm.solves: expected a count (an integer in [0, 2^64)), got -5"), std::string::npos) << e;
  e = with_count(0, "restarts", json::parse("18446744073709551616"));
  EXPECT_NE(e.find("out/s0.json: pairs[1].passes.warm.restarts: expected a count"), std::string::npos) << e;
  EXPECT_NE(e.find("2^64 or more"), std::string::npos) << e;
  std::vector<json> big = parts;
  for (json& p : big) p["pairs"][1]["passes"]["warm"]["solves"] = std::uint64_t{1} << 63;
  e = merge_error(big, names);
  EXPECT_NE(e.find("out/s1.json: pairs[1].passes.warm.solves: 9223372036854775808 + 9223372036854775808 passes 2^64 - 1"),
            std::string::npos) << e;
  std::vector<json> hist = parts;
  hist[1]["pairs"][0]["passes"]["cold"]["status"]["converged"] = -1;
  e = merge_error(hist, names);
  EXPECT_NE(e.find("out/s1.json: pairs[0].passes.cold.status.converged: expected a count"), std::string::npos) << e;
  // A bin index past the binning and an iteration key that is no count:
  // named, not "vector::_M_range_check" or "stoi".
  std::vector<json> bins = parts;
  bins[1]["pairs"][1]["passes"]["cold"]["residual"]["all"]["histogram"]["bins"] = json::array({json::array({99999, 1})});
  e = merge_error(bins, names);
  EXPECT_NE(e.find("out/s1.json: pairs[1].passes.cold.bins: bin index 99999 past the"), std::string::npos) << e;
  for (const char* key : {"abc", "99999999999", "-1", ""}) {
    std::vector<json> keys = parts;
    keys[1]["pairs"][1]["passes"]["cold"]["iterations"]["histogram"] = json{{key, 3}};
    e = merge_error(keys, names);
    EXPECT_NE(e.find("out/s1.json: pairs[1].passes.cold.iterations.histogram: key \"" + std::string(key) + "\" is not an iteration count"),
              std::string::npos) << e;
  }
}

TEST(LogHistogram, QuantilesAndMerge) {
  LogHistogram h(0, 10, 100), a(0, 10, 100), b(0, 10, 100);
  for (int i = 1; i <= 1000; ++i) {
    h.add(i);
    (i % 3 ? a : b).add(i);
  }
  a.merge(b);
  EXPECT_TRUE(a.same_counts(h));
  EXPECT_EQ(a.max(), 1000.0);
  EXPECT_NEAR(h.quantile(0.5), 500.0, 500.0 * 0.025);
  EXPECT_NEAR(h.quantile(0.99), 990.0, 990.0 * 0.025);
  EXPECT_EQ(LogHistogram::from_json(h.to_json()).to_json(), h.to_json());
}

}  // namespace
}  // namespace idcol::harness

namespace idcol::harness {
namespace {

TEST(Threads, NonTimingSweepEqualsSingleThreaded) {
  std::string text = scene_text("[solver]\nmax_iterations = 6\nmax_restarts = 0\ncontinuation = false\nbarrier = false\n");
  text.replace(text.find("\"timing\", "), 10, "");
  const Scene s = parse_scene(text, "threads.toml");
  StudyOptions one, three;
  three.threads = 3;
  // Which failures get a trace past the cap depends on thread timing; trace all.
  one.max_traced_failures = three.max_traced_failures = std::size_t(-1);
  const RunOutput a = run_scene(s, one), b = run_scene(s, three);
  EXPECT_EQ(make_results(s, a, json{})["pairs"], make_results(s, b, json{})["pairs"]);
  ASSERT_GT(a.failures.size(), 0u);
  EXPECT_EQ(a.failures, b.failures);  // same records in the same order
  // Timing scenes refuse threads.
  const Scene timed = parse_scene(scene_text(""), "timed.toml");
  EXPECT_THROW(run_scene(timed, three), std::invalid_argument);
}

}  // namespace
}  // namespace idcol::harness
