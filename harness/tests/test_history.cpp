// history add / show: the series key separates scenes that cannot be
// compared and nothing else; a line holds the guarded metrics as the
// results file has them; steps are found where a metric moves beyond its
// guard and stays; the table and the page show each series apart.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "io/files.hpp"
#include "report/history.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

const std::string kDir = IDCOL_HARNESS_FIXTURES_DIR;
const std::string kThresholds = IDCOL_THRESHOLDS_FILE;

/// The compare fixture as a run of the scene "s" at git `rev`, made on `host`.
json run_at(const std::string& rev, const std::string& host = "box", const std::string& date = "2026-01-01T00:00:00Z") {
  json r = read_json_file(kDir + "/compare_old.json");
  r["scene"] = {{"name", "s"}, {"path", "s.toml"}, {"content", "# a scene\nname = \"s\"\n[sweep]\nposes = 1000  # enough\n"}};
  r["metadata"] = {{"git_revision", rev}, {"git_dirty", false}, {"date_utc", date}, {"host", host}, {"cpu_model", "CPU"},
                   {"compiler", "GNU 12"}, {"cxx_flags", "-O3"}, {"build_type", "Release"}, {"native", false}};
  r["solver"] = {{"tolerance", 1e-10}};
  r["shard"] = {{"index", 0}, {"count", 1}};
  return r;
}

std::string key_of(const json& r) { return series_key(scene_identity(r)); }

std::string temp_path(const char* name) {
  return (::testing::TempDir() + "/idcol_history_" + std::to_string(::getpid()) + "_" + name);
}

TEST(HistorySeries, SameSceneSameKeyWhateverTheBuildOrMachine) {
  const json a = run_at("aaaa"), b = run_at("bbbb", "other");
  json c = a;
  c["solver"]["support_guess"] = true;  // a new default of the solver: what the history tracks
  c["scene"]["content"] = "name = \"s\"   # the scene, reworded comment\n\n[sweep]\nposes = 1000\n";
  c["scene"]["path"] = "elsewhere/s.toml";
  c["wall_seconds"] = 99.0;
  EXPECT_EQ(key_of(a), key_of(b));
  EXPECT_EQ(key_of(a), key_of(c));
  EXPECT_EQ(key_of(a).rfind("sweep:s:", 0), 0u) << key_of(a);
}

TEST(HistorySeries, ScenesThatCannotBeComparedDiffer) {
  const json a = run_at("aaaa");
  json poses = a, text = a, shard = a, pairs = a, hash_in_string = a;
  poses["sweep"]["poses"] = 2000;
  text["scene"]["content"] = "name = \"s\"\n[sweep]\nposes = 1001\n";
  shard["shard"] = {{"index", 0}, {"count", 2}};
  pairs["pairs"].erase(1);
  // A '#' inside a string is not a comment: the text differs.
  hash_in_string["scene"]["content"] = "# a scene\nname = \"s#1\"\n[sweep]\nposes = 1000  # enough\n";
  for (const json* other : {&poses, &text, &shard, &pairs, &hash_in_string}) EXPECT_NE(key_of(a), key_of(*other));
  json stress = read_json_file(kDir + "/compare_stress.json");
  EXPECT_EQ(key_of(stress).rfind("stress:", 0), 0u);
}

TEST(HistorySeries, NotAResultsFileIsNamed) {
  try {
    scene_identity(json{{"schema", "something-else"}});
    FAIL() << "no error";
  } catch (const HistoryError& e) {
    EXPECT_NE(std::string(e.what()).find("\"something-else\""), std::string::npos) << e.what();
  }
}

