// Every reader of the harness's files (compare, merge, table, info, history,
// replay) refuses a file that is not a valid one: a count below 0 or not an
// integer, a rate outside [0, 1], an entry listed twice, a schema version
// other than the one it reads, a field of the wrong type. Each refusal names
// the file, the field (its JSON path) and the value, exits non-zero and
// leaves no output file. Each tampered file is made here from a valid one
// (a fixture, a checked-in reference, or a run of a tiny scene).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "io/files.hpp"
#include "io/record.hpp"
#include "report/history.hpp"
#include "studies/results_file.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

const std::string kFixtures = IDCOL_HARNESS_FIXTURES_DIR;
const std::string kBaseline = std::filesystem::path(IDCOL_THRESHOLDS_FILE).parent_path().string();
const std::string kResults = std::filesystem::path(kBaseline).parent_path().string();

/// A folder of our own, removed with everything in it.
struct TempDir {
  std::string path;
  TempDir() {
    char templ[] = "/tmp/idcol_tampered_XXXXXX";
    path = ::mkdtemp(templ);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
};

/// Runs the harness; returns its exit status, stdout and stderr together in *text.
int cli(const std::string& args, std::string* text) {
  char templ[] = "/tmp/idcol_tampered_out_XXXXXX";
  const int fd = ::mkstemp(templ);
  ::close(fd);
  const int rc = std::system((std::string(IDCOL_HARNESS_EXE) + " " + args + " > " + templ + " 2>&1").c_str());
  std::ifstream in(templ);
  std::stringstream ss;
  ss << in.rdbuf();
  *text = ss.str();
  ::unlink(templ);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

void write(const std::string& path, const json& j) { std::ofstream(path) << j.dump(1) << "\n"; }

/// The command is refused: exit `rc`, a message naming each of `names` (the
/// file, the field, the value), no bare message of the JSON library, and no
/// file at `output` (where given).
void expect_refused(const std::string& args, int rc, const std::vector<std::string>& names, const std::string& output = "") {
  std::string text;
  EXPECT_EQ(cli(args, &text), rc) << args << "\n" << text;
  for (const std::string& n : names) EXPECT_NE(text.find(n), std::string::npos) << args << ": no \"" << n << "\" in\n" << text;
  EXPECT_EQ(text.find("[json.exception"), std::string::npos) << args << "\n" << text;
  if (!output.empty()) EXPECT_FALSE(std::filesystem::exists(output)) << args << " wrote " << output;
}

/// One tampering of a valid results file: what it changes, and the field
/// and value the refusal must name.
struct Tamper {
  std::string field, value;
  std::function<void(json&)> edit;
};

/// Each tampering of `valid` (a results file of `kind`) is refused by
/// compare (as NEW, exit 2), by info (exit 1) and, where the kind has a
/// table, by table (exit 1, no table written); the valid file passes each.
void expect_each_refused(const std::string& valid_path, bool has_table, const std::vector<Tamper>& tampers) {
  TempDir dir;
  const json valid = read_json_file(valid_path);
  write(dir / "valid.json", valid);
  std::string text;
  ASSERT_EQ(cli("compare " + dir / "valid.json " + dir / "valid.json", &text), 0) << text;
  ASSERT_EQ(cli("info " + dir / "valid.json", &text), 0) << text;
  if (has_table) ASSERT_EQ(cli("table " + dir / "valid.json -o " + dir / "valid.md", &text), 0) << text;
  for (std::size_t i = 0; i < tampers.size(); ++i) {
    const Tamper& t = tampers[i];
    SCOPED_TRACE(t.field + " = " + t.value);
    json bad = valid;
    t.edit(bad);
    const std::string path = dir / ("tampered" + std::to_string(i) + ".json");
    write(path, bad);
    expect_refused("compare " + dir / "valid.json " + path, 2, {"NEW", path, t.field, t.value});
    expect_refused("info " + path, 1, {path, t.field, t.value});
    if (has_table) expect_refused("table " + path + " -o " + dir / "t.md", 1, {path, t.field, t.value}, dir / "t.md");
  }
}

std::vector<Tamper> schema_versions() {
  std::vector<Tamper> v;
  for (const char* version : {"2", "4294967297", "1e10", "true", "\"1\"", "1.5", "null"})
    v.push_back({"schema_version", version, [version](json& r) { r["schema_version"] = json::parse(version); }});
  // 1e10 is written back as 10000000000.0.
  v[2].value = "10000000000.0";
  v.push_back({"schema_version", "has no", [](json& r) { r.erase("schema_version"); }});
  return v;
}

// A NEW sweep with failures = -5 once compared as PASS ("-5 better"), as did
// a rate of 1.5 and any schema version.
TEST(TamperedResults, SweepCountsRatesAndVersionsAreRefusedByName) {
  std::vector<Tamper> t = {
      {"pairs[0].passes.cold.failures", "-5", [](json& r) { r["pairs"][0]["passes"]["cold"]["failures"] = -5; }},
      {"pairs[0].passes.cold.failures", "2.5", [](json& r) { r["pairs"][0]["passes"]["cold"]["failures"] = 2.5; }},
      {"pairs[0].passes.cold.failures", "1.8446744073709552e+19",
       [](json& r) { r["pairs"][0]["passes"]["cold"]["failures"] = 18446744073709551616.0; }},  // 2^64
      {"pairs[0].passes.cold.failures", "\"0\"", [](json& r) { r["pairs"][0]["passes"]["cold"]["failures"] = "0"; }},
      {"pairs[0].passes.cold.convergence_rate", "1.5", [](json& r) { r["pairs"][0]["passes"]["cold"]["convergence_rate"] = 1.5; }},
      {"pairs[1].passes.cold.convergence_rate", "-0.5", [](json& r) { r["pairs"][1]["passes"]["cold"]["convergence_rate"] = -0.5; }},
      {"pairs[0].baselines.status.fcl_collide.genuine", "-1",
       [](json& r) { r["pairs"][0]["baselines"]["status"]["fcl_collide"]["genuine"] = -1; }},
      {"pairs[0].derivatives.agreement", "1.01", [](json& r) { r["pairs"][0]["derivatives"]["agreement"] = 1.01; }},
      {"pairs[0].body1", "7", [](json& r) { r["pairs"][0]["body1"] = 7; }},
  };
  for (Tamper& v : schema_versions()) t.push_back(v);
  // The fixture holds what compare and info read, not a table's metadata:
  // table is refused a tampered sweep in MergeRefusesAFileThatListsAnEntryTwice.
  expect_each_refused(kFixtures + "/compare_old.json", false, t);
}

TEST(TamperedResults, StressSmoothingAndToiCountsAndRatesAreRefusedByName) {
  expect_each_refused(kFixtures + "/compare_stress.json", true,
                      {{"cases[0].passes.cold.false_convergence.total", "-1",
                        [](json& r) { r["cases"][0]["passes"]["cold"]["false_convergence"]["total"] = -1; }},
                       {"cases[1].passes.warm.genuine_rate", "1.5", [](json& r) { r["cases"][1]["passes"]["warm"]["genuine_rate"] = 1.5; }},
                       {"cases[0].passes.cold.solves", "-3", [](json& r) { r["cases"][0]["passes"]["cold"]["solves"] = -3; }},
                       {"schema_version", "4294967297", [](json& r) { r["schema_version"] = 4294967297ull; }}});
  expect_each_refused(kFixtures + "/compare_smoothing.json", false,
                      {{"points[0].cold_accuracy_pass.converged_fraction", "1.5",
                        [](json& r) { r["points"][0]["cold_accuracy_pass"]["converged_fraction"] = 1.5; }},
                       {"points[1].cold_accuracy_pass.oracle_failures", "-2",
                        [](json& r) { r["points"][1]["cold_accuracy_pass"]["oracle_failures"] = -2; }},
                       {"schema_version", "true", [](json& r) { r["schema_version"] = true; }}});
  expect_each_refused(kBaseline + "/ci_toi.json", true,
                      {{"pairs[0].idcol.missed_contacts", "-1", [](json& r) { r["pairs"][0]["idcol"]["missed_contacts"] = -1; }},
                       {"pairs[0].oracle.clear_hits", "0.5", [](json& r) { r["pairs"][0]["oracle"]["clear_hits"] = 0.5; }},
                       {"pairs[1].idcol.solves_per_query", "-4", [](json& r) { r["pairs"][1]["idcol"]["solves_per_query"] = -4; }},
                       {"schema_version", "2", [](json& r) { r["schema_version"] = 2; }}});
}

// A pair listed twice once passed compare (the later copy won) and merge kept
// both; each kind's entries are refused when one is listed twice.
TEST(TamperedResults, AnEntryListedTwiceIsRefused) {
  struct Twice {
    std::string file, entries, key;
  };
  for (const Twice& t : {Twice{kFixtures + "/compare_old.json", "pairs", "A-A"}, Twice{kFixtures + "/compare_stress.json", "cases", ""},
                         Twice{kFixtures + "/compare_smoothing.json", "points", ""}, Twice{kBaseline + "/ci_toi.json", "pairs", ""}}) {
    SCOPED_TRACE(t.file);
    TempDir dir;
    json r = read_json_file(t.file);
    const std::size_t n = r[t.entries].size();
    r[t.entries].push_back(r[t.entries][0]);
    write(dir / "twice.json", r);
    std::vector<std::string> names = {dir / "twice.json", t.entries + "[" + std::to_string(n) + "]", t.entries + "[0]"};
    if (!t.key.empty()) names.push_back(t.key);
    expect_refused("compare " + t.file + " " + dir / "twice.json", 2, names);
    expect_refused("info " + dir / "twice.json", 1, names);
  }
}

/// A tiny sweep with two pairs, one of which fails most solves (B-B within
/// two iterations, no restart, barrier or continuation).
const char* kTinySweep = R"(name = "tiny"
[shapes]
A = { family = "sphere", R = 1.0 }
B = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
[sweep]
generator = "paper"
poses = 60
warm_chain = 20
warmup = 0
[run]
pairs = [["A", "B"], ["B", "B"]]
passes = ["cold", "warm"]
record = ["iterations", "failures"]
[solver]
max_iterations = 2
max_iterations_extended = 2
max_restarts = 0
barrier = false
continuation = false
)";

/// A tiny time-of-impact study: two pairs, one motion model, a few motions.
const char* kTinyToi = R"(name = "tiny_toi"
[shapes]
Ball = { family = "sphere", R = 0.3 }
Ellip = { family = "superellipsoid", a = 0.6, b = 0.3, c = 0.2, n = 1 }
[toi]
pairs = [["Ball", "Ellip"], ["Ellip", "Ellip"]]
motions = 6
models = ["translation"]
seed = 1
offset = 3.0
end_inside = 0.2
oracle_samples = 40
fcl = ["naive"]
fcl_naive_steps = 10
)";

