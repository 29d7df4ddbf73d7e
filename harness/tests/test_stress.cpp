// The stress suite's scene loader, pose generators and checks, and bad input
// end to end through the command line: each ends in an error message naming
// file, field, value and expectation, with no partial results file.
#include <gtest/gtest.h>

#include <dirent.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "idcol/solver.hpp"
#include "studies/sweep/sweep.hpp"
#include "studies/stress/stress.hpp"
#include "io/files.hpp"
#include "studies/stress/stress_tally.hpp"
#include "referee/methods.hpp"
#include "studies/entry_shards.hpp"
#include "studies/metric.hpp"
#include "studies/study.hpp"

namespace idcol::harness {
namespace {

const char* kBase = R"(name = "t"
[shapes]
A = { family = "sphere", R = 1.0 }
B = { family = "superellipsoid", a = 1.0, b = 2.0, c = 3.0, n = 1 }
P = { family = "box", half = [1.0, 0.5, 0.75], beta = 1000 }
[[case]]
name = "c0"
body1 = "A"
body2 = "B"
kind = "shell"
rmin = 1e-3
rmax = 10.0
zero_every = 7
poses = 40
passes = ["cold", "warm"]
derivative_samples = 4
[[case]]
name = "c1"
body1 = "A"
body2 = "A"
kind = "explicit"
passes = ["cold"]
poses = [{ R = [[1, 0, 0], [0, 1, 0], [0, 0, 1]], p = [0.5, 0.25, 3.0] }]
)";

std::string with(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) s.replace(pos, from.size(), to);
  return s;
}

void expect_error(const std::string& text, const std::string& field, const std::string& expect) {
  try {
    (void)parse_scene(text, "bad.toml");
    ADD_FAILURE() << "no error for field " << field;
  } catch (const SceneError& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.rfind("bad.toml: ", 0), 0u) << w;
    EXPECT_NE(w.find(field), std::string::npos) << w;
    EXPECT_NE(w.find(expect), std::string::npos) << w;
  }
}

TEST(Stress, ShippedSuiteLoadsWithTenThousandPosesPerCase) {
  const Scene s = load_scene(std::string(IDCOL_CONFIGS_DIR) + "/stress.toml");
  EXPECT_GE(s.spec.as<StressSpec>().cases.size(), 20u);
  for (const StressCase& c : s.spec.as<StressSpec>().cases) EXPECT_GE(c.poses, 10000u) << c.name;
}

TEST(Stress, MalformedStressScenesNameFileFieldAndExpectation) {
  const std::string base = kBase;
  expect_error(with(base, "zero_every = 7", "zero_every = 7\nzero_evry = 3"), "case[0].zero_evry", "unknown key");
  expect_error(with(base, "poses = 40", "poses = \"many\""), "case[0].poses", "expected a positive integer, got a string");
  expect_error(with(base, "rmin = 1e-3", "rmin = -1.0"), "case[0].rmin", "expected a finite number > 0, got -1");
  expect_error(with(base, "rmax = 10.0", "rmax = nan"), "case[0].rmax", "got nan");
  expect_error(with(base, "kind = \"shell\"", "kind = \"spiral\""), "case[0].kind", "expected \"shell\", \"touching\", \"explicit\" or \"random_bodies\"");
  expect_error(with(base, "body2 = \"B\"", "body2 = \"Q\""), "case[0].body2", "unknown shape \"Q\"");
  expect_error(with(base, "half = [1.0, 0.5, 0.75]", "half = [1.0, 0.5]"), "shapes.P.half", "expected [hx, hy, hz]");
  expect_error(with(base, "beta = 1000 }", "beta = 1000, origin = [2.0, 0, 0] }"), "shapes.P.origin", "|origin_i| < half_i");
  expect_error(with(base, "name = \"c1\"", "name = \"c0\""), "case[1].name", "given twice");
  expect_error(with(base, "[[case]]\nname = \"c0\"", "[case]\nname = \"c0\""), "case", "");
  expect_error(std::string(kBase) + "[[case]\n", "line", "not valid TOML");
  // The generated polytopes are bounded in all, before any is built: a few
  // bytes must not ask for minutes of hull building.
  const std::string big = "P = { family = \"box\", half = [1.0, 0.5, 0.75], beta = 1000 }\n"
                          "F = { family = \"facet_sphere\", facets = 12000, radius = 1.0, beta = 1000 }\n";
  EXPECT_NO_THROW((void)parse_scene(with(base, "P = { family = \"box\", half = [1.0, 0.5, 0.75], beta = 1000 }\n", big), "ok.toml"));
  expect_error(with(base, "P = { family = \"box\", half = [1.0, 0.5, 0.75], beta = 1000 }\n",
                    big + "V = { family = \"vertex_sphere\", vertices = 2001, radius = 1.0, beta = 1000 }\n"),
               "shapes.V", "20004 half-spaces in all (a vertex counts as 4); a scene may have at most 20000");
  expect_error(with(base, "P = { family = \"box\", half = [1.0, 0.5, 0.75], beta = 1000 }\n",
                    big + "G = { family = \"facet_sphere\", facets = 30000, radius = 1.0, beta = 1000 }\n"),
               "shapes.G.facets", "expected an integer in [4, 20000], got 30000");
}