TEST(HistoryRecord, GuardedMetricsAsTheFileHasThem) {
  const json r = run_at("0123456789abcdef");
  const json rec = history_record(r, guards_in_force(load_guards(kThresholds)), nullptr, "x.json");
  // Read straight from the results file, not through the metric table.
  const json& ab = rec.at("entries").at("A-B");
  EXPECT_EQ(ab.at("cold.convergence_rate").get<double>(), r["pairs"][1]["passes"]["cold"]["convergence_rate"].get<double>());
  EXPECT_EQ(ab.at("cold.iterations.mean").get<double>(), r["pairs"][1]["passes"]["cold"]["iterations"]["mean"].get<double>());
  EXPECT_EQ(ab.at("derivatives.agreement").get<double>(), 0.99);
  EXPECT_EQ(ab.at("baselines.fcl_collide.genuine").get<double>(), 0.0);
  // worst_error has no guard in the thresholds file but a declared default: in the history.
  EXPECT_TRUE(ab.contains("derivatives.worst_error"));
  EXPECT_EQ(rec.at("run").at("git_revision"), "0123456789abcdef");
  EXPECT_EQ(rec.at("run").at("machine"), "box (CPU), GNU 12, Release -O3");
  EXPECT_EQ(rec.at("series"), key_of(r));
  // Only the guards that matched are kept, in the file's order.
  ASSERT_FALSE(rec.at("guards").empty());
  bool convergence_guarded = false;
  for (const json& g : rec.at("guards")) convergence_guarded |= g.at("metric") == "cold.convergence_rate" || g.at("metric") == "*.convergence_rate";
  EXPECT_TRUE(convergence_guarded) << rec.at("guards").dump();
  // Without a thresholds file: compare's default guards (iterations only informational).
  const json def = history_record(r, default_guards(), nullptr, "x.json");
  EXPECT_TRUE(def.at("entries").at("A-B").contains("cold.convergence_rate"));
  EXPECT_FALSE(def.at("entries").at("A-B").contains("cold.iterations.mean"));
}

TEST(HistoryRecord, OneLineSortedKeysRoundTrip) {
  json r = run_at("aaaa");
  r["pairs"][0]["passes"]["cold"]["convergence_rate"] = 0.1 + 0.2;  // not representable in few digits
  const std::string line = history_line(history_record(r, guards_in_force(load_guards(kThresholds)), nullptr, "x.json"));
  ASSERT_EQ(line.back(), '\n');
  EXPECT_EQ(line.find('\n'), line.size() - 1);
  const json back = json::parse(line);
  EXPECT_EQ(back.dump() + "\n", line);  // nlohmann's objects keep sorted keys: the line is canonical
  EXPECT_LT(line.find("\"entries\""), line.find("\"guards\""));
  EXPECT_EQ(back["entries"]["A-A"]["cold.convergence_rate"].get<double>(), 0.1 + 0.2);
}

TEST(HistoryRecord, InstructionsPerSolveOfTheSameRevision) {
  const json r = run_at("aaaa");
  json ir = {{"schema", kInstructionsSchema},
             {"git_revision", "aaaa"},
             {"driver", "test"},
             {"pairs", {{"A-B", {{"cold", {{"solves", 200}, {"instructions", 3000000}}}, {"warm", {{"solves", 2000}, {"instructions", 9000000}}}}}}}};
  const json rec = history_record(r, guards_in_force(load_guards(kThresholds)), ir, "x.json");
  EXPECT_EQ(rec["entries"]["A-B"]["cold.instructions_per_solve"].get<double>(), 15000.0);
  EXPECT_EQ(rec["entries"]["A-B"]["warm.instructions_per_solve"].get<double>(), 4500.0);
  EXPECT_EQ(rec["instructions"]["driver"], "test");
  EXPECT_FALSE(rec["instructions"].contains("pairs"));
  EXPECT_EQ(rec["guards"].back()["metric"], "*.instructions_per_solve");
  ir["git_revision"] = "bbbb";
  EXPECT_THROW(history_record(r, guards_in_force(load_guards(kThresholds)), ir, "x.json"), HistoryError);
  ir["git_revision"] = "aaaa";
  ir["pairs"]["A-B"]["cold"]["solves"] = 0;
  EXPECT_THROW(history_record(r, guards_in_force(load_guards(kThresholds)), ir, "x.json"), HistoryError);
  EXPECT_THROW(history_record(r, guards_in_force(load_guards(kThresholds)), json{{"schema", "x"}}, "x.json"), HistoryError);
}