// merge of one file that lists a pair twice once kept both; a shard that
// lists an entry twice, or holds a count below 0, is refused by name, and no
// merge is written.
TEST(TamperedResults, MergeRefusesAFileThatListsAnEntryTwice) {
  TempDir dir;
  std::ofstream(dir / "s.toml") << kTinySweep;
  std::string text;
  ASSERT_EQ(cli("run " + dir / "s.toml -o " + dir / "whole.json --no-progress", &text), 0) << text;
  for (int i = 0; i < 2; ++i)
    ASSERT_EQ(cli("run " + dir / "s.toml -o " + dir / ("s" + std::to_string(i) + ".json") + " --shard " + std::to_string(i) +
                      "/2 --no-progress", &text), 0) << text;
  ASSERT_EQ(cli("merge -o " + dir / "m.json " + dir / "s0.json " + dir / "s1.json", &text), 0) << text;
  json whole = read_json_file(dir / "whole.json");
  whole["pairs"].push_back(whole["pairs"][0]);
  write(dir / "whole.json", whole);
  expect_refused("merge -o " + dir / "m1.json " + dir / "whole.json", 1, {dir / "whole.json", "pairs[2]", "A-B"}, dir / "m1.json");
  expect_refused("table " + dir / "whole.json -o " + dir / "whole.md", 1, {dir / "whole.json", "pairs[2]", "A-B"}, dir / "whole.md");
  const json valid_s0 = read_json_file(dir / "s0.json");
  json s0 = valid_s0;
  s0["pairs"].push_back(s0["pairs"][1]);
  write(dir / "s0.json", s0);
  expect_refused("merge -o " + dir / "m2.json " + dir / "s0.json " + dir / "s1.json", 1, {dir / "s0.json", "pairs[2]", "B-B"},
                 dir / "m2.json");
  write(dir / "s0.json", valid_s0);
  json s1 = read_json_file(dir / "s1.json");
  s1["pairs"][0]["passes"]["warm"]["failures"] = -5;
  write(dir / "s1.json", s1);
  expect_refused("merge -o " + dir / "m3.json " + dir / "s0.json " + dir / "s1.json", 1,
                 {dir / "s1.json", "pairs[0].passes.warm.failures", "-5"}, dir / "m3.json");
}

