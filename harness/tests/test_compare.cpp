// compare on fixture files: a regression is caught, an improvement passes,
// a missing pair and a corrupt file are clear errors; and on the checked-in
// CI references (results/baseline), each way compare was once fooled,
// turned into a FAIL or a refusal by a results file broken on purpose.
#include <gtest/gtest.h>

#include <fnmatch.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <filesystem>
#include <fstream>
#include <sstream>
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
  // And, declared since, new genuine disagreements with a baseline (A-A
  // genuine_total and fcl_collide.genuine).
  EXPECT_EQ(row(r, "A-A", "baselines.fcl_collide.genuine")->verdict, "FAIL");
  EXPECT_EQ(r.failed, 4);
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

// ------------------------------------------------------------------
// Broken on purpose: each test below takes a checked-in CI reference,
// breaks one thing in a copy, and sees the verdict turn to FAIL (or the
// comparison refused as bad input).

const std::string kBaseline = std::filesystem::path(IDCOL_THRESHOLDS_FILE).parent_path().string();
nlohmann::json baseline(const std::string& name) { return read_json_file(kBaseline + "/" + name); }

/// A file of our own under /tmp holding `text`; removed by the destructor.
struct TempFile {
  std::string path;
  explicit TempFile(const std::string& text, const char* suffix = ".json") {
    char templ[] = "/tmp/idcol_compare_XXXXXX";
    const int fd = ::mkstemp(templ);
    ::close(fd);
    ::unlink(templ);
    path = std::string(templ) + suffix;
    std::ofstream(path) << text;
  }
  ~TempFile() { ::unlink(path.c_str()); }
};

/// Runs the harness's compare; returns the exit status, stdout in `out`.
int cli_compare(const std::string& args, std::string* out = nullptr) {
  TempFile o("");
  const int s = std::system((std::string(IDCOL_HARNESS_EXE) + " compare " + args + " > " + o.path + " 2>&1").c_str());
  if (out) {
    std::ifstream f(o.path);
    std::stringstream ss;
    ss << f.rdbuf();
    *out = ss.str();
  }
  return WIFEXITED(s) ? WEXITSTATUS(s) : -1;
}

int count_verdict(const CompareReport& r, const std::string& v) {
  int n = 0;
  for (const auto& x : r.rows) n += x.verdict == v;
  return n;
}

nlohmann::json& first_pair_with(nlohmann::json& r, const char* member) {
  for (auto& p : r["pairs"])
    if (p.contains(member)) return p;
  throw std::runtime_error(std::string("no pair with ") + member);
}

// A thresholds file with one timing guard once replaced the defaults: a
// drop to 99.9% convergence with 10 failed solves passed. Now it adds.
TEST(CompareBroken, ThresholdsFileAddsToTheDefaultGuards) {
  const nlohmann::json old = baseline("ci.json");
  nlohmann::json n = old;
  auto& cold = n["pairs"][0]["passes"]["cold"];
  cold["convergence_rate"] = 0.999;
  cold["failures"] = 10;
  const TempFile th("[[guard]]\nmetric = \"*.time.median_us\"\nbetter = \"lower\"\nrel = 0.3\nfail = false\n", ".toml");
  const CompareReport r = compare_results(old, n, load_guards(th.path));
  EXPECT_EQ(r.failed, 2);
  EXPECT_EQ(row(r, "Poly-Poly", "cold.convergence_rate")->verdict, "FAIL");
  EXPECT_EQ(row(r, "Poly-Poly", "cold.failures")->verdict, "FAIL");
  const TempFile nf(n.dump());
  EXPECT_EQ(cli_compare(kBaseline + "/ci.json " + nf.path + " --thresholds " + th.path), 1);
}