TEST(Stress, OracleThatCannotServeThePairIsRejected) {
  const std::string base = kBase;
  expect_error(with(base, "derivative_samples = 4", "derivative_samples = 4\noracle = \"closed_form\""), "case[0].oracle",
               "serves sphere x sphere only, not \"A\" (sphere) x \"B\" (superellipsoid)");
  const std::string poly = with(with(base, "body2 = \"B\"", "body2 = \"P\""), "derivative_samples = 4", "derivative_samples = 4\noracle = \"pw\"");
  expect_error(poly, "case[0].oracle", "serves exact ellipsoids only");
  expect_error(with(base, "derivative_samples = 4", "derivative_samples = 4\noracle = \"lp\""), "case[0].oracle",
               "serves smooth_polytope x smooth_polytope only");
  expect_error(with(base, "derivative_samples = 4", "derivative_samples = 4\noracle = \"gjk\""), "case[0].oracle", "unknown oracle");
}

TEST(Stress, ExplicitPosesMustBeFiniteProperRotations) {
  const std::string base = kBase;
  const std::string pose = "p = [0.5, 0.25, 3.0]";
  expect_error(with(base, pose, "p = [0.5, nan, 3.0]"), "case[1].poses[0].p[1]", "expected a finite number, got nan");
  expect_error(with(base, pose, "p = [inf, 0.25, 3.0]"), "case[1].poses[0].p[0]", "expected a finite number, got inf");
  expect_error(with(base, "[0, 1, 0], [0, 0, 1]]", "[0, -inf, 0], [0, 0, 1]]"), "case[1].poses[0].R[1][1]", "got -inf");
  expect_error(with(base, "[0, 1, 0], [0, 0, 1]]", "[0, 1.2, 0], [0, 0, 1]]"), "case[1].poses[0].R", "not orthonormal");
  expect_error(with(base, "[0, 1, 0], [0, 0, 1]]", "[0, 1, 0], [0, 0, -1]]"), "case[1].poses[0].R", "expected det R = +1");
  expect_error(with(base, "[0, 1, 0], [0, 0, 1]]", "[0, 1, 0]]"), "case[1].poses[0].R", "expected a 3x3 rotation");
  expect_error(with(base, pose, "p = [0.5, \"x\", 3.0]"), "case[1].poses[0].p[1]", "expected a number");
  expect_error(with(base, pose, pose + ", q = 1"), "case[1].poses[0].q", "unknown key");
}

TEST(Stress, PoseKDependsOnKAlone) {
  const Scene s = parse_scene(with(kBase, "kind = \"shell\"", "kind = \"shell\""), "t.toml");
  const StressCase& c = s.spec.as<StressSpec>().cases[0];
  const Pose a = stress_pose(s, c, 13, nullptr, nullptr);
  for (std::uint64_t k = 0; k < 20; ++k) (void)stress_pose(s, c, k, nullptr, nullptr);
  const Pose b = stress_pose(s, c, 13, nullptr, nullptr);
  EXPECT_EQ(a.p, b.p);
  EXPECT_EQ(a.R, b.R);
  EXPECT_EQ(stress_pose(s, c, 14, nullptr, nullptr).p.squaredNorm(), 0.0);  // zero_every = 7
}

TEST(Stress, TouchingPosesHaveAlphaOnePlusEps) {
  const std::string text = with(with(kBase, "kind = \"shell\"\nrmin = 1e-3\nrmax = 10.0\nzero_every = 7", "kind = \"touching\"\norientation = \"vertex\""),
                                "body2 = \"B\"", "body2 = \"P\"");
  const Scene s = parse_scene(text, "t.toml");
  for (std::uint64_t k = 0; k < 6; ++k) {
    TouchReference ref;
    double expected = 0.0;
    const Pose X = stress_pose(s, s.spec.as<StressSpec>().cases[0], k, &ref, &expected);
    ASSERT_TRUE(ref.ok) << ref.error;
    EXPECT_EQ(ref.method, "support_function");  // never the solver's own solve
    EXPECT_NEAR(0.5 * (ref.lo + ref.hi), expected, 1e-15);
    const SolveResult r = solve(*s.shapes[0].shape, *s.shapes[2].shape, X, s.solver);
    ASSERT_TRUE(r.converged());
    // Sphere x smooth box: the smoothing bracket between the exact inner and outer boxes.
    EXPECT_GE(r.alpha, ref.lo * (1 - 1e-10));
    EXPECT_LE(r.alpha, ref.hi * (1 + 1e-10));
    EXPECT_NEAR(expected, 1.0, 1.1e-12);
  }
  // Sphere x exact ellipsoid: Perram-Wertheim, exact; the solver must hit 1 + eps.
  const Scene e = parse_scene(with(kBase, "kind = \"shell\"\nrmin = 1e-3\nrmax = 10.0\nzero_every = 7", "kind = \"touching\""), "t.toml");
  for (std::uint64_t k = 0; k < 6; ++k) {
    TouchReference ref;
    double expected = 0.0;
    const Pose X = stress_pose(e, e.spec.as<StressSpec>().cases[0], k, &ref, &expected);
    ASSERT_TRUE(ref.ok) << ref.error;
    EXPECT_EQ(ref.method, "perram_wertheim");
    const SolveResult r = solve(*e.shapes[0].shape, *e.shapes[1].shape, X, e.solver);
    ASSERT_TRUE(r.converged());
    EXPECT_NEAR(r.alpha, expected, 1e-9);
  }
}