// Merged shards once could not be compared with the single run (the shard's
// fields counted as what was run), and two time-of-impact runs of different
// solver options compared as one. The sweep and the time-of-impact study
// here; the stress suite and the smoothing grid in
// CommandLine.MergeTakesAFolderOfShardsWithTheirFailuresFiles.
TEST(MergedShards, CompareWithTheSingleRunOfASweepAndATimeOfImpactStudy) {
  TempDir dir;
  std::ofstream(dir / "sweep.toml") << kTinySweep;
  std::ofstream(dir / "toi.toml") << kTinyToi;
  std::string text;
  for (const char* kind : {"sweep", "toi"}) {
    SCOPED_TRACE(kind);
    const std::string scene = dir / (std::string(kind) + ".toml"), whole = dir / (std::string(kind) + "_whole.json");
    ASSERT_EQ(cli("run " + scene + " -o " + whole + " --no-progress", &text), 0) << text;
    std::string shards;
    for (int i = 0; i < 2; ++i) {
      const std::string shard = dir / (std::string(kind) + std::to_string(i) + ".json");
      ASSERT_EQ(cli("run " + scene + " -o " + shard + " --shard " + std::to_string(i) + "/2 --no-progress", &text), 0) << text;
      shards += " " + shard;
    }
    const std::string merged = dir / (std::string(kind) + "_merged.json");
    ASSERT_EQ(cli("merge -o " + merged + shards, &text), 0) << text;
    EXPECT_EQ(cli("compare " + whole + " " + merged, &text), 0) << text;
    EXPECT_NE(text.find("PASS"), std::string::npos) << text;
    EXPECT_EQ(cli("compare " + merged + " " + whole, &text), 0) << text;
    // Runs of another solver option are still refused, naming it.
    json other = read_json_file(merged);
    other["solver"]["tolerance"] = 1e-8;
    write(dir / "other.json", other);
    EXPECT_EQ(cli("compare " + whole + " " + dir / "other.json", &text), 2) << text;
    EXPECT_NE(text.find("solver.tolerance: OLD 1e-10, NEW 1e-08"), std::string::npos) << text;
  }
}

