// compare on fixture files: a regression is caught, an improvement passes,
// a missing pair and a corrupt file are clear errors.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <string>

#include "report/compare.hpp"
#include "io/files.hpp"

namespace idcol::harness {
namespace {

const std::string kDir = IDCOL_HARNESS_FIXTURES_DIR;
const std::string kThresholds = IDCOL_THRESHOLDS_FILE;  // the checked-in results/baseline/thresholds.toml

nlohmann::json fixture(const std::string& name) { return read_json_file(kDir + "/" + name); }

const CompareRow* row(const CompareReport& r, const std::string& pair, const std::string& metric) {
  for (const auto& x : r.rows)
    if (x.pair == pair && x.metric == metric) return &x;
  return nullptr;
}

TEST(Compare, UnchangedPasses) {
  const auto g = load_guards(kThresholds);
  const CompareReport r = compare_results(fixture("compare_old.json"), fixture("compare_old.json"), g);
  EXPECT_EQ(r.failed, 0);
  EXPECT_EQ(r.warned, 0);
  for (const auto& x : r.rows) EXPECT_EQ(x.verdict, "same") << x.pair << " " << x.metric;
}

TEST(Compare, RegressionIsCaughtAndNamed) {
  const auto g = load_guards(kThresholds);
  const CompareReport r = compare_results(fixture("compare_old.json"), fixture("compare_regressed.json"), g);
  EXPECT_EQ(r.failed, 4);  // A-B convergence and failures, A-A genuine_total and fcl_collide.genuine
  ASSERT_NE(row(r, "A-B", "cold.convergence_rate"), nullptr);
  EXPECT_EQ(row(r, "A-B", "cold.convergence_rate")->verdict, "FAIL");
  EXPECT_EQ(row(r, "A-B", "cold.failures")->verdict, "FAIL");
  EXPECT_EQ(row(r, "A-A", "baselines.fcl_collide.genuine")->verdict, "FAIL");
  EXPECT_EQ(row(r, "A-A", "cold.convergence_rate")->verdict, "same");
  const std::string t = r.text();
  EXPECT_NE(t.find("REGRESSION"), std::string::npos) << t;
  EXPECT_NE(t.find("cold.convergence_rate"), std::string::npos) << t;
}

TEST(Compare, ImprovementPassesAndTimingOnlyWarns) {
  const auto g = load_guards(kThresholds);
  const CompareReport r = compare_results(fixture("compare_old.json"), fixture("compare_improved.json"), g);
  EXPECT_EQ(r.failed, 0);
  EXPECT_EQ(row(r, "A-B", "cold.iterations.mean")->verdict, "better");
  EXPECT_EQ(row(r, "A-A", "derivatives.agreement")->verdict, "better");
  EXPECT_EQ(row(r, "A-A", "timing.idcol_cold/fcl_collide")->verdict, "WARN");
  EXPECT_EQ(r.warned, 1);
}

// What a reviewer reads: only the rows that changed, the true count of
// metrics compared, rates in percentage points, and no "worse" for a change
// that is rounding.
TEST(Compare, TextShowsChangesWithTheTrueCount) {
  const auto g = load_guards(kThresholds);
  const CompareReport r = compare_results(fixture("compare_old.json"), fixture("compare_regressed.json"), g);
  const std::string t = r.text(), all = r.text(true);
  EXPECT_NE(t.find(std::to_string(r.rows.size()) + " metrics compared"), std::string::npos) << t;
  EXPECT_NE(t.find("only changes shown"), std::string::npos) << t;
  EXPECT_EQ(t.find(" same\n"), std::string::npos) << t;
  EXPECT_NE(all.find(" same\n"), std::string::npos) << all;
  EXPECT_NE(t.find(" pp "), std::string::npos) << "a convergence change in percentage points\n" << t;
  // A change of a part in 10^12 is rounding: "same", not "worse".
  nlohmann::json o = fixture("compare_old.json"), n = o;
  double& it = n["pairs"][0]["passes"]["cold"]["iterations"]["mean"].get_ref<double&>();
  it *= 1.0 + 1e-12;
  const CompareReport tiny = compare_results(o, n, g);
  EXPECT_EQ(row(tiny, "A-A", "cold.iterations.mean")->verdict, "same");
  EXPECT_NE(tiny.text().find("no metric changed"), std::string::npos) << tiny.text();
}

TEST(Compare, CommonPairsComparesTheSharedOnesAndNamesTheRest) {
  const auto g = load_guards(kThresholds);
  const CompareReport r = compare_results(fixture("compare_old.json"), fixture("compare_missing_pair.json"), g, true);
  EXPECT_EQ(row(r, "A-B", "cold.convergence_rate"), nullptr);
  EXPECT_NE(row(r, "A-A", "cold.convergence_rate"), nullptr);
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("pair A-B is only in OLD"), std::string::npos) << r.notes[0];
}

TEST(Compare, MissingPairIsAnError) {
  const auto g = load_guards(kThresholds);
  try {
    compare_results(fixture("compare_old.json"), fixture("compare_missing_pair.json"), g);
    FAIL() << "no error";
  } catch (const CompareError& e) {
    EXPECT_NE(std::string(e.what()).find("pair A-B is in OLD but missing from NEW"), std::string::npos) << e.what();
  }
  EXPECT_THROW(compare_results(fixture("compare_missing_pair.json"), fixture("compare_old.json"), g), CompareError);
}

// A guard whose pattern matches no metric (a typo) guards nothing: it is an
// error naming the guard, not a silent PASS. A guard for another kind of
// results file (stress metrics against sweep files) is not an error: one
// thresholds file serves all kinds.
TEST(Compare, GuardMatchingNoMetricIsAnError) {
  char templ[] = "/tmp/idcol_thresholds_XXXXXX";
  const int fd = ::mkstemp(templ);
  ASSERT_GE(fd, 0);
  ::close(fd);
  const std::string th = templ;
  std::FILE* f = std::fopen(th.c_str(), "w");
  std::fputs("[[guard]]\nmetric = \"*.genuine_rate\"\nbetter = \"higher\"\n\n"
             "[[guard]]\nmetric = \"*.convergance_rate\"\nbetter = \"higher\"\n", f);
  std::fclose(f);
  const auto g = load_guards(th);
  try {
    compare_results(fixture("compare_old.json"), fixture("compare_regressed.json"), g);
    FAIL() << "a guard that matches nothing was accepted";
  } catch (const CompareError& e) {
    EXPECT_NE(std::string(e.what()).find(th + ": guard[1]: metric = \"*.convergance_rate\" matches no metric"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(compare_results(fixture("compare_old.json"), fixture("compare_old.json"), {g[0]}));
  ::unlink(th.c_str());
}

// Without a thresholds file, drops in convergence and new failures still fail
// (compare once passed everything then); other figures are reported only.
TEST(Compare, DefaultGuardsCatchConvergenceAndFailures) {
  const CompareReport r = compare_results(fixture("compare_old.json"), fixture("compare_regressed.json"), default_guards());
  ASSERT_NE(row(r, "A-B", "cold.convergence_rate"), nullptr);
  EXPECT_EQ(row(r, "A-B", "cold.convergence_rate")->verdict, "FAIL");
  ASSERT_NE(row(r, "A-B", "cold.failures"), nullptr);
  EXPECT_EQ(row(r, "A-B", "cold.failures")->verdict, "FAIL");
  EXPECT_EQ(r.failed, 2);
  EXPECT_EQ(compare_results(fixture("compare_old.json"), fixture("compare_improved.json"), default_guards()).failed, 0);
  // Through the command line: the fixtures directory has no thresholds.toml.
  const std::string exe = IDCOL_HARNESS_EXE;
  const int s = std::system((exe + " compare " + kDir + "/compare_old.json " + kDir + "/compare_regressed.json > /dev/null 2>&1").c_str());
  EXPECT_EQ(WIFEXITED(s) ? WEXITSTATUS(s) : -1, 1);
}

TEST(Compare, CommandLineExitCodes) {
  const std::string exe = IDCOL_HARNESS_EXE;
  // A path of our own: concurrent runs of this test must not share it.
  char templ[] = "/tmp/idcol_compare_test_XXXXXX";
  const int fd = ::mkstemp(templ);
  ASSERT_GE(fd, 0);
  ::close(fd);
  const std::string err_path = templ;
  auto run = [&](const std::string& args) {
    const int s = std::system((exe + " compare " + args + " > /dev/null 2> " + err_path).c_str());
    return WIFEXITED(s) ? WEXITSTATUS(s) : -1;
  };
  const std::string th = " --thresholds " + kThresholds;
  EXPECT_EQ(run(kDir + "/compare_old.json " + kDir + "/compare_old.json" + th), 0);
  EXPECT_EQ(run(kDir + "/compare_old.json " + kDir + "/compare_improved.json" + th), 0);
  EXPECT_EQ(run(kDir + "/compare_old.json " + kDir + "/compare_regressed.json" + th), 1);
  EXPECT_EQ(run(kDir + "/compare_old.json " + kDir + "/compare_missing_pair.json" + th), 2);
  // A corrupt file: exit 2 and a message naming the file and the JSON error.
  EXPECT_EQ(run(kDir + "/compare_old.json " + kDir + "/compare_corrupt.json" + th), 2);
  const nlohmann::json dummy;
  std::string err;
  if (std::FILE* f = std::fopen(err_path.c_str(), "r")) {
    char buf[4096];
    const std::size_t n = std::fread(buf, 1, sizeof buf, f);
    err.assign(buf, n);
    std::fclose(f);
  }
  EXPECT_NE(err.find("compare_corrupt.json: not valid JSON"), std::string::npos) << err;
  EXPECT_EQ(run(kDir + "/compare_old.json " + kDir + "/compare_old.json --thresholds " + kDir + "/compare_corrupt.json"), 2);
  ::unlink(err_path.c_str());
}


// Stress and smoothing-study files go through the same compare: an unchanged
// file passes with every figure "same", a worse guarded figure fails, a
// missing case is an error and two files of different kinds are refused.
TEST(Compare, StressFiles) {
  const auto g = load_guards(kThresholds);
  const nlohmann::json old = fixture("compare_stress.json");
  const CompareReport same = compare_results(old, old, g);
  EXPECT_EQ(same.failed, 0);
  ASSERT_GE(same.rows.size(), 2u * 2u * 14u);  // two cases, two passes, 14 figures each
  for (const auto& x : same.rows) EXPECT_EQ(x.verdict, "same") << x.pair << " " << x.metric;
  nlohmann::json worse = old;
  auto& box = worse["cases"][1];
  ASSERT_EQ(box["name"], "box_box_beta1000");
  box["passes"]["cold"]["genuine_rate"] = box["passes"]["cold"]["genuine_rate"].get<double>() - 1e-4;
  box["passes"]["warm"]["false_convergence"]["total"] = 1;
  const CompareReport r = compare_results(old, worse, g);
  EXPECT_EQ(r.failed, 2);
  ASSERT_NE(row(r, "box_box_beta1000", "cold.genuine_rate"), nullptr);
  EXPECT_EQ(row(r, "box_box_beta1000", "cold.genuine_rate")->verdict, "FAIL");
  EXPECT_EQ(row(r, "box_box_beta1000", "warm.false_convergence.total")->verdict, "FAIL");
  EXPECT_EQ(row(r, "sphere_warm_jumps", "cold.genuine_rate")->verdict, "same");
  nlohmann::json fewer = old;
  fewer["cases"].erase(0);
  try {
    compare_results(old, fewer, g);
    FAIL() << "no error";
  } catch (const CompareError& e) {
    EXPECT_NE(std::string(e.what()).find("case sphere_warm_jumps is in OLD but missing from NEW"), std::string::npos) << e.what();
  }
  EXPECT_THROW(compare_results(old, fixture("compare_old.json"), g), CompareError);
}

TEST(Compare, SmoothingFiles) {
  const auto g = load_guards(kThresholds);
  const nlohmann::json old = fixture("compare_smoothing.json");
  const CompareReport same = compare_results(old, old, g);
  EXPECT_EQ(same.failed, 0);
  ASSERT_GE(same.rows.size(), 2u * 17u);  // two points: 6 accuracy, 5 geometry and smoothness, 3 per timed pass
  for (const auto& x : same.rows) EXPECT_EQ(x.verdict, "same") << x.pair << " " << x.metric;
  nlohmann::json worse = old;
  worse["points"][1]["cold_accuracy_pass"]["alpha_rel_error"]["p99"] =
      1.5 * worse["points"][1]["cold_accuracy_pass"]["alpha_rel_error"]["p99"].get<double>();
  worse["points"][0]["timing"]["warm"]["converged_fraction"] = 0.999;
  const CompareReport r = compare_results(old, worse, g);
  EXPECT_EQ(r.failed, 2);
  ASSERT_NE(row(r, "beta = 5", "accuracy.alpha_rel_error.p99"), nullptr);
  EXPECT_EQ(row(r, "beta = 5", "accuracy.alpha_rel_error.p99")->verdict, "FAIL");
  EXPECT_EQ(row(r, "beta = 2", "warm.converged_fraction")->verdict, "FAIL");
  EXPECT_THROW(compare_results(fixture("compare_stress.json"), old, g), CompareError);
}

}  // namespace
}  // namespace idcol::harness