TEST(Stress, SmallRunIsGenuineAndHasNoNaN) {
  const Scene s = parse_scene(kBase, "t.toml");
  const StressOutput out = run_stress(s, StudyOptions{});
  const nlohmann::json res = make_stress_results(s, out, nlohmann::json::object());
  for (const auto& c : res["cases"])
    for (const auto& [name, p] : c["passes"].items()) {
      EXPECT_EQ(p["genuine"], p["solves"]) << c["name"] << " " << name;
      EXPECT_EQ(p["false_convergence"]["total"], 0);
    }
  EXPECT_EQ(res["cases"][0]["passes"]["cold"]["concentric"]["expected"], 6);  // k = 0, 7, ..., 35
  const std::string text = res.dump();
  EXPECT_EQ(text.find("NaN"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_TRUE(out.failures.empty());
  const std::string md = stress_markdown(res, "r.json");
  EXPECT_NE(md.find("| c0 |"), std::string::npos);
}

// ---- the command line

std::string temp_dir() {
  char templ[] = "/tmp/idcol_stress_test.XXXXXX";
  const char* d = ::mkdtemp(templ);
  EXPECT_NE(d, nullptr);
  return d ? d : "/tmp";
}
std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
  }
  return out;
}
void remove_dir(const std::string& dir) {
  for (const auto& f : list_dir(dir)) ::unlink((dir + "/" + f).c_str());
  ::rmdir(dir.c_str());
}
/// Runs the harness; returns the exit code, and one of its streams (stderr,
/// or stdout with `stdout_wanted`) in *text, the other discarded.
int run_cli_stream(const std::string& args, std::string* text, bool stdout_wanted) {
  char templ[] = "/tmp/idcol_stress_cli.XXXXXX";
  const int fd = ::mkstemp(templ);
  ::close(fd);
  const std::string redirect = stdout_wanted ? std::string(" >") + templ + " 2>/dev/null" : std::string(" >/dev/null 2>") + templ;
  const int rc = std::system((std::string(IDCOL_HARNESS_EXE) + " " + args + redirect).c_str());
  std::ifstream in(templ);
  std::stringstream ss;
  ss << in.rdbuf();
  *text = ss.str();
  ::unlink(templ);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
int run_cli(const std::string& args, std::string* err) { return run_cli_stream(args, err, false); }
int run_cli_out(const std::string& args, std::string* out) { return run_cli_stream(args, out, true); }

TEST(CommandLine, UnwritableOutputIsNamedAndNothingIsWritten) {
  const std::string dir = temp_dir();
  const std::string scene = dir + "/s.toml";
  std::ofstream(scene) << kBase;
  const std::string sweep = dir + "/w.toml";
  std::ofstream(sweep) << "name = \"w\"\n[shapes]\nA = { family = \"sphere\", R = 1.0 }\n[sweep]\ngenerator = \"uniform\"\nposes = 10\n"
                          "[run]\npairs = \"all\"\npasses = [\"cold\"]\nrecord = [\"failures\"]\n";
  std::string err;
  // A directory that does not exist.
  EXPECT_EQ(run_cli("stress " + scene + " -o " + dir + "/missing/r.json", &err), 1);
  EXPECT_NE(err.find(dir + "/missing/r.json"), std::string::npos) << err;
  EXPECT_NE(err.find("No such file or directory"), std::string::npos) << err;
  EXPECT_EQ(run_cli("run " + sweep + " -o " + dir + "/missing/r.json --no-progress", &err), 1);
  EXPECT_NE(err.find(dir + "/missing/r.json"), std::string::npos) << err;
  // A read-only file system (read-only even for root).
  EXPECT_EQ(run_cli("stress " + scene + " -o /proc/idcol_stress_r.json", &err), 1);
  EXPECT_NE(err.find("/proc/idcol_stress_r.json"), std::string::npos) << err;
  // A bad --threads value and a bad explicit pose, through the command line.
  EXPECT_EQ(run_cli("stress " + scene + " -o " + dir + "/r.json --threads two", &err), 2);
  EXPECT_NE(err.find("--threads expects an integer"), std::string::npos) << err;
  std::ofstream(scene) << with(kBase, "p = [0.5, 0.25, 3.0]", "p = [0.5, nan, 3.0]");
  EXPECT_EQ(run_cli("stress " + scene + " -o " + dir + "/r.json", &err), 1);
  EXPECT_NE(err.find("case[1].poses[0].p[1]: expected a finite number, got nan"), std::string::npos) << err;
  EXPECT_EQ(list_dir(dir).size(), 2u);  // s.toml and w.toml only
  remove_dir(dir);
}

// Bad option values name the option, the value and what is expected; none is
// raw exception text ("stoul", "sched_setaffinity: Invalid argument") and none
// wraps around (--index -1 once became 18446744073709551615).
TEST(CommandLine, BadOptionValuesNameOptionValueAndExpectation) {
  const std::string dir = temp_dir();
  const std::string sweep = dir + "/w.toml";
  std::ofstream(sweep) << "name = \"w\"\n[shapes]\nA = { family = \"sphere\", R = 1.0 }\n[sweep]\ngenerator = \"uniform\"\nposes = 10\n"
                          "[run]\npairs = \"all\"\npasses = [\"cold\"]\nrecord = [\"failures\"]\n";
  const std::string out = " -o " + dir + "/r.json --no-progress";
  std::string err;
  for (const char* v : {"abc", "0", "-1", "2x"}) {
    EXPECT_EQ(run_cli("run " + sweep + out + " --threads " + v, &err), 2) << v;
    EXPECT_NE(err.find("--threads expects an integer in [1, 256], got \"" + std::string(v) + "\""), std::string::npos) << err;
  }
  // A CPU outside this process's affinity mask: refused before the run.
  EXPECT_EQ(run_cli("run " + sweep + out + " --pin 1000", &err), 2);
  EXPECT_NE(err.find("--pin expects a CPU this process may run on ("), std::string::npos) << err;
  EXPECT_NE(err.find("got \"1000\""), std::string::npos) << err;
  EXPECT_EQ(err.find("Invalid argument"), std::string::npos) << err;
  EXPECT_EQ(run_cli("run " + sweep + out + " --pin abc", &err), 2);
  EXPECT_NE(err.find("--pin expects an integer"), std::string::npos) << err;
  EXPECT_EQ(list_dir(dir).size(), 1u);  // w.toml only: nothing ran

  // replay --index: a non-number and a negative number.
  const std::string fails = dir + "/f.json";
  std::ofstream(fails) << R"({"schema": "idcol-harness-failures", "failures": []})";
  for (const char* v : {"abc", "-1"}) {
    EXPECT_EQ(run_cli("replay " + fails + " --index " + v, &err), 2) << v;
    EXPECT_NE(err.find("--index expects an integer in [0, "), std::string::npos) << err;
    EXPECT_NE(err.find("got \"" + std::string(v) + "\""), std::string::npos) << err;
    EXPECT_EQ(err.find("18446744073709551615"), std::string::npos) << err;
  }

  // table on a file that claims a schema but lacks its fields: the first
  // one missing is named.
  const std::string partial = dir + "/p.json";
  std::ofstream(partial) << R"({"schema": "idcol-harness-results"})";
  EXPECT_EQ(run_cli("table " + partial, &err), 1);
  EXPECT_NE(err.find(partial + " has no \"schema_version\""), std::string::npos) << err;
  std::ofstream(partial) << R"({"schema": "idcol-harness-stress", "schema_version": 1, "scene": {}, "solver": {}})";
  EXPECT_EQ(run_cli("table " + partial, &err), 1);
  EXPECT_NE(err.find(partial + " has no \"thresholds\""), std::string::npos) << err;
  remove_dir(dir);
}

// -o never destroys an input or another output, refuses what is not a
// regular file's path before the run, and "-" is standard output.
TEST(CommandLine, OutputsNeverReplaceInputsOrDevices) {
  const std::string dir = temp_dir();
  const std::string sweep = dir + "/w.toml";
  const std::string text = "name = \"w\"\n[shapes]\nA = { family = \"sphere\", R = 1.0 }\n[sweep]\ngenerator = \"uniform\"\nposes = 10\n"
                           "[run]\npairs = \"all\"\npasses = [\"cold\"]\nrecord = [\"failures\"]\n";
  std::ofstream(sweep) << text;
  std::string err;
  EXPECT_EQ(run_cli("run " + sweep + " -o " + sweep + " --no-progress", &err), 2);
  EXPECT_NE(err.find("-o " + sweep + " is the scene " + sweep), std::string::npos) << err;
  EXPECT_EQ(run_cli("run " + sweep + " -o " + dir + "/a.json --failures " + dir + "/a.json --no-progress", &err), 2);
  EXPECT_NE(err.find("each output needs a path of its own"), std::string::npos) << err;
  EXPECT_EQ(run_cli("run " + sweep + " -o " + dir + " --no-progress", &err), 1);
  EXPECT_NE(err.find("-o " + dir + ": a directory"), std::string::npos) << err;
  EXPECT_EQ(run_cli("run " + sweep + " -o /dev/full --no-progress", &err), 1);
  EXPECT_NE(err.find("-o /dev/full: a character device"), std::string::npos) << err;
  {
    std::ifstream in(sweep);
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_EQ(ss.str(), text);  // the scene is whole
  }
  // -o -: the results on standard output, nothing else there.
  const std::string out = dir + "/stdout.json";
  const int rc = std::system((std::string(IDCOL_HARNESS_EXE) + " run " + sweep + " -o - --failures " + dir + "/f.json --no-progress > " +
                              out + " 2>/dev/null").c_str());
  EXPECT_EQ(WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, 0);
  EXPECT_NO_THROW(EXPECT_EQ(read_json_file(out).at("schema"), "idcol-harness-results"));
  EXPECT_EQ(run_cli("run " + sweep + " -o - --no-progress", &err), 2);
  EXPECT_NE(err.find("give --failures FILE"), std::string::npos) << err;
  // table onto its own input.
  EXPECT_EQ(run_cli("table " + out + " -o " + out, &err), 2);
  EXPECT_NE(err.find("destroy an input"), std::string::npos) << err;
  remove_dir(dir);
}

// --help is the reference: each command lists its exit codes and every
// option's default; a usage error is one line that says where help is.
TEST(CommandLine, HelpListsExitCodesAndUsageErrorsAreOneLine) {
  for (const char* cmd : {"run", "stress", "smoothing", "table", "merge", "replay", "check", "compare", "info", "shapes"}) {
    std::string out;
    EXPECT_EQ(run_cli_out(std::string(cmd) + " --help", &out), 0) << cmd;
    EXPECT_NE(out.find("exit: 0"), std::string::npos) << cmd << "\n" << out;
  }
  std::string out;
  EXPECT_EQ(run_cli_out("compare --help", &out), 0);
  for (const char* o : {"--thresholds", "--all", "--only-changes", "--common-pairs"}) EXPECT_NE(out.find(o), std::string::npos) << o;
  EXPECT_EQ(run_cli_out("smoothing --help", &out), 0);
  for (const char* o : {"--poses N", "--threads T", "--pin CPU", "--shard i/N"}) EXPECT_NE(out.find(o), std::string::npos) << o;
  std::string err;
  EXPECT_EQ(run_cli("compare only_one.json", &err), 2);
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("idcol_harness compare --help"), std::string::npos) << err;
  EXPECT_EQ(run_cli("no_such_command", &err), 2);
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

// What a new user asks the command line: its version, a command's options
// with their defaults, the shape families, what a file holds, what a scene
// costs; and what a results file says about the build and machine.
TEST(CommandLine, VersionHelpShapesInfoAndCost) {
  std::string out;
  EXPECT_EQ(run_cli_out("--version", &out), 0);
  EXPECT_NE(out.find("idcol_harness 0."), std::string::npos) << out;
  EXPECT_NE(out.find("Eigen "), std::string::npos) << out;
  EXPECT_EQ(run_cli_out("run --help", &out), 0);
  EXPECT_NE(out.find("--max-traced-failures M (default 20)"), std::string::npos) << out;
  EXPECT_EQ(run_cli_out("merge --help", &out), 0);
  EXPECT_NE(out.find("--allow-mixed"), std::string::npos) << out;
  EXPECT_EQ(run_cli_out("shapes", &out), 0);
  for (const char* f : {"sphere:", "superellipsoid:", "superelliptic_cylinder:", "smooth_polytope:", "smooth_truncated_cone:"})
    EXPECT_NE(out.find(f), std::string::npos) << f << "\n" << out;

  const std::string dir = temp_dir();
  const std::string sweep = dir + "/w.toml";
  std::ofstream(sweep) << "name = \"w\"\n[shapes]\nA = { family = \"sphere\", R = 1.0 }\nB = { family = \"superellipsoid\", a = 0.5, "
                          "b = 1, c = 1.5, n = 8 }\n[sweep]\ngenerator = \"uniform\"\nposes = 50\n"
                          "[run]\npairs = \"all\"\npasses = [\"cold\", \"warm\"]\nrecord = [\"timing\", \"failures\"]\n"
                          "[solver]\nmax_iterations = 2\nmax_restarts = 0\ncontinuation = false\nbarrier = false\n";
  EXPECT_EQ(run_cli_out("check " + sweep, &out), 0);
  EXPECT_NE(out.find("a valid sweep scene; cost: 300 solves"), std::string::npos) << out;  // 3 pairs x 2 passes x 50
  EXPECT_EQ(run_cli_out("run " + sweep + " -o " + dir + "/r.json --no-progress", &out), 0);
  const nlohmann::json r = read_json_file(dir + "/r.json");
  for (const char* k : {"idcol_version", "libraries", "os", "kernel"}) EXPECT_TRUE(r.at("metadata").contains(k)) << k;
  EXPECT_TRUE(r.at("metadata").at("libraries").contains("Eigen"));
  // A starved solver fails: the verdict names the rows that did not converge,
  // and the replay commands name the harness by the path it ran from.
  EXPECT_EQ(run_cli_out("info " + dir + "/r.json", &out), 0);
  EXPECT_NE(out.find("VERDICT: "), std::string::npos) << out;
  EXPECT_NE(out.find("did not converge everywhere"), std::string::npos) << out;
  EXPECT_NE(out.find("cold median / p99 us"), std::string::npos) << out;
  const nlohmann::json f = read_json_file(dir + "/r.failures.json");
  ASSERT_FALSE(f.at("failures").empty());
  const std::string replay = f.at("failures")[0].at("replay").get<std::string>();
  const std::string exe = replay.substr(0, replay.find(' '));
  std::error_code ec;
  EXPECT_TRUE(std::filesystem::equivalent(exe, IDCOL_HARNESS_EXE, ec)) << replay;  // the harness run, relative to the cwd or absolute
  EXPECT_NE(replay.find(" replay " + dir + "/r.failures.json --index 0"), std::string::npos) << replay;
  // By default only the first 20 failure records carry a trace.
  std::size_t traced = 0;
  for (const auto& x : f.at("failures")) traced += x.contains("trace");
  EXPECT_GT(f.at("failures").size(), 20u);
  EXPECT_EQ(traced, 20u);
  EXPECT_EQ(run_cli_out("info " + dir + "/r.failures.json", &out), 0);
  EXPECT_NE(out.find("failures: " + std::to_string(f.at("failures").size()) + " records"), std::string::npos) << out;
  remove_dir(dir);
}

// replay checks the options a failures file records (as a scene's are) and
// reproduces a record only when the status, alpha and x all come back.
TEST(CommandLine, ReplayValidatesOptionsAndComparesAlphaAndX) {
  const std::string dir = temp_dir();
  const std::string sweep = dir + "/w.toml";
  std::ofstream(sweep) << "name = \"w\"\n[shapes]\nB = { family = \"superellipsoid\", a = 0.5, b = 1, c = 1.5, n = 8 }\n"
                          "[sweep]\ngenerator = \"uniform\"\nposes = 20\n[run]\npairs = \"all\"\npasses = [\"cold\"]\nrecord = [\"failures\"]\n"
                          "[solver]\nmax_iterations = 2\nmax_restarts = 0\ncontinuation = false\nbarrier = false\n";
  std::string out;
  ASSERT_EQ(run_cli_out("run " + sweep + " -o " + dir + "/r.json --no-progress", &out), 0);
  const std::string fails = dir + "/r.failures.json";
  const nlohmann::json f = read_json_file(fails);
  ASSERT_FALSE(f.at("failures").empty());
  const nlohmann::json rec = f.at("failures")[0];
  ASSERT_TRUE(rec.contains("x"));
  ASSERT_TRUE(rec.at("alpha").is_number());
  EXPECT_EQ(run_cli_out("replay " + fails, &out), 0) << out;
  EXPECT_NE(out.find("reproduced (status, alpha and x)"), std::string::npos) << out;
  auto edited = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json g = f;
    edit(g);
    std::ofstream(dir + "/g.json") << g.dump(1);
    return dir + "/g.json";
  };
  const double a = rec.at("alpha").get<double>();
  EXPECT_EQ(run_cli_out("replay " + edited([&](nlohmann::json& g) { g["failures"][0]["alpha"] = a * (1 + 1e-6); }), &out), 3);
  EXPECT_NE(out.find("NOT reproduced (alpha (recorded"), std::string::npos) << out;
  EXPECT_EQ(run_cli_out("replay " + edited([&](nlohmann::json& g) { g["failures"][0]["x"][2] = 1e3; }), &out), 3);
  EXPECT_NE(out.find("NOT reproduced (x differs)"), std::string::npos) << out;
  EXPECT_EQ(run_cli_out("replay " + edited([&](nlohmann::json& g) { g["failures"][0]["x"][0] = nullptr; }), &out), 3);
  EXPECT_EQ(run_cli_out("replay " + edited([&](nlohmann::json& g) { g["failures"][0]["status"] = "Converged"; }), &out), 3);
  EXPECT_NE(out.find("NOT reproduced (status differs)"), std::string::npos) << out;
  // The last bits of another build still reproduce.
  EXPECT_EQ(run_cli_out("replay " + edited([&](nlohmann::json& g) { g["failures"][0]["alpha"] = a * (1 + 1e-13); }), &out), 0);
  // Recorded options outside their ranges are refused, naming the file and option.
  std::string err;
  for (const auto& kv : std::vector<std::pair<std::string, nlohmann::json>>{{"tolerance", -1.0}, {"max_iterations", -5}}) {
    const std::string& key = kv.first;  // named, not a structured binding: a lambda may capture it (C++17)
    const nlohmann::json& v = kv.second;
    const std::string g = edited([&](nlohmann::json& j) { j["solver"][key] = v; });
    EXPECT_EQ(run_cli("replay " + g, &err), 1) << key;
    EXPECT_NE(err.find(g + ": solver: "), std::string::npos) << err;
    EXPECT_NE(err.find(key), std::string::npos) << err;
    EXPECT_EQ(err.find("reproduced"), std::string::npos) << err;
  }
  remove_dir(dir);
}