/// A history of one valid line, from the compare fixture as a run at git "cafe".
std::string valid_history(const TempDir& dir) {
  json r = read_json_file(kFixtures + "/compare_old.json");
  r["metadata"] = {{"git_revision", "cafe"}, {"git_dirty", false}, {"date_utc", "2026-01-01T00:00:00Z"}, {"host", "box"}};
  write(dir / "r.json", r);
  std::string text;
  EXPECT_EQ(cli("history add " + dir / "r.json --into " + dir / "h.jsonl", &text), 0) << text;
  EXPECT_EQ(cli("history show " + dir / "h.jsonl", &text), 0) << text;
  return dir / "h.jsonl";
}

json first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return json::parse(line);
}

// A history line's hostile schema_version once read as 1 (4294967297, true,
// 1e10), "2" gave a bare type_error of the JSON library, and a folder given
// to `history show` exited 0.
TEST(TamperedHistory, VersionsCountsAndFoldersAreRefusedByName) {
  TempDir dir;
  const std::string hist = valid_history(dir);
  const json line = first_line(hist);
  const std::vector<Tamper> tampers = {
      {"schema_version", "4294967297", [](json& l) { l["schema_version"] = 4294967297ull; }},
      {"schema_version", "true", [](json& l) { l["schema_version"] = true; }},
      {"schema_version", "10000000000.0", [](json& l) { l["schema_version"] = 1e10; }},
      {"schema_version", "\"2\"", [](json& l) { l["schema_version"] = "2"; }},
      {"schema_version", "2", [](json& l) { l["schema_version"] = 2; }},
      {"entries.A-A.cold.failures", "-5", [](json& l) { l["entries"]["A-A"]["cold.failures"] = -5; }},
      {"entries.A-B.cold.convergence_rate", "1.5", [](json& l) { l["entries"]["A-B"]["cold.convergence_rate"] = 1.5; }},
      {"run.git_dirty", "\"no\"", [](json& l) { l["run"]["git_dirty"] = "no"; }},
      {"guards[0].abs", "\"x\"", [](json& l) { l["guards"][0]["abs"] = "x"; }},
  };
  for (std::size_t i = 0; i < tampers.size(); ++i) {
    SCOPED_TRACE(tampers[i].field + " = " + tampers[i].value);
    json bad = line;
    tampers[i].edit(bad);
    const std::string path = dir / ("h" + std::to_string(i) + ".jsonl");
    std::ofstream(path) << bad.dump() << "\n";
    expect_refused("history show " + path, 2, {path + ":1", tampers[i].field, tampers[i].value});
    expect_refused("history show " + path + " --html " + dir / "p.html", 2, {path + ":1", tampers[i].field}, dir / "p.html");
    // Appending to it reads it first, and leaves it as it was.
    expect_refused("history add " + dir / "r.json --into " + path, 2, {path + ":1", tampers[i].field});
  }
  std::filesystem::create_directories(dir / "folder");
  expect_refused("history show " + dir / "folder", 2, {dir / "folder"});
  expect_refused("history add " + dir / "r.json --into " + dir / "folder", 2, {dir / "folder"});
  // A results file with a count below 0 is not added.
  json r = read_json_file(dir / "r.json");
  r["pairs"][0]["passes"]["cold"]["failures"] = -5;
  write(dir / "bad.json", r);
  expect_refused("history add " + dir / "bad.json --into " + dir / "new.jsonl", 2,
                 {dir / "bad.json", "pairs[0].passes.cold.failures", "-5"}, dir / "new.jsonl");
}