// A looser guard in a thresholds file does not loosen (the default still
// applies, and a note says so); replace = true does, because it says so.
TEST(CompareBroken, LooserGuardNeedsReplaceToLoosen) {
  const nlohmann::json old = baseline("ci.json");
  nlohmann::json n = old;
  n["pairs"][0]["passes"]["cold"]["failures"] = 3;
  n["pairs"][0]["passes"]["cold"]["convergence_rate"] = 1.0;  // (a hand-made file: the rate is not recomputed)
  const TempFile loose("[[guard]]\nmetric = \"*.failures\"\nbetter = \"lower\"\nabs = 100\n", ".toml");
  const CompareReport r = compare_results(old, n, load_guards(loose.path));
  EXPECT_EQ(row(r, "Poly-Poly", "cold.failures")->verdict, "FAIL");
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("is looser than the default guard of cold.failures"), std::string::npos) << r.notes[0];
  const TempFile replace("[[guard]]\nmetric = \"*.failures\"\nbetter = \"lower\"\nabs = 100\nreplace = true\n", ".toml");
  const CompareReport rr = compare_results(old, n, load_guards(replace.path));
  EXPECT_EQ(row(rr, "Poly-Poly", "cold.failures")->verdict, "worse");
  EXPECT_EQ(rr.failed, 0);
  // A tighter guard tightens: 5% more mean iterations passes by default
  // (informational), fails under a 1% guard.
  nlohmann::json it = old;
  double& mean = it["pairs"][0]["passes"]["cold"]["iterations"]["mean"].get_ref<double&>();
  mean *= 1.05;
  EXPECT_EQ(compare_results(old, it, std::vector<Guard>{}).failed, 0);
  const TempFile tight("[[guard]]\nmetric = \"*.iterations.mean\"\nbetter = \"lower\"\nrel = 0.01\n", ".toml");
  EXPECT_EQ(compare_results(old, it, load_guards(tight.path)).failed, 1);
  const TempFile bad("[[guard]]\nmetric = \"*.failures\"\nbetter = \"lower\"\nreplace = \"yes\"\n", ".toml");
  EXPECT_THROW(load_guards(bad.path), CompareError);
}

// Runs of different things are refused, naming only the fields that differ.
TEST(CompareBroken, RunsOfDifferentThingsAreRefusedNamingOnlyTheFieldsThatDiffer) {
  const nlohmann::json old = baseline("ci.json");
  auto refused = [&](const nlohmann::json& a, const nlohmann::json& b) -> std::vector<std::string> {
    try {
      compare_results(a, b, std::vector<Guard>{});
    } catch (const CompareMismatch& e) {
      EXPECT_NE(std::string(e.what()).find("--allow-mismatch"), std::string::npos) << e.what();
      return e.fields;
    }
    ADD_FAILURE() << "not refused";
    return {};
  };
  nlohmann::json solver = old;
  solver["solver"]["max_iterations"] = 50;
  solver["solver"]["tolerance"] = 1e-8;
  const auto f = refused(old, solver);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0], "solver.max_iterations: OLD 25, NEW 50");
  EXPECT_EQ(f[1], "solver.tolerance: OLD 1e-10, NEW 1e-08");
  // The quick scene against itself with SE at n = 2 instead of 8.
  nlohmann::json shapes = old;
  for (auto& p : shapes["pairs"])
    for (const char* s : {"shape1", "shape2"}) {
      std::string t = p[s];
      if (t.find("\"superellipsoid\"") != std::string::npos && t.find("n = 8") != std::string::npos) t.replace(t.find("n = 8"), 5, "n = 2");
      p[s] = t;
    }
  const auto fs = refused(old, shapes);
  ASSERT_EQ(fs.size(), 2u);  // shape2 of Poly-SE, TC-SE, SE-SE; shape1 of SE-SE, SE-SEC
  EXPECT_EQ(fs[0].rfind("shape2: ", 0), 0u) << fs[0];
  EXPECT_NE(fs[0].find("n = 2"), std::string::npos) << fs[0];
  nlohmann::json poses = old;
  poses["sweep"]["poses"] = 1000;
  poses["shard"]["poses"][1] = 1000;
  EXPECT_EQ(refused(old, poses).size(), 2u);
  nlohmann::json scene = old;
  scene["scene"]["name"] = "quick";
  EXPECT_EQ(refused(old, scene), std::vector<std::string>{"scene.name: OLD \"ci\", NEW \"quick\""});
  // A 10,000-pose stress file against a 1,000-pose one: one line for all cases.
  const nlohmann::json st = baseline("stress.json");
  nlohmann::json st10k = st;
  for (auto& c : st10k["cases"]) c["poses"] = 10000;
  const auto fp = refused(st, st10k);
  ASSERT_EQ(fp.size(), 1u);
  EXPECT_EQ(fp[0], "poses: OLD 1000, NEW 10000 (every case (" + std::to_string(st["cases"].size()) + "))");
  // Another kind: refused.
  EXPECT_THROW(compare_results(st, old, std::vector<Guard>{}), CompareMismatch);
  // Two smoothing grids of different families.
  const nlohmann::json sm = fixture("compare_smoothing.json");
  nlohmann::json cone = sm;  // a cone grid as the polytope grid
  cone["family"] = "smooth_polytope";
  cone["scene"]["name"] = "smoothing_polytope";
  EXPECT_EQ(refused(sm, cone).size(), 2u);
  // --allow-mismatch compares, the fields heading the report.
  CompareOptions allow;
  allow.allow_mismatch = true;
  const CompareReport r = compare_results(old, solver, allow);
  EXPECT_EQ(r.mismatches.size(), 2u);
  EXPECT_NE(r.text().find("MISMATCH: OLD and NEW are not runs of the same thing"), std::string::npos) << r.text();
  // The command line: exit 2 naming the fields; --allow-mismatch: the verdict.
  const TempFile nf(solver.dump());
  std::string out;
  EXPECT_EQ(cli_compare(kBaseline + "/ci.json " + nf.path, &out), 2);
  EXPECT_NE(out.find("solver.max_iterations: OLD 25, NEW 50"), std::string::npos) << out;
  EXPECT_EQ(out.find("solver.armijo_c"), std::string::npos) << out;
  EXPECT_EQ(cli_compare(kBaseline + "/ci.json " + nf.path + " --allow-mismatch", &out), 0);
  EXPECT_NE(out.find("MISMATCH"), std::string::npos) << out;
}