TEST(CommandLine, StressSigintLeavesNoPartialResults) {
  const std::string dir = temp_dir();
  const std::string scene = dir + "/long.toml";
  std::ofstream(scene) << with(kBase, "poses = 40", "poses = 100000000");
  const std::string out = dir + "/results.json";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    ::execl(IDCOL_HARNESS_EXE, IDCOL_HARNESS_EXE, "stress", scene.c_str(), "-o", out.c_str(), "--threads", "2", nullptr);
    std::_Exit(127);
  }
  for (int i = 0; i < 200 && list_dir(dir).size() < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_EQ(list_dir(dir), std::vector<std::string>{"long.toml"});
  remove_dir(dir);
}

// A pass in which nothing converged still reports its mean iterations, over
// every solve, and no mean over the converged ones.
TEST(Stress, MeanIterationsCountEverySolveWhenNothingConverged) {
  const idcol::Shape a = idcol::Sphere(1.0), b = idcol::Sphere(2.0);
  const AnswerChecker checker(a, b, OracleChoice::ClosedForm, idcol::SolverOptions{});
  idcol::Pose X;
  X.p = idcol::Vec3(4.0, 0.0, 0.0);
  StressTally tally;
  for (const int iterations : {30, 10}) {
    idcol::SolveResult r;
    r.status = idcol::SolveStatus::IterationLimit;
    r.iterations = iterations;
    EXPECT_EQ(tally.check(checker, X, r, 0, true).problem, "status iteration_limit");
  }
  const nlohmann::json it = tally.to_json().at("iterations");
  EXPECT_DOUBLE_EQ(it.at("mean").get<double>(), 20.0);
  EXPECT_TRUE(it.at("mean_converged").is_null());
  EXPECT_EQ(it.at("max"), 30);
}


