// The command line as a user meets it: what `run` leaves when its results
// cannot be written, what `check` costs, what each command's --help lists.
// Each test runs the built idcol_harness in a child process.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "referee/methods.hpp"
#include "studies/study.hpp"

namespace idcol::harness {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A fresh folder under the test's temporary directory.
fs::path scratch(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("idcol_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// `idcol_harness ARGS` through the shell (ARGS may redirect); its exit
/// status, its standard output in *out (unless ARGS redirects it) and its
/// standard error in *err.
int harness(const std::string& args, std::string* out = nullptr, std::string* err = nullptr) {
  const fs::path o = fs::path(::testing::TempDir()) / ("idcol_cli_out_" + std::to_string(::getpid()));
  const fs::path e = fs::path(::testing::TempDir()) / ("idcol_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = std::string(IDCOL_HARNESS_EXE) + " " + args +
                          (args.find(" > ") == std::string::npos ? " > " + o.string() : "") + " 2> " + e.string();
  const int rc = std::system(cmd.c_str());
  if (out) *out = read_text(o);
  if (err) *err = read_text(e);
  fs::remove(o);
  fs::remove(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

const char* kSmallSweep = R"(
name = "small"
[shapes]
A = { family = "sphere", R = 1.0 }
B = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
[sweep]
generator = "paper"
poses = 200
[run]
pairs = "all"
passes = ["cold"]
record = ["iterations", "failures"]
)";

// `run -o - --failures F.json` into a full standard output: the run fails
// (exit 1) and F.json is the old one, untouched, with no temporary beside
// it (the failures file was once renamed over F.json before the results
// were written, and the run then failed). Into a writable one, both are
// written.
TEST(CommandLine, ResultsThatCannotBeWrittenToStandardOutputReplaceNoFailuresFile) {
  const fs::path dir = scratch("full");
  std::ofstream(dir / "s.toml") << kSmallSweep;
  const fs::path fails = dir / "F.json";
  std::ofstream(fails) << "old failures\n";
  std::string err;
  const std::string run = "run " + (dir / "s.toml").string() + " -o - --failures " + fails.string() + " --no-progress";
  EXPECT_EQ(harness(run + " > /dev/full", nullptr, &err), 1);
  EXPECT_NE(err.find("cannot write standard output"), std::string::npos) << err;
  EXPECT_NE(err.find("no file written"), std::string::npos) << err;
  EXPECT_EQ(read_text(fails), "old failures\n");
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.path().filename() != "s.toml" && e.path().filename() != "F.json";
  EXPECT_EQ(files, 0u) << "a temporary was left in " << dir;
  std::string out;
  EXPECT_EQ(harness(run, &out, &err), 0) << err;
  EXPECT_NE(out.find("\"schema\": \"idcol-harness-results\""), std::string::npos) << out.substr(0, 200);
  EXPECT_NE(read_text(fails).find("\"schema\": \"idcol-harness-failures\""), std::string::npos);
  fs::remove_all(dir);
}

// A reduced run says what it ran: the Markdown of a shard names its poses
// (it once printed the scene's whole count, "1000000 poses", for a
// 1/100 shard of Table 1), and `check` costs the run that `run` would make
// with the same options (it took none); an option that does not change
// the cost, or that the kind does not take, is a usage error.
TEST(CommandLine, AShardsTableAndCostSayWhatItRuns) {
  const fs::path dir = scratch("shard");
  std::string scene = kSmallSweep;
  scene.replace(scene.find("poses = 200"), 11, "poses = 200\nwarm_chain = 50");
  std::ofstream(dir / "s.toml") << scene;
  const std::string s = (dir / "s.toml").string(), r = (dir / "r.json").string();
  std::string out, err;
  ASSERT_EQ(harness("run " + s + " -o " + r + " --shard 1/4 --no-progress", &out, &err), 0) << err;
  ASSERT_EQ(harness("table " + r, &out, &err), 0) << err;
  EXPECT_NE(out.find("; 50 poses (poses 50 to 99 of the scene's 200: shard 1/4) per pair and pass"), std::string::npos) << out;
  ASSERT_EQ(harness("run " + s + " -o " + r + " --no-progress", &out, &err), 0) << err;
  ASSERT_EQ(harness("table " + r, &out, &err), 0) << err;
  EXPECT_NE(out.find("; 200 poses per pair and pass"), std::string::npos) << out;
  // 3 pairs x 1 pass x the shard's 50 poses.
  ASSERT_EQ(harness("check " + s + " --shard 1/4", &out, &err), 0) << err;
  EXPECT_NE(out.find("a valid sweep scene; shard 1/4: cost: 150 solves"), std::string::npos) << out;
  ASSERT_EQ(harness("check " + s, &out, &err), 0) << err;
  EXPECT_NE(out.find("a valid sweep scene; cost: 600 solves"), std::string::npos) << out;
  const std::string stress = std::string(IDCOL_CONFIGS_DIR) + "/stress.toml";
  ASSERT_EQ(harness("check " + stress + " --max-poses 10 --shard 0/1000", &out, &err), 0) << err;
  EXPECT_NE(out.find("shard 0/1000: cost: 20 solves"), std::string::npos) << out;  // case 0 alone: 10 poses, cold and warm
  // A shard that does not exist is a usage error (2), as the help says.
  for (const char* bad : {"3/2", "0/0", "1", "-1/4"}) {
    EXPECT_EQ(harness("run " + s + " -o " + r + " --shard " + bad + " --no-progress", &out, &err), 2) << bad;
    EXPECT_NE(err.find(std::string("--shard expects i/N with 0 <= i < N, got \"") + bad + "\""), std::string::npos) << err;
  }
  EXPECT_EQ(harness("check " + s + " --pin 0", &out, &err), 2);
  EXPECT_NE(err.find("unknown option --pin (check takes the options that change a run's cost"), std::string::npos) << err;
  EXPECT_EQ(harness("check " + s + " --max-poses 10", &out, &err), 2);
  EXPECT_NE(err.find("--max-poses does not apply to a sweep scene"), std::string::npos) << err;
  EXPECT_EQ(harness("check " + s + " " + s, &out, &err), 2);
  fs::remove_all(dir);
}

// merge without a shard says how to rerun it with the -o its shards'
// names give (the command once lacked -o altogether), for a sweep and for a
// kind sharded by entries; where the names follow no pattern, it asks for a
// path.
TEST(CommandLine, MergeWithoutAShardGivesTheRerunWithItsOutput) {
  const fs::path dir = scratch("rerun");
  std::ofstream(dir / "s.toml") << kSmallSweep;
  const std::string s = (dir / "s.toml").string();
  fs::create_directories(dir / "shards");
  std::string out, err;
  for (int i : {0, 1, 3})
    ASSERT_EQ(harness("run " + s + " -o " + (dir / "shards" / (std::to_string(i) + ".json")).string() + " --shard " +
                      std::to_string(i) + "/4 --no-progress", &out, &err), 0) << err;
  EXPECT_EQ(harness("merge -o " + (dir / "m.json").string() + " " + (dir / "shards").string(), &out, &err), 1);
  EXPECT_NE(err.find("shard 2/4 is missing"), std::string::npos) << err;
  EXPECT_NE(err.find("`idcol_harness run " + s + " -o " + (dir / "shards" / "2.json").string() + " --shard 2/4`"), std::string::npos) << err;
  fs::rename(dir / "shards" / "1.json", dir / "shards" / "first.json");
  EXPECT_EQ(harness("merge -o " + (dir / "m.json").string() + " " + (dir / "shards").string(), &out, &err), 1);
  EXPECT_NE(err.find("-o SHARD_i.json --shard i/4` (SHARD_i.json: where shard i's results go)"), std::string::npos) << err;
  const std::string stress = std::string(IDCOL_CONFIGS_DIR) + "/stress.toml";
  for (int i : {0, 2})
    ASSERT_EQ(harness("stress " + stress + " -o " + (dir / ("st_" + std::to_string(i) + "_of_3.json")).string() + " --shard " +
                      std::to_string(i) + "/3 --max-poses 5 --no-progress", &out, &err), 0) << err;
  EXPECT_EQ(harness("merge -o " + (dir / "m.json").string() + " " + (dir / "st_0_of_3.json").string() + " " +
                    (dir / "st_2_of_3.json").string(), &out, &err), 1);
  EXPECT_NE(err.find("-o " + (dir / "st_1_of_3.json").string() + " --shard 1/3`"), std::string::npos) << err;
  fs::remove_all(dir);
}

// A smoothing grid's recommendation threshold is a scene option, recorded
// in the results file for the Markdown (scripts/plot_smoothing.py) to use.
TEST(CommandLine, ASmoothingGridRecordsItsRecommendationThreshold) {
  if (!baselines_available()) GTEST_SKIP() << "the smoothing study needs a build with the baselines";
  const fs::path dir = scratch("smoothing");
  std::ofstream(dir / "g.toml") << "name = \"g\"\n[grid]\nshape = { family = \"superellipsoid\", a = 0.5, b = 1.0, c = 1.5 }\n"
                                   "parameter = \"n\"\nvalues = [4]\n[sweep]\nposes = 20\nwarmup = 5\n"
                                   "[study]\nhausdorff_directions = 50\noracle_check_poses = 5\nrecommend_error_below = 0.05\n";
  std::string out, err;
  ASSERT_EQ(harness("smoothing " + (dir / "g.toml").string() + " -o " + (dir / "r.json").string() + " --threads 1", &out, &err), 0) << err;
  EXPECT_NE(read_text(dir / "r.json").find("\"recommend_error_below\": 0.05"), std::string::npos);
  fs::remove_all(dir);
}

// `info` and `history show` print what a results file holds, names and
// machines included, escaped: a hand-edited scene name with a terminal
// escape sequence, a right-to-left override or a newline (which reached
// both raw, and the history's series key) neither reaches the terminal nor
// breaks a line.
TEST(CommandLine, InfoAndHistoryShowPrintNamesEscaped) {
  const fs::path dir = scratch("escaped");
  json r;
  std::ifstream(std::string(IDCOL_CONFIGS_DIR) + "/../results/baseline/ci.json") >> r;
  r["scene"]["name"] = "ci\x1b[2J\u202Eevil\nline";
  r["metadata"]["host"] = "host\x1b]0;title\x07";
  std::ofstream(dir / "ci.json") << r.dump(1);
  std::string out, err;
  ASSERT_EQ(harness("info " + (dir / "ci.json").string(), &out, &err), 0) << err;
  ASSERT_EQ(harness("history add " + (dir / "ci.json").string() + " --into " + (dir / "h.jsonl").string(), nullptr, &err), 0) << err;
  std::string shown;
  ASSERT_EQ(harness("history show " + (dir / "h.jsonl").string() + " --pair 'Poly-Poly' --metric 'cold.convergence_rate'", &shown, &err), 0)
      << err;
  for (const std::string& o : {out, shown}) {
    EXPECT_EQ(o.find('\x1b'), std::string::npos) << o;
    EXPECT_EQ(o.find("\u202E"), std::string::npos) << o;
    EXPECT_NE(o.find("ci\\x1B[2J\\u202Eevil\\nline"), std::string::npos) << o;
  }
  EXPECT_NE(out.find("host\\x1B]0;title\\x07"), std::string::npos) << out;
  fs::remove_all(dir);
}

// The commands whose help names the study kinds list every kind of the
// table (studies/registry.cpp): its scene and its options under `run`, its
// results files under `table` (or where its tables come from), `compare`
// and `metrics`. The time-of-impact kind was once missing from all four.
TEST(CommandLine, HelpListsEveryStudyKind) {
  std::string run, table, compare, metrics, all;
  ASSERT_EQ(harness("run --help", &run), 0);
  ASSERT_EQ(harness("table --help", &table), 0);
  ASSERT_EQ(harness("compare --help", &compare), 0);
  ASSERT_EQ(harness("metrics --help", &metrics), 0);
  ASSERT_EQ(harness("--help", &all), 0);
  for (const StudyKind& k : study_kinds()) {
    EXPECT_NE(run.find(std::string("        ") + k.scene_is + "\n"), std::string::npos) << k.name << "\n" << run;
    EXPECT_NE(run.find(std::string("      ") + k.name + ":"), std::string::npos) << k.name << "\n" << run;
    EXPECT_NE(table.find(k.has_table() ? k.noun : k.tables_from), std::string::npos) << k.name << "\n" << table;
    EXPECT_NE(compare.find(k.noun), std::string::npos) << k.name << "\n" << compare;
    EXPECT_NE(metrics.find(std::string(k.name) + (&k == &study_kinds().back().get() ? ")" : ",")), std::string::npos)
        << k.name << "\n" << metrics;
    EXPECT_NE(all.find(k.scene_is), std::string::npos) << k.name;
  }
  EXPECT_EQ(all.find("{"), all.find("{\"verdict\"")) << "a field of the help left unfilled";
  EXPECT_NE(run.find("--max-traced-failures M (default 20)"), std::string::npos) << run;
}

}  // namespace
}  // namespace idcol::harness