// The report says which file is the reference; files given in the wrong
// order (OLD made after NEW) get a note.
TEST(CompareBroken, SaysWhichFileIsOldAndWhichNew) {
  const nlohmann::json old = baseline("ci.json");
  nlohmann::json later = old;
  later["metadata"]["date_utc"] = "2030-01-01T00:00:00Z";
  const CompareReport ok = compare_results(old, later, std::vector<Guard>{});
  EXPECT_NE(ok.text().find("OLD (the reference): made "), std::string::npos) << ok.text();
  EXPECT_NE(ok.text().find("NEW (judged against it): made 2030-01-01"), std::string::npos) << ok.text();
  EXPECT_TRUE(ok.notes.empty());
  const CompareReport swapped = compare_results(later, old, std::vector<Guard>{});
  ASSERT_EQ(swapped.notes.size(), 1u);
  EXPECT_NE(swapped.notes[0].find("was made after NEW"), std::string::npos) << swapped.notes[0];
}

// Null and NaN once became "info": a stress file with null genuine_rate and
// false_convergence.total passed. (NaN is written as null; a string where a
// number belongs is not a results file: test_tampered.cpp.)
TEST(CompareBroken, NullOrMissingGuardedMetricFails) {
  const nlohmann::json old = baseline("stress.json");
  nlohmann::json n = old;
  const std::string name = n["cases"][0]["name"];
  n["cases"][0]["passes"]["cold"]["genuine_rate"] = nullptr;
  n["cases"][0]["passes"]["cold"]["false_convergence"]["total"] = nullptr;
  n["cases"][0]["passes"]["warm"].erase("failures");
  n["cases"][0]["passes"]["warm"]["worst_residual"] = nullptr;
  const CompareReport r = compare_results(old, n, std::vector<Guard>{});
  EXPECT_EQ(row(r, name, "cold.genuine_rate")->verdict, "FAIL");
  EXPECT_EQ(row(r, name, "cold.false_convergence.total")->verdict, "FAIL");
  EXPECT_EQ(row(r, name, "warm.failures")->verdict, "FAIL");
  EXPECT_EQ(row(r, name, "warm.worst_residual")->verdict, "FAIL");
  EXPECT_EQ(r.failed, 4);
  // A whole pass that vanishes: each of its guarded figures fails.
  nlohmann::json nopass = old;
  nopass["cases"][0]["passes"].erase("warm");
  EXPECT_GE(compare_results(old, nopass, std::vector<Guard>{}).failed, 10);
  // An unguarded count that vanishes fails too; an unguarded figure that is
  // not a count is reported "missing".
  const nlohmann::json ci = baseline("ci.json");
  nlohmann::json band = ci;
  nlohmann::json& p = first_pair_with(band, "baselines");
  const std::string key = p["body1"].get<std::string>() + "-" + p["body2"].get<std::string>();
  p["baselines"]["status"]["fcl_collide"].erase("band");
  p["passes"]["cold"]["iterations"].erase("mean");
  const CompareReport rb = compare_results(ci, band, std::vector<Guard>{});
  EXPECT_EQ(row(rb, key, "baselines.fcl_collide.band")->verdict, "FAIL");
  EXPECT_EQ(row(rb, key, "cold.iterations.mean")->verdict, "missing");
  EXPECT_EQ(rb.failed, 1);
}