// A results file's entries without their times (measured, not computed).
nlohmann::json without_times(nlohmann::json j) {
  if (j.is_object()) {
    for (const char* k : {"time", "timing", "wall_seconds"}) j.erase(k);
    for (auto& [k, v] : j.items()) v = without_times(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_times(v);
  }
  return j;
}

// Shards of a stress suite take its cases round robin; their merge is the
// single run in every figure but the times, and in every declared metric.
TEST(Stress, ShardsMergeToTheSingleRun) {
  const Scene s = parse_scene(std::string(kBase) + R"(
[[case]]
name = "c2"
body1 = "P"
body2 = "B"
kind = "shell"
rmin = 0.5
rmax = 4.0
poses = 30
passes = ["cold"]
)",
                              "t.toml");
  const nlohmann::json meta = {{"test", true}};
  const nlohmann::json whole = make_stress_results(s, run_stress(s, StudyOptions{}), meta);
  EXPECT_FALSE(whole.contains("shard"));  // an unsharded file is as before
  for (int n : {2, 3, 4}) {
    SCOPED_TRACE(n);
    std::vector<nlohmann::json> parts;
    for (int i = n - 1; i >= 0; --i) {  // any order
      StudyOptions o;
      o.shard_index = i;
      o.shard_count = n;
      parts.push_back(make_stress_results(s, run_stress(s, o), meta));
      EXPECT_EQ(parts.back().at("shard").at("count"), n);
    }
    const nlohmann::json merged = merge_entry_shards(parts, meta, {}, kStressSchema, "cases", "failure_records");
    ASSERT_EQ(merged.at("cases").size(), s.spec.as<StressSpec>().cases.size());
    EXPECT_EQ(without_times(merged.at("cases")), without_times(whole.at("cases")));
    const StudyKind& k = *study_kind_named("stress");
    for (std::size_t c = 0; c < s.spec.as<StressSpec>().cases.size(); ++c) {
      const auto a = entry_metrics(k.metrics(), whole["cases"][c]);
      const auto b = entry_metrics(k.metrics(), merged["cases"][c]);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t m = 0; m < a.size(); ++m)
        if (!find_metric(k.metrics(), a[m].first)->timing && !std::isnan(a[m].second)) EXPECT_EQ(a[m].second, b[m].second) << a[m].first;
    }
    // A shard missing, or given twice, is named.
    std::vector<nlohmann::json> short_by_one(parts.begin(), parts.end() - 1);
    EXPECT_THROW(merge_entry_shards(short_by_one, meta, {}, kStressSchema, "cases", "failure_records"), std::invalid_argument);
    std::vector<nlohmann::json> twice = parts;
    twice.back() = parts.front();
    EXPECT_THROW(merge_entry_shards(twice, meta, {}, kStressSchema, "cases", "failure_records"), std::invalid_argument);
  }
  // A whole run is not a shard.
  EXPECT_THROW(merge_entry_shards({whole}, meta, {}, kStressSchema, "cases", "failure_records"), std::invalid_argument);
}

