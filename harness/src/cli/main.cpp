// idcol_harness: the command line of the harness (see kCommands). run, stress
// and smoothing are one command over the Study interface (studies/study.hpp).
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "idcol/solver.hpp"
#include "cli/history_cmd.hpp"
#include "studies/sweep/agreement.hpp"
#include "report/compare.hpp"
#include "studies/metric_list.hpp"
#include "studies/results_file.hpp"
#include "studies/study.hpp"
#include "studies/sweep/sweep.hpp"
#include "scene/scene.hpp"
#include "stats/stats.hpp"
#include "studies/stress/stress.hpp"
#include "io/keys.hpp"
#include "io/files.hpp"

using namespace idcol;
using namespace idcol::harness;
using nlohmann::json;

namespace {

/// Each command's synopsis and options, with their defaults: `idcol_harness
/// CMD --help` prints one, the usage message all of them.
struct CommandHelp {
  const char* name;
  const char* text;
};
// Exit codes shared by the commands that run or read files.
#define IDCOL_EXIT_RUN \
  "      exit: 0 done (failed solves are counted in the results, not an error); 1 a scene or file could not be\n" \
  "            read or written; 2 usage error; 130 interrupted (SIGINT/SIGTERM): nothing written\n"
#define IDCOL_EXIT_READ "      exit: 0 done; 1 a file could not be read or written, or is not of the right kind; 2 usage error\n"
#define IDCOL_RUN_OPTIONS \
  "      -o RESULTS.json     where the results go (required); -o - : standard output (then --failures F is required)\n" \
  "      --failures F        failure records (default: RESULTS with .failures.json)\n" \
  "      --no-progress       no progress line on stderr (default: a progress line when stderr is a terminal)\n" \
  "      --shard i/N         run the i-th of N shards (default 0/1: everything); merge puts them back together\n"
const CommandHelp kCommands[] = {
    {"run",
     "  idcol_harness run SCENE.toml -o RESULTS.json [options]\n"
     "      any scene (`check` first gives its cost):\n{scene list}" IDCOL_RUN_OPTIONS
     "{run options}" IDCOL_EXIT_RUN},
    {"stress",
     "  idcol_harness stress STRESS.toml -o RESULTS.json [options]\n"
     "      run, for a stress suite only (a scene with [[case]]s; a random-body suite too)\n" IDCOL_RUN_OPTIONS
     "      --threads T         threads (default 1; the counts do not depend on it)\n"
     "      --max-failures N    failure records kept per case and pass (default 2000; all are counted)\n"
     "      --max-poses N       each case's first min(poses, N) poses (default all; CI: 1000)\n"
     "      --oracle-every K    the oracle (LP, support function, ...) on poses k = 0, K, 2K, ... only; the surface\n"
     "                          and normal checks stay on every answer (default: each case's oracle_every, 1)\n" IDCOL_EXIT_RUN},
    {"smoothing",
     "  idcol_harness smoothing GRID.toml -o RESULTS.json [options]\n"
     "      run, for a smoothing grid only (a scene with [grid]); needs a build with the baselines\n" IDCOL_RUN_OPTIONS
     "      --poses N           poses per grid value (default: the scene's `poses`; CI: 2000)\n"
     "      --threads T         threads of the accuracy pass (default 2)\n"
     "      --pin CPU           the CPU of the timed passes (default: not pinned)\n"
     "      figures and tables: scripts/plot_smoothing.py RESULTS.json -o DIR --md TABLES.md\n" IDCOL_EXIT_RUN},
    {"toi",
     "  idcol_harness toi TOI.toml -o RESULTS.json [options]\n"
     "      run, for a time-of-impact study (a scene with [toi]) only; FCL's continuousCollide beside idcol where built\n" IDCOL_RUN_OPTIONS
     "      --pin CPU           the CPU of the timed loops (default: not pinned)\n"
     "      shards are the entries (pairs x models) i, i+N, ...\n" IDCOL_EXIT_RUN},
    {"table",
     "  idcol_harness table RESULTS.json [-o TABLE.md]\n"
     "      a {tables} results file as Markdown, from the file alone; stress-table is the same\n"
     "{tables from}"
     "      -o TABLE.md         where the table goes (default: standard output)\n" IDCOL_EXIT_READ},
    {"merge",
     "  idcol_harness merge -o MERGED.json SHARD.json...|FOLDER... [--allow-mixed]\n"
     "      the shards of one scene of any kind (a FOLDER: its results files; failures files beside them are skipped)\n"
     "      -o MERGED.json      where the merge goes (required)\n"
     "      --allow-mixed       merge shards of different git revisions (or, for timing, CPUs, compilers, flags) anyway,\n"
     "                          listing what differs in metadata.mixed_shards (default: refused, naming the field)\n"
     "      exit: 0 merged; 1 a shard is missing, unreadable or of another scene or revision; 2 usage error\n"},
    {"replay",
     "  idcol_harness replay FAILURES.json [--index I]\n"
     "      re-solves one failure record with its iteration trace, and says when the record was made by another\n"
     "      git revision than this binary's (then a different answer may be the code's change, not chance)\n"
     "      --index I           the record (default 0; `info FAILURES.json` counts them)\n"
     "      exit: 0 reproduced (same status); 3 not reproduced, or a record with no solve to replay;\n"
     "            1 the file cannot be read or has no such record; 2 usage error\n"},
    {"check",
     "  idcol_harness check SCENE.toml [--shard i/N] [--threads T] [--max-poses N] [--oracle-every K] [--poses N]\n"
     "      validates any scene and prints its cost: solves, and a rough time for this machine class on the kind's\n"
     "      default threads, in parts (solves, checks, oracles, baselines, derivatives; a smoothing grid's accuracy\n"
     "      pass and geometry; a time-of-impact study's oracle and FCL), from per-query constants measured on one\n"
     "      machine (harness/src/studies/cost_model.hpp; within a factor of 2 of the runs measured there); a sweep\n"
     "      scene is also printed back as read, with every default filled in\n"
     "      --shard, --threads, --max-poses, --oracle-every, --poses: the cost of `run` with these options, as `run`\n"
     "                          takes them for the scene's kind (default: the whole scene on the kind's default threads)\n"
     IDCOL_EXIT_READ},
    {"compare",
     "  idcol_harness compare OLD.json NEW.json [--thresholds T.toml] [--all] [--common-pairs] [--allow-mismatch] [--json]\n"
     "      two results files of one kind ({results}),\n"
     "      OLD the reference and NEW the run judged; prints the metrics that changed (--all: every one) and the\n"
     "      number compared; rates change in percentage points\n"
     "      runs of different scenes, shapes, pose sets or counts, solver options or kinds are refused, naming the fields\n"
     "      that differ; --allow-mismatch compares them anyway, those fields heading the report\n"
     "      --common-pairs      compare the pairs (cases, points) both files hold and name the others\n"
     "      --thresholds T      guards added to the declared defaults (a guard with replace = true replaces the default\n"
     "                          of the metrics it matches); default: thresholds.toml beside OLD.json if present\n"
     "      --json              the report as JSON on standard output (on bad input: {\"verdict\": \"ERROR\", ...})\n"
     "      --all               every metric, changed or not (default: only the changes)\n"
     "      --only-changes      only the metrics that changed (the default; kept for old scripts)\n"
     "      exit: 0 no guarded metric worsened beyond its threshold; 1 a regression (a guarded metric worse, or missing,\n"
     "            null or NaN in NEW, or a count that vanished); 2 bad input (unreadable or incomplete file, runs that\n"
     "            differ, a guard matching no metric) or usage error\n"},
    {"history", kHistoryUsage},
    {"info",
     "  idcol_harness info FILE.json\n"
     "      a few lines on any file the harness writes: what, when, where, by which build, its headline figures;\n"
     "      no options\n" IDCOL_EXIT_READ},
    {"shapes", "  idcol_harness shapes\n      the shape families a scene can use, with their parameters; no options\n      exit: 0\n"},
    {"metrics",
     "  idcol_harness metrics [--json | --keys] [KIND]\n"
     "      the declared metrics of each study kind ({kinds}) or of KIND: name, key in the\n"
     "      results file, unit, better direction, merge rule, default guard\n"
     "      --json              as JSON (results/metrics.json is this; the plot scripts read it)\n"
     "      --keys              each metric's key once, one per line (the counts of work a scene fixes aside:\n"
     "                          solves, poses, checked, queries)\n"
     "      exit: 0 listed; 2 usage error or an unknown KIND\n"},
    {"version", "  idcol_harness --version\n      project version, git revision, compiler and libraries\n      exit: 0\n"},
};

/// "a, b or c".
std::string listed(const std::vector<std::string>& items, const char* last = " or ") {
  std::string t;
  for (std::size_t i = 0; i < items.size(); ++i) t += (i == 0 ? "" : i + 1 == items.size() ? last : ", ") + items[i];
  return t;
}

/// A command's help, with what differs by study kind filled in from the
/// table of kinds (studies/registry.cpp), so that a new kind is listed by
/// every command without an edit here: {scene list} (each kind's scene, a
/// line each), {run options} (the options `run` takes for each), {tables}
/// (the kinds `table` reads) and {tables from} (where the others' tables
/// come from),
/// {results} (their results files, by noun), {kinds} (their names).
std::string help_text(const CommandHelp& c) {
  std::vector<std::string> tables, results, kinds;
  std::string run_options, tables_from, scene_list;
  std::size_t width = 0;
  for (const StudyKind& k : study_kinds()) width = std::max(width, std::string(k.name).size() + 2);
  for (const StudyKind& k : study_kinds()) {
    scene_list += "        " + std::string(k.scene_is) + "\n";
    results.emplace_back(k.noun);
    kinds.emplace_back(k.name);
    if (k.has_table()) tables.emplace_back(k.noun);
    else tables_from += "      (a " + std::string(k.noun) + " results file: its tables and figures come from " + k.tables_from + ")\n";
    std::string head = std::string(k.name) + ":";
    for (std::size_t at = 0, end; at < std::strlen(k.run_options); at = end + 1, head.clear()) {
      end = std::string(k.run_options).find('\n', at);
      if (end == std::string::npos) end = std::strlen(k.run_options);
      run_options += "      " + head + std::string(width + 1 - head.size(), ' ') + std::string(k.run_options + at, end - at) + "\n";
    }
  }
  std::string t = c.text;
  for (const auto& [field, value] : std::vector<std::pair<std::string, std::string>>{{"{scene list}", scene_list},
                                                                                     {"{run options}", run_options},
                                                                                     {"{tables}", listed(tables)},
                                                                                     {"{tables from}", tables_from},
                                                                                     {"{results}", listed(results)},
                                                                                     {"{kinds}", listed(kinds, ", ")}})
    for (std::size_t at; (at = t.find(field)) != std::string::npos;) t.replace(at, field.size(), value);
  return t;
}

std::string usage() {
  std::string u = "usage:\n";
  for (const CommandHelp& c : kCommands) u += help_text(c);
  return u;
}

const CommandHelp* command_help(const std::string& name) {
  for (const CommandHelp& c : kCommands)
    if (name == c.name || (name == "stress-table" && std::string(c.name) == "table")) return &c;
  return nullptr;
}

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

extern "C" void on_sigint(int) { interrupt_flag().store(true); }

/// SIGINT and SIGTERM raise interrupt_flag(): the run stops at its next pose
/// and writes nothing.
void stop_on_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

std::string replace_suffix(const std::string& path, const std::string& suffix) {
  const std::string ext = ".json";
  if (path.size() > ext.size() && path.compare(path.size() - ext.size(), ext.size(), ext) == 0)
    return path.substr(0, path.size() - ext.size()) + suffix;
  return path + suffix;
}

/// require_distinct_files (io/files.hpp), a clash being a usage error.
void require_distinct_arguments(const std::vector<std::pair<std::string, std::string>>& inputs,
                                const std::vector<std::pair<std::string, std::string>>& outputs) {
  try {
    require_distinct_files(inputs, outputs);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

std::string need(const std::vector<std::string>& a, std::size_t& i) {
  if (i + 1 >= a.size()) throw UsageError(a[i] + " needs a value");
  return a[++i];
}

/// Parses a count option, naming the option and the value on error.
int parse_int_option(const std::string& opt, const std::string& v, int lo, int hi) {
  std::size_t used = 0;
  int n = 0;
  try {
    n = std::stoi(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || v.empty() || n < lo || n > hi)
    throw UsageError(opt + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got \"" + v + "\"");
  return n;
}

/// --pin: the CPU must be one this process may run on, checked before the run
/// (sched_setaffinity's own "Invalid argument" names neither option nor CPU).
int parse_pin_option(const std::string& opt, const std::string& v) {
  const int cpu = parse_int_option(opt, v, 0, CPU_SETSIZE - 1);
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0 && !CPU_ISSET(cpu, &allowed)) {
    std::string list;
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &allowed)) list += (list.empty() ? "" : ", ") + std::to_string(c);
    throw UsageError(opt + " expects a CPU this process may run on (" + list + "), got \"" + v + "\"");
  }
  return cpu;
}

/// Refuses, as a usage error, a flag in `given` that the study does not take.
void require_flags_apply(const Study& study, const std::vector<std::string>& given) {
  const std::vector<std::string> takes = study.flags();
  for (const std::string& f : given)
    if (std::find(takes.begin(), takes.end(), f) == takes.end()) {
      std::string list;
      for (const std::string& t : takes) list += (list.empty() ? "" : ", ") + t;
      throw UsageError(f + " does not apply to a " + study.kind().name + " scene (it takes " + list + ")");
    }
}

/// Reads an option of a run that changes its cost (--shard, --threads,
/// --max-poses, --oracle-every, --poses) at a[i] into `opt`, moving i past
/// its value; false if a[i] is none of them. `run` and `check` read them alike.
bool parse_cost_option(const std::vector<std::string>& a, std::size_t& i, StudyOptions& opt) {
  const std::string& f = a[i];
  if (f == "--shard") {
    const std::string v = need(a, i);
    try {
      std::tie(opt.shard_index, opt.shard_count) = parse_shard(v);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  else if (f == "--threads") opt.threads = parse_int_option(f, need(a, i), 1, 256);
  else if (f == "--max-poses") opt.max_poses = parse_int_option(f, need(a, i), 1, 2000000000);
  else if (f == "--oracle-every") opt.oracle_every = parse_int_option(f, need(a, i), 1, 2000000000);
  else if (f == "--poses") opt.poses = parse_int_option(f, need(a, i), 1, 2000000000);
  else return false;
  return true;
}

/// run, stress and smoothing: any scene through the Study interface (studies/study.hpp);
/// `kind` ("" for run) is the kind the command expects.
int cmd_run(const std::vector<std::string>& a, int argc, char** argv, const std::string& kind) {
  std::string scene_path, out_path, failures_path, per_pose_path;
  StudyOptions opt;
  bool progress = true;
  std::vector<std::string> given;  // flags that only some studies take
  for (std::size_t i = 1; i < a.size(); ++i) {
    const std::string& f = a[i];
    if (f == "-o" || f == "--output") out_path = need(a, i);
    else if (f == "--failures") failures_path = need(a, i);
    else if (f == "--no-progress") progress = false;
    else if (f.empty() || f[0] != '-') {
      if (!scene_path.empty()) throw UsageError("more than one scene given");
      scene_path = f;
      continue;
    } else {
      given.push_back(f);
      if (f == "--per-pose") per_pose_path = need(a, i);
      else if (f == "--pin") opt.pin = parse_pin_option(f, need(a, i));
      else if (f == "--max-traced-failures") opt.max_traced_failures = parse_int_option(f, need(a, i), 0, 2000000000);
      else if (f == "--max-failures") opt.max_failures = parse_int_option(f, need(a, i), 0, 100000000);
      else if (!parse_cost_option(a, i, opt)) throw UsageError("unknown option " + f);
    }
  }
  const std::string cmd = a[0];
  if (scene_path.empty() || out_path.empty()) throw UsageError(cmd + " needs a scene and -o RESULTS.json");
  const std::unique_ptr<Study> study = load_study(scene_path, kind);
  require_flags_apply(*study, given);

  json meta = collect_metadata(argc, argv);
  if (opt.pin >= 0 && study->kind().pin_whole_run) pin_to_cpu(opt.pin);
  meta["pinned_cpu"] = opt.pin >= 0 ? json(opt.pin) : json(nullptr);
  meta["threads"] = opt.threads > 0 ? opt.threads : study->kind().default_threads;
  if (out_path == "-" && ((study->records_failures() && failures_path.empty()) || (study->records_per_pose() && per_pose_path.empty())))
    throw UsageError(std::string("-o - (standard output): a ") + study->kind().name + " scene also writes " +
                     (study->records_failures() && failures_path.empty() ? "failure records: give --failures FILE" : "per-pose rows: give --per-pose FILE"));
  if (study->records_failures() && failures_path.empty()) failures_path = replace_suffix(out_path, ".failures.json");
  if (study->records_per_pose() && per_pose_path.empty()) per_pose_path = replace_suffix(out_path, ".poses.csv");
  require_distinct_arguments({{"the scene", scene_path}},
                             {{"-o", out_path},
                              {"--failures", study->records_failures() ? failures_path : ""},
                              {"--per-pose", study->records_per_pose() ? per_pose_path : ""}});
  opt.progress = progress && ::isatty(2);
  if (study->estimated_seconds(opt) > 60.0) std::fprintf(stderr, "idcol_harness: %s\n", cost_line(*study, opt).c_str());
  stop_on_signals();

  // Every output goes through an AtomicFile, created before the run so that an
  // unwritable path fails at once: an interrupted run leaves none.
  AtomicFile results_file(out_path, "-o");
  std::unique_ptr<AtomicFile> per_pose_file, failures_file;
  if (study->records_per_pose()) {
    per_pose_file = std::make_unique<AtomicFile>(per_pose_path, "--per-pose");
    per_pose_file->write(per_pose_csv_header());
    opt.per_pose = per_pose_file->stream();
  }
  if (study->records_failures()) failures_file = std::make_unique<AtomicFile>(failures_path, "--failures");
  RecordSink sink{failures_path};
  json results;
  try {
    results = study->run(opt, meta, sink);
  } catch (const Interrupted&) {
    std::fprintf(stderr, "\nidcol_harness: interrupted; no results written\n");
    return 130;  // AtomicFile destructors remove the temporary files
  }
  if (interrupt_flag().load()) {
    std::fprintf(stderr, "idcol_harness: interrupted; no results written\n");
    return 130;
  }
  // All or nothing: every output is complete on disk before any is renamed
  // over its target. A write that fails (a full disk) throws here and every
  // old file stays as it was. A results file is renamed last, so that its
  // failures file beside it is complete when it appears; results on
  // standard output (-o -) are written first, since that write can fail
  // only when it is made (a full disk, a closed pipe) and no file may be
  // replaced before it has succeeded.
  try {
    if (failures_file) {
      failures_file->write(harness::failures_file(meta, study->scene(), study->solver(), out_path, sink.failures).dump(1) + "\n");
      failures_file->stage();
    }
    if (per_pose_file) per_pose_file->stage();
    results_file.write(results.dump(1) + "\n");
    results_file.stage();
    if (out_path == "-") results_file.publish();
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + (out_path == "-" ? "; no file written (standard output may hold part of the results)"
                                                                      : "; no output written") +
                             ", every old one is as it was");
  }
  if (failures_file) failures_file->publish();
  if (per_pose_file) per_pose_file->publish();
  if (out_path != "-") results_file.publish();
  if (const std::uint64_t aborts = baseline_aborts_trapped())
    std::fprintf(stderr,
                 "idcol_harness: note: %llu \"Assertion ... failed\" line%s above came from FCL, not from this program: Debian's "
                 "libfcl keeps its assertions on, and its EPA asserts on some poses near touching contact. Each abort was trapped "
                 "and counted as a failed FCL query (baselines.<method>.failed in the results).\n",
                 static_cast<unsigned long long>(aborts), aborts == 1 ? "" : "s");
  std::FILE* say = out_path == "-" ? stderr : stdout;  // standard output holds the results
  std::fprintf(say, "%sresults: %s\n", study->summary(results).c_str(), out_path == "-" ? "standard output" : out_path.c_str());
  if (failures_file) std::fprintf(say, "failures: %s (%zu)\n", failures_path.c_str(), sink.failures.size());
  if (per_pose_file) std::fprintf(say, "per-pose: %s\n", per_pose_path.c_str());
  return 0;
}

int cmd_table(const std::vector<std::string>& a) {
  std::string in, out;
  for (std::size_t i = 1; i < a.size(); ++i) {
    if (a[i] == "-o") out = need(a, i);
    else if (in.empty()) in = a[i];
    else throw UsageError("table takes one results file");
  }
  if (in.empty()) throw UsageError("table needs a results file");
  require_distinct_arguments({{"the results file", in}}, {{"-o", out}});
  // Any results file of the harness, by its schema.
  const json r = read_json_file(in);
  const std::string schema = r.is_object() && r.contains("schema") && r.at("schema").is_string() ? r.at("schema").get<std::string>() : "";
  const StudyKind* k = study_kind_of_schema(schema);
  if (!k || !k->has_table()) {
    if (k) throw std::runtime_error(in + ": a " + k->noun + " results file; its tables and figures come from " + k->tables_from);
    std::string expected;
    for (const StudyKind& t : study_kinds())
      if (t.has_table()) expected += std::string(expected.empty() ? "" : " or ") + "\"" + t.schema + "\"";
    throw std::runtime_error(in + ": schema \"" + schema + "\" is not a results file of the harness (expected " + expected + ")");
  }
  check_results(r, in);
  std::string md;
  // A file that claims a schema but lacks its fields (hand-edited, truncated
  // by a tool, or of an older harness): name the file and what it should hold,
  // not only the JSON library's "key 'sweep' not found".
  try {
    md = k->table(r, in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(in + ": schema \"" + schema + "\" but not a complete " + k->noun + " results file (" + e.what() + ")");
  }
  if (out.empty() || out == "-") std::cout << md;
  else write_file_atomically(out, md);
  return 0;
}

int cmd_merge(const std::vector<std::string>& a, int argc, char** argv) {
  std::string out;
  std::vector<json> shards;
  std::vector<std::string> paths;
  bool allow_mixed = false;
  // A folder stands for its *.json files that are results files: each
  // shard's failures file may lie beside its results.
  auto add = [&](const std::string& p, bool from_folder) {
    json r = read_json_file(p);
    if (from_folder && r.is_object() && r.contains("schema") && r.at("schema") == kFailuresSchema) return;
    check_results(r, p);
    shards.push_back(std::move(r));
    paths.push_back(p);
  };
  for (std::size_t i = 1; i < a.size(); ++i) {
    if (a[i] == "-o") out = need(a, i);
    else if (a[i] == "--allow-mixed") allow_mixed = true;
    else if (!a[i].empty() && a[i][0] == '-' && a[i] != "-") throw UsageError("unknown option " + a[i]);
    else if (std::filesystem::is_directory(a[i])) {
      std::vector<std::string> files;
      for (const auto& e : std::filesystem::directory_iterator(a[i]))
        if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path().string());
      std::sort(files.begin(), files.end());
      if (files.empty()) throw UsageError(a[i] + ": a folder without .json files");
      for (const std::string& f : files) add(f, true);
    } else {
      add(a[i], false);
    }
  }
  if (out.empty() || shards.empty()) throw UsageError("merge needs -o OUT.json and the shards' results files (or a folder of them)");
  std::vector<std::pair<std::string, std::string>> ins;
  for (const std::string& p : paths) ins.emplace_back("the shard", p);
  require_distinct_arguments(ins, {{"-o", out}});
  json meta = collect_metadata(argc, argv);
  // The kind of the first file merges them all (and refuses other kinds).
  const json& first = shards.front();
  const std::string schema = first.is_object() ? first.value("schema", std::string()) : std::string();
  const StudyKind* kind = study_kind_of_schema(schema);
  const json merged = kind ? kind->merge(shards, meta, paths, allow_mixed) : merge_results(shards, meta, paths, allow_mixed);
  write_file_atomically(out, merged.dump(1) + "\n");
  std::fprintf(out == "-" ? stderr : stdout, "merged %zu shards into %s\n", shards.size(), out == "-" ? "standard output" : out.c_str());
  return 0;
}

class PrintingTrace : public TraceSink {
 public:
  void record(const TraceRecord& r) override {
    std::printf("  run %d %-12s sharp (%g, %g) it %2d  |F| %.6e  step %-10s len %.4g  z = [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g]\n",
                r.run, r.run_kind ? r.run_kind : "", r.sharp1, r.sharp2, r.iteration, r.residual, r.step ? r.step : "",
                r.step_length, r.z[0], r.z[1], r.z[2], r.z[3], r.z[4], r.z[5]);
  }
};

int cmd_replay(const std::vector<std::string>& a) {
  std::string in;
  std::size_t index = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    if (a[i] == "--index") index = static_cast<std::size_t>(parse_int_option("--index", need(a, i), 0, 2000000000));
    else if (in.empty()) in = a[i];
    else throw UsageError("replay takes one failures file");
  }
  if (in.empty()) throw UsageError("replay needs a failures file");
  const json file = read_json_file(in);
  check_failures_file(file, in);
  const json& fs = file.at(key::failures);
  if (index >= fs.size())
    throw std::runtime_error(in + ": has " + std::to_string(fs.size()) + " failures, no index " + std::to_string(index));
  const json& f = fs.at(index);
  // A record made by another revision may replay differently because the code
  // changed, not by chance: say so before the answer.
  const json made = file.value("metadata", json::object());
  const auto rev_of = [](const json& m) {
    return m.is_object() && m.contains("git_revision") && m.at("git_revision").is_string() ? m.at("git_revision").get<std::string>()
                                                                                             : std::string();
  };
  const std::string record_rev = rev_of(made), binary_rev = rev_of(collect_metadata(0, nullptr));
  const bool other_revision = !record_rev.empty() && !binary_rev.empty() && record_rev != binary_rev;
  if (other_revision)
    std::printf("note: the record was made at git %s%s, this binary's checkout is at %s: a different answer may be the "
                "code's change\n",
                record_rev.substr(0, 12).c_str(), made.value("git_dirty", false) ? " (dirty)" : "", binary_rev.substr(0, 12).c_str());
  const ShapeSpec s1 = parse_shape_inline(f.at("shape1").get<std::string>(), in, "failures[" + std::to_string(index) + "].shape1");
  const ShapeSpec s2 = parse_shape_inline(f.at("shape2").get<std::string>(), in, "failures[" + std::to_string(index) + "].shape2");
  // The recorded options are checked as a scene's are: a hand-edited or
  // corrupted file (tolerance = -1) is refused, not solved with.
  SolverOptions opt;
  try {
    opt = solver_from_json(file.at("solver"));
    opt.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(in + ": solver: " + e.what());
  }
  if (f.contains("kind")) {  // an agreement record (baselines or derivatives), not a failed solve
    std::printf("replay %s --index %zu: %s-%s %s, pose k = %llu\nshape1 = %s\nshape2 = %s\npose: %s\n", in.c_str(), index,
                f.at("body1").get<std::string>().c_str(), f.at("body2").get<std::string>().c_str(),
                f.at("kind").get<std::string>().c_str(), static_cast<unsigned long long>(f.at("k").get<std::uint64_t>()),
                describe(*s1.shape).c_str(), describe(*s2.shape).c_str(), f.at("pose_text").get<std::string>().c_str());
    return replay_agreement_record(f, *s1.shape, *s2.shape, opt);
  }
  const Pose X = pose_from_json(f.at("pose"));
  if (!f.contains("status")) {  // no solve was made: the record says what failed before it
    std::printf("replay %s --index %zu: %s\nno solve recorded, nothing to replay\n", in.c_str(), index,
                f.value("problem", std::string("(no problem recorded)")).c_str());
    return 3;
  }
  const bool warm = f.contains("warm_start");
  WarmStart ws = warm ? warm_start_from_json(f.at("warm_start")) : WarmStart{};
  std::printf("replay %s --index %zu: %s-%s %s pass, pose k = %llu\n", in.c_str(), index,
              f.at("body1").get<std::string>().c_str(), f.at("body2").get<std::string>().c_str(),
              f.at("pass").get<std::string>().c_str(), static_cast<unsigned long long>(f.at("k").get<std::uint64_t>()));
  std::printf("shape1 = %s\nshape2 = %s\npose: %s\n", describe(*s1.shape).c_str(), describe(*s2.shape).c_str(),
              pose_text(X).c_str());
  if (warm) std::printf("warm start: valid %d\n", ws.valid ? 1 : 0);
  PrintingTrace tr;
  const SolveResult r = solve(*s1.shape, *s2.shape, X, opt, warm ? &ws : nullptr, &tr);
  std::printf("status %s (recorded: %s), iterations %d (recorded %d), restarts %d, continuation %d, residual %.6e, alpha %.17g\n",
              to_string(r.status), f.at("status").get<std::string>().c_str(), r.iterations, f.at(key::iterations).get<int>(),
              r.restarts, r.used_continuation ? 1 : 0, r.residual_norm, r.alpha);
  // Reproduced: the same status, alpha and x (the record's 17 digits; to
  // 1e-9 relative, so that another build's last bits still reproduce it). A
  // non-finite value is recorded as null and matches only a non-finite one.
  const auto close = [](const json& rec, double now) {
    if (rec.is_null()) return !std::isfinite(now);
    return std::isfinite(now) && std::abs(now - rec.get<double>()) <= 1e-9 * std::max(1.0, std::abs(rec.get<double>()));
  };
  std::string differs;
  if (std::string(to_string(r.status)) != f.at("status").get<std::string>()) differs += ", status";
  if (f.contains("alpha") && !close(f.at("alpha"), r.alpha)) differs += ", alpha (recorded " + f.at("alpha").dump() + ")";
  if (f.contains("x")) {
    std::printf("x %.17g %.17g %.17g (recorded %s)\n", r.x_1[0], r.x_1[1], r.x_1[2], f.at("x").dump().c_str());
    for (int i = 0; i < 3; ++i)
      if (!close(f.at("x").at(static_cast<std::size_t>(i)), r.x_1[i])) {
        differs += ", x";
        break;
      }
  }
  if (differs.empty())
    std::printf("reproduced (status, alpha%s)\n", f.contains("x") ? " and x" : "; the record has no x");
  else
    std::printf("NOT reproduced (%s differs)%s\n", differs.substr(2).c_str(),
                other_revision ? ("; the record is from git " + record_rev.substr(0, 12) + ", another revision").c_str() : "");
  return differs.empty() ? 0 : 3;
}

int cmd_compare(const std::vector<std::string>& a) {
  std::string old_path, new_path, th;
  bool all_rows = false, as_json = false;
  CompareOptions opt;
  for (std::size_t i = 1; i < a.size(); ++i) {
    if (a[i] == "--thresholds") th = need(a, i);
    else if (a[i] == "--only-changes") all_rows = false;  // the default; kept for old scripts
    else if (a[i] == "--all") all_rows = true;
    else if (a[i] == "--common-pairs") opt.common_only = true;
    else if (a[i] == "--allow-mismatch") opt.allow_mismatch = true;
    else if (a[i] == "--json") as_json = true;
    else if (!a[i].empty() && a[i][0] == '-') throw UsageError("unknown option " + a[i]);
    else if (old_path.empty()) old_path = a[i];
    else if (new_path.empty()) new_path = a[i];
    else throw UsageError("compare takes two results files");
  }
  if (new_path.empty()) throw UsageError("compare needs OLD.json and NEW.json");
  try {
    const std::string beside = std::filesystem::path(old_path).replace_filename("thresholds.toml").string();
    if (th.empty() && std::ifstream(beside)) th = beside;
    if (!th.empty()) opt.guards = load_guards(th);
    // Either file unreadable: a compare error naming the side.
    const auto read = [](const std::string& path, const char* side) {
      try {
        return read_results_file(path);
      } catch (const std::exception& e) {
        throw CompareError(side + std::string(": ") + e.what());
      }
    };
    const json o = read(old_path, "OLD");  // OLD first: it is named if both fail
    const CompareReport rep = compare_results(o, read(new_path, "NEW"), opt);
    if (as_json) {
      json j = rep.to_json();
      j["old"] = old_path;
      j["new"] = new_path;
      j["thresholds"] = th.empty() ? json(nullptr) : json(th);
      std::printf("%s\n", j.dump(1).c_str());
    } else {
      std::printf("compare OLD %s -> NEW %s, guards: the defaults%s\n%s", old_path.c_str(), new_path.c_str(),
                  th.empty() ? " (any drop in convergence or new failure fails, time per solve warns)" : (" and " + th).c_str(),
                  rep.text(all_rows).c_str());
    }
    return rep.failed ? 1 : 0;
  } catch (const std::exception& e) {
    // Every error here is bad input (exit 2), never a regression (exit 1).
    std::fprintf(stderr, "idcol_harness compare: %s\n", e.what());
    if (as_json) {
      json j = {{"verdict", "ERROR"}, {"exit_code", 2}, {"error", e.what()}, {"old", old_path}, {"new", new_path}};
      if (const auto* m = dynamic_cast<const CompareMismatch*>(&e)) j["mismatches"] = m->fields;
      std::printf("%s\n", j.dump(1).c_str());
    }
    return 2;
  }
}

/// Validates a scene and prints its cost, of the whole scene or of the run
/// that the options given describe (a shard, a cut).
int cmd_check(const std::vector<std::string>& a) {
  std::string scene_path;
  StudyOptions opt;
  std::vector<std::string> given;
  for (std::size_t i = 1; i < a.size(); ++i) {
    const std::string& f = a[i];
    if (f.empty() || f[0] != '-') {
      if (!scene_path.empty()) throw UsageError("check takes one scene file");
      scene_path = f;
      continue;
    }
    given.push_back(f);
    if (!parse_cost_option(a, i, opt))
      throw UsageError("unknown option " + f + " (check takes the options that change a run's cost: --shard, --threads, "
                       "--max-poses, --oracle-every, --poses)");
  }
  if (scene_path.empty()) throw UsageError("check takes one scene file");
  const std::unique_ptr<Study> study = load_study(scene_path);
  require_flags_apply(*study, given);
  if (study->kind().prints_scene()) std::cout << study->kind().scene_text(load_scene(scene_path));
  const std::string shard = opt.shard_count > 1 ? format("shard %d/%d: ", opt.shard_index, opt.shard_count) : "";
  std::printf("# %s: a valid %s scene; %s%s\n", scene_path.c_str(), study->kind().name, shard.c_str(), cost_line(*study, opt).c_str());
  return 0;
}

int cmd_shapes(const std::vector<std::string>& a) {
  if (a.size() != 1) throw UsageError("shapes takes no arguments");
  std::printf("Shape families (a scene's [shapes] table: NAME = { family = \"...\", ... }):\n");
  for (const FamilyDoc& f : scene_families()) {
    std::printf("\n%s: %s\n  axes     %s\n", f.family.c_str(), f.summary.c_str(), f.axes.c_str());
    for (const idcol::FamilyParam& p : f.params) std::printf("  %-8s %s\n", p.key, p.meaning);
    std::printf("  e.g. %s\n", f.example.c_str());
  }
  return 0;
}

/// The declared metrics of every kind, or of one (studies/metric_list.hpp).
int cmd_metrics(const std::vector<std::string>& a) {
  std::string as, only;
  for (std::size_t i = 1; i < a.size(); ++i) {
    if (a[i] == "--json" || a[i] == "--keys") as = a[i];
    else if (only.empty() && study_kind_named(a[i])) only = a[i];
    else throw UsageError("metrics: unknown argument " + a[i]);
  }
  json all = json::array();
  std::set<std::string> keys;
  for (const StudyKind& k : study_kinds()) {
    if (!only.empty() && only != k.name) continue;
    if (as.empty()) std::fputs((metrics_text(k) + "\n").c_str(), stdout);
    for (json& m : metrics_listing(k)) {
      // The counts of work (key::kCountsOfWork) are common words used in other senses too: not listed.
      const std::string key_name = m.at("key").get<std::string>();
      if (std::none_of(key::kCountsOfWork.begin(), key::kCountsOfWork.end(), [&](const char* w) { return key_name == w; }))
        keys.insert(key_name);
      all.push_back(std::move(m));
    }
  }
  if (as == "--json") std::cout << all.dump(1) << "\n";
  if (as == "--keys")
    for (const std::string& k : keys) std::printf("%s\n", k.c_str());
  return 0;
}

/// A few lines on any JSON file of the harness: what it is, when, where and
/// by which build it was made, and its headline figures. Every line is
/// printed escaped (io/text.hpp: escaped), as each kind's info() prints
/// the names it shows: the names in a file, which may have been edited by
/// hand, can neither break a line nor send a terminal control sequences.
int cmd_info(const std::vector<std::string>& a) {
  if (a.size() != 2) throw UsageError("info takes one file");
  const json r = read_json_file(a[1]);
  if (!r.is_object() || !r.contains("schema"))
    throw std::runtime_error(escaped(a[1]) + ": not a file of the harness (it has no \"schema\")");
  const std::string schema = member(r, "schema", JsonType::String, JsonAt(a[1])).get<std::string>();
  if (study_kind_of_schema(schema)) check_results(r, a[1]);
  if (schema == kFailuresSchema) check_failures_file(r, a[1]);
  const json meta = r.value("metadata", json::object());
  auto str = [](const json& j, const char* k) {
    return j.is_object() && j.contains(k) && !j.at(k).is_null() ? (j.at(k).is_string() ? j.at(k).get<std::string>() : j.at(k).dump())
                                                                : std::string("?");
  };
  const json scene = r.value("scene", json::object());
  std::vector<std::string> lines;
  lines.push_back(a[1] + ": " + schema + ", scene \"" + str(scene, "name") + "\" (" + str(scene, "path") + ")");
  lines.push_back(format("made %s on %s (%s), git %s%s, %s %s", str(meta, "date_utc").c_str(), str(meta, "host").c_str(),
                         str(meta, "cpu_model").c_str(), str(meta, "git_revision").substr(0, 12).c_str(),
                         meta.value("git_dirty", false) ? " (dirty)" : "", str(meta, "compiler").c_str(), str(meta, "build_type").c_str()));
  std::string figures;
  if (const StudyKind* k = study_kind_of_schema(schema)) {
    figures = k->info(r);
  } else if (schema == kFailuresSchema) {
    std::map<std::string, std::size_t> by;
    for (const json& f : r.at(key::failures)) by[f.value("problem", f.value("status", std::string("?")))]++;
    figures = format("failures: %zu records\n", r.at(key::failures).size());
    for (const auto& [what, count] : by) figures += format("  %6zu  ", count) + escaped(what) + "\n";
    figures += "replay one: " + escaped(harness_command() + " replay " + a[1]) + " --index I\n";
  }
  for (const std::string& l : lines) std::printf("%s\n", escaped(l).c_str());
  std::fputs(figures.c_str(), stdout);  // each kind's info() escapes the names it prints
  return 0;
}

/// The path this executable was run from, relative to the working directory
/// when beneath it: what replay commands in failure records name.
std::string own_command(const char* argv0) {
  std::error_code ec;
  std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return argv0 ? argv0 : "idcol_harness";
  const std::filesystem::path cwd = std::filesystem::current_path(ec);
  if (!ec) {
    const std::filesystem::path rel = exe.lexically_relative(cwd);
    if (!rel.empty() && *rel.begin() != "..") return rel.string();
  }
  return exe.string();
}

/// The command line, its exit status; main() adds the check of standard output.
int run_command_line(int argc, char** argv) {
  std::vector<std::string> a(argv + 1, argv + argc);
  if (a.empty() || a[0] == "-h" || a[0] == "--help" || a[0] == "help") {
    std::fputs(usage().c_str(), a.empty() ? stderr : stdout);
    return a.empty() ? 2 : 0;
  }
  if (a[0] == "--version" || a[0] == "version") {
    std::fputs(version_text().c_str(), stdout);
    return 0;
  }
  if (a.size() >= 2 && (std::find(a.begin() + 1, a.end(), "--help") != a.end() || std::find(a.begin() + 1, a.end(), "-h") != a.end())) {
    if (const CommandHelp* h = command_help(a[0])) {
      std::fputs(help_text(*h).c_str(), stdout);
      return 0;
    }
  }
  set_harness_command(own_command(argv[0]));
  try {
    if (a[0] == "run") return cmd_run(a, argc, argv, "");
    // `run` for one kind only: a kind whose name is a command (a row of kCommands).
    if (a[0] != "run" && command_help(a[0]) && study_kind_named(a[0])) return cmd_run(a, argc, argv, a[0]);
    if (a[0] == "table" || a[0] == "stress-table") return cmd_table(a);
    if (a[0] == "merge") return cmd_merge(a, argc, argv);
    if (a[0] == "replay") return cmd_replay(a);
    if (a[0] == "check") return cmd_check(a);
    if (a[0] == "compare") return cmd_compare(a);
    if (a[0] == "shapes") return cmd_shapes(a);
    if (a[0] == "metrics") return cmd_metrics(a);
    if (a[0] == "info") return cmd_info(a);
    if (a[0] == "history") return cmd_history(a);
    throw UsageError("unknown command " + a[0]);
  } catch (const UsageError& e) {
    // One line: what is wrong, and where the reference is (not the whole usage).
    const bool known = command_help(a[0]) != nullptr;
    std::fprintf(stderr, "idcol_harness%s: %s (see idcol_harness %s--help)\n", known ? (" " + a[0]).c_str() : "", e.what(),
                 known ? (a[0] + " ").c_str() : "");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "idcol_harness: %s\n", e.what());
    return 1;
  }
}

}  // namespace

/// A table, an info or a comparison that could not be written (standard
/// output a full disk, a closed pipe) is an error, not a silent success: the
/// stream's error flag is read after the last flush.
int main(int argc, char** argv) {
  const int rc = run_command_line(argc, argv);
  errno = 0;
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
    std::fprintf(stderr, "idcol_harness: cannot write standard output%s%s\n", errno ? ": " : "", errno ? std::strerror(errno) : "");
    // compare's 1 means a regression; its errors are 2.
    return rc != 0 ? rc : (argc > 1 && std::strcmp(argv[1], "compare") == 0 ? 2 : 1);
  }
  return rc;
}