// Every per-method status count zeroed once passed, the drops "better".
TEST(CompareBroken, PerMethodTableThatEmptiesFails) {
  const nlohmann::json old = baseline("ci.json");
  nlohmann::json n = old;
  int methods = 0;
  for (auto& p : n["pairs"])
    if (p.contains("baselines"))
      for (auto& [m, st] : p["baselines"]["status"].items()) {
        for (auto& [k, v] : st.items()) v = 0;
        ++methods;
      }
  ASSERT_GT(methods, 0);
  const CompareReport r = compare_results(old, n, std::vector<Guard>{});
  EXPECT_EQ(r.failed, methods);  // each method's queries
  // A method's table removed: its figures are missing, and fail.
  nlohmann::json gone = old;
  nlohmann::json& p = first_pair_with(gone, "baselines");
  p["baselines"]["status"].erase("fcl_collide");
  const CompareReport rg = compare_results(old, gone, std::vector<Guard>{});
  EXPECT_EQ(rg.failed, 4);  // queries, genuine, band (a count), failed
}

// A results file with a member every such file has removed is bad input
// (exit 2), not a regression (exit 1).
TEST(CompareBroken, RemovedKeyIsBadInput) {
  const nlohmann::json old = baseline("ci.json");
  for (const char* top : {"solver", "scene", "sweep", "passes"}) {
    nlohmann::json n = old;
    n.erase(top);
    EXPECT_THROW(compare_results(old, n, std::vector<Guard>{}), CompareError) << top;
  }
  for (const char* member : {"shape1", "body2", "passes"}) {
    nlohmann::json n = old;
    n["pairs"][3].erase(member);
    try {
      compare_results(old, n, std::vector<Guard>{});
      ADD_FAILURE() << member << ": accepted";
    } catch (const CompareError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("NEW: pairs[3] has no \"") + member + "\""), std::string::npos) << e.what();
    }
  }
  nlohmann::json n = old;
  n["pairs"][3].erase("shape1");
  const TempFile nf(n.dump());
  EXPECT_EQ(cli_compare(kBaseline + "/ci.json " + nf.path), 2);
  nlohmann::json typed = old;
  typed["pairs"][2]["body1"] = 7;  // a member of the wrong type
  const TempFile tf(typed.dump());
  EXPECT_EQ(cli_compare(kBaseline + "/ci.json " + tf.path), 2);
}

// One test per kind of guard: exact (lower, higher), same (either way), a
// tolerance (below passes, beyond fails), warn-only; and each metric the
// audit found unguarded.
TEST(CompareBroken, EachKindOfGuardFails) {
  const nlohmann::json st = baseline("stress.json");
  const std::string c0 = st["cases"][0]["name"];
  auto verdict = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& metric) {
    nlohmann::json n = st;
    edit(n["cases"][0]["passes"]["cold"]);
    const CompareReport r = compare_results(st, n, std::vector<Guard>{});
    const CompareRow* x = row(r, c0, metric);
    return x ? x->verdict : std::string("no row");
  };
  // Exact, lower is better.
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["failures"] = p["failures"].get<int>() + 1; }, "cold.failures"), "FAIL");
  // Exact, higher is better.
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["genuine_rate"] = p["genuine_rate"].get<double>() - 1e-4; }, "cold.genuine_rate"), "FAIL");
  // Same: a count fixed by the scene, either way.
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["solves"] = p["solves"].get<int>() + 1; }, "cold.solves"), "FAIL");
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["solves"] = p["solves"].get<int>() - 1; }, "cold.solves"), "FAIL");
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["oracle"]["checked"] = 0; }, "cold.oracle.checked"), "FAIL");
  // A tolerance: within it "worse", beyond it FAIL; for each worst error the
  // audit found unguarded.
  for (const char* m : {"worst_surface_error", "worst_residual", "worst_normal_error", "oracle.worst_bracket_violation",
                        "oracle.worst_relative_error"}) {
    std::string json_path = "/" + std::string(m);
    std::replace(json_path.begin(), json_path.end(), '.', '/');
    EXPECT_EQ(verdict([&](nlohmann::json& p) { p[nlohmann::json::json_pointer(json_path)] = 1e-6; }, std::string("cold.") + m), "FAIL") << m;
    EXPECT_NE(verdict([&](nlohmann::json& p) {
                const double v = p[nlohmann::json::json_pointer(json_path)].get<double>();
                p[nlohmann::json::json_pointer(json_path)] = v * 1.5 + 1e-12;
              }, std::string("cold.") + m), "FAIL") << m;
  }
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["conditioning"]["unreliable"] = p["conditioning"]["unreliable"].get<int>() + 20; },
                    "cold.conditioning.unreliable"), "FAIL");
  EXPECT_EQ(verdict([](nlohmann::json& p) { p["conditioning"]["unreliable"] = p["conditioning"]["unreliable"].get<int>() + 1; },
                    "cold.conditioning.unreliable"), "worse");
  for (const char* m : {"concentric.wrong", "reference_solve_failed", "oracle.oracle_failed"}) {
    std::string json_path = "/" + std::string(m);
    std::replace(json_path.begin(), json_path.end(), '.', '/');
    EXPECT_EQ(verdict([&](nlohmann::json& p) { p[nlohmann::json::json_pointer(json_path)] = 1; }, std::string("cold.") + m), "FAIL") << m;
  }
  // The sweep's: derivative worst error (its guard once named a metric the
  // sweep does not have), baseline and oracle failures.
  const nlohmann::json ci = baseline("ci.json");
  nlohmann::json n = ci;
  nlohmann::json& p = first_pair_with(n, "baselines");
  const std::string key = p["body1"].get<std::string>() + "-" + p["body2"].get<std::string>();
  p["derivatives"]["worst_error"] = 1e-3;
  p["baselines"]["status"]["ccd_gjk"]["failed"] = p["baselines"]["status"]["ccd_gjk"]["failed"].get<int>() + 1;
  p["baselines"]["oracle_failed"] = p["baselines"]["oracle_failed"].get<int>() + 1;
  p["baselines"]["timing"]["methods"]["idcol_cold"]["median_ns"] = 10.0 * p["baselines"]["timing"]["methods"]["idcol_cold"]["median_ns"].get<double>();
  const CompareReport r = compare_results(ci, n, std::vector<Guard>{});
  EXPECT_EQ(row(r, key, "derivatives.worst_error")->verdict, "FAIL");
  EXPECT_EQ(row(r, key, "baselines.ccd_gjk.failed")->verdict, "FAIL");
  EXPECT_EQ(row(r, key, "baselines.oracle_failed")->verdict, "FAIL");
  // Warn only: a wall-clock time ratio.
  EXPECT_EQ(row(r, key, "timing.idcol_cold/fcl_collide")->verdict, "WARN");
  EXPECT_EQ(r.failed, 3);
  EXPECT_EQ(r.warned, 1);
}