// `merge FOLDER`: the shards' results files with their failures files beside
// them, as a job array leaves them; for a stress suite and a smoothing grid.
// --oracle-every K runs the oracle on poses 0, K, 2K, ... only (the CI's
// random-body cut), while every answer still gets the surface and normal
// checks; the results file records K, so compare sees a cut made otherwise.
TEST(CommandLine, OracleEveryThinsTheOracleAndKeepsEveryOtherCheck) {
  const std::string dir = temp_dir();
  const std::string scene = dir + "/rb.toml";
  std::ofstream(scene) << "name = \"rb\"\n[[case]]\nname = \"box-cone\"\nkind = \"random_bodies\"\nfamily1 = \"box\"\n"
                          "family2 = \"cone\"\nrange = \"normal\"\nseed = 2\nposes = 9\npasses = [\"cold\", \"warm\"]\n";
  std::string err;
  ASSERT_EQ(run_cli("stress " + scene + " -o " + dir + "/all.json --no-progress", &err), 0) << err;
  ASSERT_EQ(run_cli("stress " + scene + " -o " + dir + "/thin.json --oracle-every 4 --no-progress", &err), 0) << err;
  const nlohmann::json all = read_json_file(dir + "/all.json").at("cases")[0], thin = read_json_file(dir + "/thin.json").at("cases")[0];
  EXPECT_EQ(all.at("oracle_every"), 1);
  EXPECT_EQ(thin.at("oracle_every"), 4);
  for (const char* pass : {"cold", "warm", "cold_swapped", "warm_swapped"}) {
    SCOPED_TRACE(pass);
    const nlohmann::json &a = all.at("passes").at(pass), &t = thin.at("passes").at(pass);
    EXPECT_EQ(a.at("oracle").at("checked"), 9);
    EXPECT_EQ(t.at("oracle").at("checked"), 3);  // k = 0, 4, 8
    EXPECT_EQ(t.at("genuine"), 9);
    EXPECT_EQ(t.at("iterations"), a.at("iterations"));  // the same solves
    EXPECT_EQ(t.at("worst_surface_error"), a.at("worst_surface_error"));  // the same checks on every answer
  }
  EXPECT_EQ(run_cli("stress " + scene + " -o " + dir + "/x.json --oracle-every 0", &err), 2);
  EXPECT_NE(err.find("--oracle-every"), std::string::npos) << err;
  remove_dir(dir);
}