// replay of a malformed failures file once printed bare messages of the JSON
// library ("[json.exception.type_error.302] ...") and replayed a file of
// schema_version 9.
TEST(TamperedFailures, ReplayAndInfoNameTheFieldAndTheValue) {
  TempDir dir;
  std::ofstream(dir / "s.toml") << kTinySweep;
  std::string text;
  ASSERT_EQ(cli("run " + dir / "s.toml -o " + dir / "s.json --max-traced-failures 0 --no-progress", &text), 0) << text;
  const json valid = read_json_file(dir / "s.failures.json");
  ASSERT_GE(valid["failures"].size(), 2u) << "the tiny sweep fails no solve";
  std::size_t warm = 0;  // a record of the warm pass: it carries the warm start
  while (warm < valid["failures"].size() && !valid["failures"][warm].contains("warm_start")) ++warm;
  ASSERT_LT(warm, valid["failures"].size());
  const std::string w = "failures[" + std::to_string(warm) + "]";
  const int replayed = cli("replay " + dir / "s.failures.json --index " + std::to_string(warm), &text);
  EXPECT_TRUE(replayed == 0 || replayed == 3) << text;
  EXPECT_EQ(cli("info " + dir / "s.failures.json", &text), 0) << text;
  struct FailuresTamper {
    std::string field, value;
    std::function<void(json&)> edit;
  };
  const std::vector<FailuresTamper> tampers = {
      {"schema_version", "9", [](json& f) { f["schema_version"] = 9; }},
      {"schema_version", "\"1\"", [](json& f) { f["schema_version"] = "1"; }},
      {"failures", "{}", [](json& f) { f["failures"] = json::object(); }},
      {w + ".pose.R[0][1]", "\"x\"", [&](json& f) { f["failures"][warm]["pose"]["R"][0][1] = "x"; }},
      {w + ".pose.p", "[1,2]", [&](json& f) { f["failures"][warm]["pose"]["p"] = {1, 2}; }},
      {w + ".shape1", "5", [&](json& f) { f["failures"][warm]["shape1"] = 5; }},
      {w + ".iterations", "\"many\"", [&](json& f) { f["failures"][warm]["iterations"] = "many"; }},
      {w + ".k", "-1", [&](json& f) { f["failures"][warm]["k"] = -1; }},
      {w + ".status", "3", [&](json& f) { f["failures"][warm]["status"] = 3; }},
      {w + ".warm_start.valid", "1", [&](json& f) { f["failures"][warm]["warm_start"]["valid"] = 1; }},
      {w + ".alpha", "\"0.5\"", [&](json& f) { f["failures"][warm]["alpha"] = "0.5"; }},
      {w, "has no \"pose\"", [&](json& f) { f["failures"][warm].erase("pose"); }},
      {"metadata.git_dirty", "\"yes\"", [](json& f) { f["metadata"]["git_dirty"] = "yes"; }},
  };
  for (std::size_t i = 0; i < tampers.size(); ++i) {
    const FailuresTamper& t = tampers[i];
    SCOPED_TRACE(t.field + " = " + t.value);
    json bad = valid;
    t.edit(bad);
    const std::string path = dir / ("f" + std::to_string(i) + ".json");
    write(path, bad);
    expect_refused("replay " + path + " --index " + std::to_string(warm), 1, {path, t.field, t.value});
    expect_refused("info " + path, 1, {path, t.field, t.value});
  }
}