// Every metric of the checked-in references has a declared default guard
// or is informational by declaration: no figure is compared without a
// declaration behind it.
TEST(CompareBroken, EveryMetricIsDeclared) {
  for (const char* f : {"ci.json", "stress.json", "random_bodies.json", "smoothing_polytope.json"}) {
    const nlohmann::json r = baseline(f);
    const CompareReport rep = compare_results(r, r, std::vector<Guard>{});
    for (const auto& x : rep.rows) EXPECT_FALSE(x.unit.empty()) << f << ": " << x.metric << " is not declared";
  }
}

// compare --json: the verdict and every row, with the exit code; bad input
// as {"verdict": "ERROR"} and exit 2; --help names the exit codes.
TEST(CompareBroken, JsonOutputAndExitCodes) {
  std::string out;
  EXPECT_EQ(cli_compare(kDir + "/compare_old.json " + kDir + "/compare_regressed.json --json", &out), 1);
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["verdict"], "REGRESSION");
  EXPECT_EQ(j["exit_code"], 1);
  EXPECT_EQ(j["fails"].get<int>(), 4);
  EXPECT_FALSE(j["rows"].empty());
  EXPECT_EQ(cli_compare(kDir + "/compare_old.json " + kDir + "/compare_old.json --json", &out), 0);
  EXPECT_EQ(nlohmann::json::parse(out)["verdict"], "PASS");
  EXPECT_EQ(cli_compare(kDir + "/compare_old.json " + kDir + "/compare_corrupt.json --json", &out), 2);
  const std::string js = out.substr(out.find('{'));
  EXPECT_EQ(nlohmann::json::parse(js)["verdict"], "ERROR");
  EXPECT_EQ(cli_compare("--help", &out), 0);
  EXPECT_NE(out.find("exit: 0 no guarded metric worsened"), std::string::npos) << out;
  EXPECT_NE(out.find("1 a regression"), std::string::npos) << out;
  EXPECT_NE(out.find("2 bad input"), std::string::npos) << out;
  EXPECT_EQ(cli_compare(kDir + "/compare_old.json", &out), 2);
  EXPECT_EQ(cli_compare(kDir + "/compare_old.json " + kDir + "/compare_old.json --bogus", &out), 2);
}

}  // namespace
}  // namespace idcol::harness