// [run] timed_path = "batch" times a sweep through solve_batch on one thread;
// the statistics are the loop's (the run stops if a batch row differs), the
// file says which path it timed, and compare refuses to set the two paths'
// times side by side. A file made before the field existed reads as "loop".
TEST(CommandLine, ASweepTimedThroughTheBatchSaysSoAndIsNotComparedWithTheLoop) {
  const std::string dir = temp_dir();
  const std::string head = "name = \"b\"\n[shapes]\nE = { family = \"superellipsoid\", a = 0.5, b = 1, c = 1.5, n = 1 }\n"
                           "P = { family = \"smooth_polytope\", normals = [[1,0,0],[-1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]], "
                           "offsets = [1,1,1,1,1,1], beta = 20 }\n[sweep]\ngenerator = \"paper\"\nposes = 3000\nwarm_chain = 1000\n"
                           "warmup = 100\n[run]\npairs = \"all\"\npasses = [\"cold\", \"warm\"]\n"
                           "record = [\"timing\", \"iterations\", \"residuals\"]\n";
  std::ofstream(dir + "/loop.toml") << head;
  std::ofstream(dir + "/batch.toml") << head << "timed_path = \"batch\"\n";
  std::string err;
  ASSERT_EQ(run_cli("run " + dir + "/loop.toml -o " + dir + "/loop.json --no-progress", &err), 0) << err;
  ASSERT_EQ(run_cli("run " + dir + "/batch.toml -o " + dir + "/batch.json --no-progress", &err), 0) << err;
  nlohmann::json loop = read_json_file(dir + "/loop.json");
  const nlohmann::json batch = read_json_file(dir + "/batch.json");
  EXPECT_EQ(loop.at("timing").at("path"), "loop");
  EXPECT_EQ(batch.at("timing").at("path"), "batch");
  EXPECT_TRUE(batch.at("timing").at("batch_simd").is_string());
  ASSERT_EQ(loop.at("pairs").size(), 3u);
  for (std::size_t i = 0; i < 3; ++i)
    for (const char* pass : {"cold", "warm"}) {
      const nlohmann::json &l = loop["pairs"][i]["passes"][pass], &b = batch["pairs"][i]["passes"][pass];
      EXPECT_EQ(b.at("iterations"), l.at("iterations")) << i << pass;
      EXPECT_EQ(b.at("residual"), l.at("residual")) << i << pass;
      EXPECT_EQ(b.at("status"), l.at("status")) << i << pass;
      EXPECT_GT(b.at("time").at("all").at("median_ns").get<double>(), 0.0) << i << pass;
    }
  EXPECT_EQ(run_cli("compare " + dir + "/loop.json " + dir + "/batch.json", &err), 2);
  EXPECT_NE(err.find("timing.path: OLD \"loop\", NEW \"batch\""), std::string::npos) << err;
  loop["timing"].erase("path");  // as written before the field existed
  write_file_atomically(dir + "/old.json", loop.dump());
  EXPECT_EQ(run_cli("compare " + dir + "/old.json " + dir + "/loop.json", &err), 0) << err;
  EXPECT_EQ(run_cli("compare " + dir + "/old.json " + dir + "/batch.json", &err), 2) << err;
  // Scene errors name the field.
  std::ofstream(dir + "/bad.toml") << head << "timed_path = \"simd\"\n";
  EXPECT_EQ(run_cli("check " + dir + "/bad.toml", &err), 1);
  EXPECT_NE(err.find("timed_path: expected \"loop\""), std::string::npos) << err;
  std::string untimed = head;
  untimed.replace(untimed.find("\"timing\", "), 10, "");
  std::ofstream(dir + "/untimed.toml") << untimed << "timed_path = \"batch\"\n";
  EXPECT_EQ(run_cli("check " + dir + "/untimed.toml", &err), 1);
  EXPECT_NE(err.find("needs \"timing\""), std::string::npos) << err;
  remove_dir(dir);
}