TEST(HistoryFile, AppendsRefusesTheSameRunAndNamesABadLine) {
  const std::string path = temp_path("append.jsonl");
  std::remove(path.c_str());
  const auto g = guards_in_force(load_guards(kThresholds));
  append_history(path, history_record(run_at("aaaa"), g, nullptr, "a.json"));
  append_history(path, history_record(run_at("bbbb"), g, nullptr, "b.json"));
  EXPECT_THROW(append_history(path, history_record(run_at("bbbb"), g, nullptr, "b.json")), HistoryError);
  EXPECT_EQ(read_history(path).size(), 2u);
  {
    std::ofstream(path, std::ios::app) << "{not json\n";
  }
  try {
    read_history(path);
    FAIL() << "no error";
  } catch (const HistoryError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3:"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

Guard guard(bool higher, double abs, double rel) {
  Guard g;
  g.pattern = "*";
  g.higher_is_better = higher;
  g.abs = abs;
  g.rel = rel;
  g.origin = "test";
  return g;
}

TEST(HistorySteps, AStepThatStaysIsMarkedAtItsFirstCommit) {
  const auto s = find_steps({1.0, 1.0, 0.99, 0.99, 0.995}, guard(true, 0.0, 0.0));
  // 1 -> 0.99 stays below 1 (0.995 included): one worse step at commit 2;
  // 0.99 -> 0.995 is a better step at commit 4 (the last value).
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].index, 2u);
  EXPECT_FALSE(s[0].better);
  EXPECT_EQ(s[0].before, 1.0);
  EXPECT_EQ(s[0].after, 0.99);
  EXPECT_EQ(s[1].index, 4u);
  EXPECT_TRUE(s[1].better);
}

TEST(HistorySteps, SpikesDriftWithinTheGuardAndGapsAreNotSteps) {
  EXPECT_TRUE(find_steps({1.0, 1.0, 0.9, 1.0, 1.0}, guard(true, 0.0, 0.0)).empty());  // came back
  EXPECT_TRUE(find_steps({10.0, 10.2, 10.4, 10.6}, guard(false, 0.0, 0.05)).empty());  // each move within 5%
  const auto s = find_steps({10.0, 10.0, 12.0, 12.1}, guard(false, 0.0, 0.05));
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].index, 2u);
  EXPECT_FALSE(s[0].better);  // lower is better, it went up
  const auto gap = find_steps({5.0, NAN, 3.0, 3.0}, guard(false, 1.0, 0.0));
  ASSERT_EQ(gap.size(), 1u);
  EXPECT_EQ(gap[0].index, 2u);
  EXPECT_TRUE(gap[0].better);
  EXPECT_TRUE(find_steps({5.0, 5.0 * (1 + 1e-12)}, guard(false, 0.0, 0.0)).empty());  // rounding
}

std::vector<json> three_commits() {
  const auto g = guards_in_force(load_guards(kThresholds));
  std::vector<json> h;
  for (int i = 0; i < 3; ++i) {
    json r = run_at(std::string("rev") + char('a' + i) + "0000000");
    if (i >= 1) r["pairs"][1]["passes"]["cold"]["convergence_rate"] = 0.98;
    h.push_back(history_record(r, g, nullptr, "r.json"));
  }
  json other = run_at("revb0000000", "box2");  // a second machine at the middle commit
  h.push_back(history_record(other, g, nullptr, "r.json"));
  json apart = run_at("revc0000000");
  apart["sweep"]["poses"] = 50;  // another cut: a series of its own
  h.push_back(history_record(apart, g, nullptr, "r.json"));
  return h;
}