// The checked-in files all pass the check every reader makes: each results
// and failures file under results/ and results/baseline/, the fixtures (the
// corrupt one, not JSON, aside) and the repository's history.
TEST(CheckedInFiles, EveryResultsFailuresAndHistoryFileReads) {
  std::size_t results = 0, failures = 0;
  for (const std::string& dir : {kResults, kBaseline, kFixtures})
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      const std::string path = e.path().string();
      if (e.path().extension() != ".json" || e.path().filename() == "compare_corrupt.json") continue;
      const json j = read_json_file(path);
      const std::string schema = j.is_object() && j.contains("schema") && j["schema"].is_string() ? j["schema"].get<std::string>() : "";
      try {
        if (study_kind_of_schema(schema)) {
          check_results(j, path);
          ++results;
        } else if (schema == kFailuresSchema) {
          check_failures_file(j, path);
          ++failures;
        }
      } catch (const FileError& err) {
        ADD_FAILURE() << err.what();
      }
    }
  EXPECT_GE(results, 20u);
  EXPECT_GE(failures, 10u);
  try {
    EXPECT_GE(read_history(kResults + "/history.jsonl").size(), 10u);
  } catch (const HistoryError& err) {
    ADD_FAILURE() << err.what();
  }
}

}  // namespace
}  // namespace idcol::harness