TEST(CommandLine, MergeTakesAFolderOfShardsWithTheirFailuresFiles) {
  const std::string dir = std::filesystem::temp_directory_path() / ("idcol_merge_folder_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/stress");
  const std::string scene = dir + "/t.toml";
  std::ofstream(scene) << kBase;
  std::string err;
  ASSERT_EQ(run_cli("stress " + scene + " -o " + dir + "/whole.json --no-progress", &err), 0) << err;
  for (int i = 0; i < 2; ++i)
    ASSERT_EQ(run_cli("stress " + scene + " -o " + dir + "/stress/" + std::to_string(i) + ".json --shard " + std::to_string(i) + "/2 --no-progress", &err), 0) << err;
  ASSERT_TRUE(std::filesystem::exists(dir + "/stress/0.failures.json"));
  ASSERT_EQ(run_cli("merge -o " + dir + "/merged.json " + dir + "/stress", &err), 0) << err;
  EXPECT_EQ(without_times(read_json_file(dir + "/merged.json").at("cases")), without_times(read_json_file(dir + "/whole.json").at("cases")));
  // The merge compares with the single run, either way round.
  EXPECT_EQ(run_cli("compare " + dir + "/whole.json " + dir + "/merged.json", &err), 0) << err;
  EXPECT_EQ(run_cli("compare " + dir + "/merged.json " + dir + "/whole.json", &err), 0) << err;
  // A failures file named on its own is still refused.
  EXPECT_NE(run_cli("merge -o " + dir + "/m2.json " + dir + "/stress/0.failures.json " + dir + "/stress/1.json", &err), 0);
  if (baselines_available()) {
    std::filesystem::create_directories(dir + "/smoothing");
    const std::string grid = std::string(IDCOL_CONFIGS_DIR) + "/smoothing_polytope.toml";
    ASSERT_EQ(run_cli("smoothing " + grid + " -o " + dir + "/sw.json --poses 60 --threads 1", &err), 0) << err;
    for (int i = 0; i < 3; ++i)
      ASSERT_EQ(run_cli("smoothing " + grid + " -o " + dir + "/smoothing/" + std::to_string(i) + ".json --poses 60 --threads 1 --shard " +
                            std::to_string(i) + "/3", &err), 0) << err;
    ASSERT_EQ(run_cli("merge -o " + dir + "/sm.json " + dir + "/smoothing", &err), 0) << err;
    EXPECT_EQ(without_times(read_json_file(dir + "/sm.json").at("points")), without_times(read_json_file(dir + "/sw.json").at("points")));
    EXPECT_EQ(run_cli("compare " + dir + "/sw.json " + dir + "/sm.json", &err), 0) << err;
    EXPECT_EQ(run_cli("compare " + dir + "/sm.json " + dir + "/sw.json", &err), 0) << err;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace idcol::harness