TEST(HistoryShow, TableShowsTheSeriesApartAndTheStep) {
  const std::string t = history_table(three_commits(), {"*.convergence_rate", "A-B"});
  EXPECT_NE(t.find("3 commits on 2 machines"), std::string::npos) << t;
  EXPECT_NE(t.find("1 run over 1 commit on 1 machine"), std::string::npos) << t;
  EXPECT_NE(t.find("revb000 worse (1 -> 0.98)"), std::string::npos) << t;
  EXPECT_EQ(t.find("A-A"), std::string::npos) << t;  // filtered out
  EXPECT_EQ(t.find("iterations"), std::string::npos) << t;
}

TEST(HistoryShow, PageHasOnePlotPerMetricAndPairAndNoScript) {
  const auto h = three_commits();
  std::size_t plots = 0;
  const std::string page = history_html(h, {"*.convergence_rate", ""}, &plots);
  // Series 1: A-A and A-B; series 2: A-A and A-B.
  EXPECT_EQ(plots, 4u);
  std::size_t svgs = 0;
  for (std::size_t at = page.find("<svg"); at != std::string::npos; at = page.find("<svg", at + 1)) ++svgs;
  EXPECT_EQ(svgs, plots);
  EXPECT_EQ(page.find("<script"), std::string::npos);
  EXPECT_EQ(page.find("src="), std::string::npos);  // nothing fetched
  EXPECT_EQ(page.find("href=\"http"), std::string::npos);
  EXPECT_NE(page.find("step at revb000 worse"), std::string::npos);
  EXPECT_NE(page.find("fraction of solves"), std::string::npos);  // the axis says its unit
  EXPECT_THROW(history_html(h, {"bad glob", ""}), HistoryError);
}

TEST(HistoryShow, ValuesOneUlpApartDrawAFlatPlot) {
  // Ticks finer than the values' spacing in binary would never advance.
  const auto g = guards_in_force(load_guards(kThresholds));
  std::vector<json> h;
  for (int i = 0; i < 2; ++i) {
    json r = run_at(std::string("rev") + char('a' + i));
    r["pairs"][1]["passes"]["cold"]["iterations"]["mean"] = i == 0 ? 30865.1 : std::nextafter(30865.1, 1e9);
    h.push_back(history_record(r, g, nullptr, "r.json"));
  }
  std::size_t plots = 0;
  const std::string page = history_html(h, {"cold.iterations.mean", "A-B"}, &plots);
  EXPECT_EQ(plots, 1u);
  EXPECT_LT(page.size(), 20000u);
}

int run(const std::string& cmd) {
  const int rc = std::system((cmd + " > /dev/null 2>&1").c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(HistoryCli, AddShowAndBadInput) {
  const std::string exe = IDCOL_HARNESS_EXE;
  const std::string res = temp_path("r.json"), hist = temp_path("h.jsonl"), page = temp_path("p.html");
  std::remove(hist.c_str());
  write_file_atomically(res, run_at("cafe").dump());
  EXPECT_EQ(run(exe + " history add " + res + " --into " + hist + " --thresholds " + kThresholds), 0);
  EXPECT_EQ(run(exe + " history add " + res + " --into " + hist), 2);  // the same run again
  EXPECT_EQ(run(exe + " history show " + hist), 0);
  EXPECT_EQ(run(exe + " history show " + hist + " --html " + page + " --metric '*.failures'"), 0);
  EXPECT_EQ(run(exe + " history show " + hist + " --html " + hist), 2);  // would overwrite its input
  EXPECT_EQ(run(exe + " history add " + kThresholds + " --into " + hist), 2);  // not JSON
  EXPECT_EQ(run(exe + " history add " + kDir + "/compare_corrupt.json --into " + hist), 2);
  EXPECT_EQ(run(exe + " history frobnicate"), 2);
  EXPECT_EQ(run(exe + " history show /nonexistent/h.jsonl"), 2);
  EXPECT_EQ(read_history(hist).size(), 1u);
  for (const std::string& p : {res, hist, page}) std::remove(p.c_str());
}

}  // namespace
}  // namespace idcol::harness
