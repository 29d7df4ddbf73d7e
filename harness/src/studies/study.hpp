// Passes behind one interface. A scene file says what it runs by its
// tables: [[case]] makes it a stress suite (stress.hpp: every answer checked
// by checks.hpp), [grid] a smoothing grid (smoothing.hpp), [toi] a
// time-of-impact study (toi.hpp), anything else a sweep (sweep.hpp: the cold
// and warm passes over pairs, and the agreement and derivative passes it
// records). load_study reads any of them; a Study runs its passes over a
// shard into a RecordSink and returns the results file (record.hpp), so one
// command line runs, writes and summarises all of them. study_kinds() is the
// one table of these kinds (studies/kinds.def, one row per kind): a new kind
// of study is its own folder under studies/ with its StudyKind (a class
// whose names and functions the compiler sees filled, its scene section and
// that section's reader among them), its spec type and reader
// (<kind>_spec.hpp, <kind>_scene.cpp) and its sources.cmake, and one row in
// that table.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "io/record.hpp"
#include "studies/metric.hpp"

namespace idcol::harness {

/// Where a pass leaves its failure records: numbered as they come, each with
/// the command that replays it from failures_path.
struct RecordSink {
  std::string failures_path;
  nlohmann::json failures = nlohmann::json::array();
  void add(nlohmann::json records) { append_failures(failures, std::move(records), failures_path); }
};

/// The options of a run, as the command line gives them and each study's
/// runner (run_scene, run_stress, run_smoothing) takes them. A study takes
/// those in its flags() and the command line rejects the others.
struct StudyOptions {
  int shard_index = 0, shard_count = 1;     // --shard i/N (sweep: poses; stress: cases; smoothing: grid values)
  /// --threads (0: the study's default; a runner given 0 runs one). A sweep
  /// runs more only when it records neither timing nor per_pose, each thread
  /// taking whole warm-start chains: results are those of one thread.
  int threads = 0;
  int pin = -1;                             // --pin CPU
  bool progress = false;                    // progress on stderr (the caller checks it is a TTY)
  /// --max-traced-failures (sweep): failure records beyond this many carry no
  /// trace (replay regenerates it).
  std::size_t max_traced_failures = kDefaultTracedFailures;
  std::size_t max_failures = 2000;          // --max-failures (stress: records kept per case and pass, lowest k first)
  std::uint64_t max_poses = 0;              // --max-poses (stress: each case's first N poses)
  std::uint64_t oracle_every = 0;           // --oracle-every (stress: the oracle on every K-th pose; 0: the scene's)
  std::uint64_t poses = 0;                  // --poses (smoothing: the sweep's length)
  std::FILE* per_pose = nullptr;            // --per-pose CSV (sweep)
  std::string failures_path;                // named in each failure record's replay command
};

struct Scene;   // scene/scene.hpp
class Reader;   // scene/scene_toml.hpp
class Study;

/// One part of a run's estimated wall time: what it is and its seconds.
struct CostPart {
  std::string name;
  double seconds = 0.0;
};

/// One kind of study, as every part of the harness that is not the study
/// itself needs to know it: the scene reader, `run`, `table`, `info`,
/// `metrics`, `merge` and `compare`. A kind derives from it in its folder
/// (studies/<kind>/), sets each name below by name in its constructor and
/// defines each function; the registry (studies/registry.cpp) holds one
/// object of each kind, a row of studies/kinds.def, and checks that every
/// name is set.
class StudyKind {
 public:
  virtual ~StudyKind() = default;

  const char* name = nullptr;    // "sweep", "stress", "smoothing", "toi": the scene's kind (Scene::kind), and the command that runs only it
  /// The table whose presence makes a scene file this kind ("case", "grid",
  /// "toi"); nullptr for the one kind that takes a file with none of the
  /// others' (the sweep).
  const char* section = nullptr;
  const char* noun = nullptr;    // in messages: "a <noun> results file"
  const char* schema = nullptr;  // of its results files (record.hpp)
  int default_threads = 1;       // --threads when not given
  bool pin_whole_run = false;    // --pin pins the whole run (else the study pins what it times)
  /// Where the tables and figures of a kind without has_table() come from.
  const char* tables_from = nullptr;
  /// What its scene is, for the commands' --help: "a stress suite ([[case]]
  /// tables)"; and the options `run` takes for it beyond -o, --failures,
  /// --no-progress and --shard, and what a shard of it is, in lines of at
  /// most 100 characters.
  const char* scene_is = nullptr;
  const char* run_options = nullptr;
  /// compare: the results file's array of entries (`entries`, each an
  /// `entry_word`), and an entry holding every declared metric, as JSON
  /// text (made by full_entry_of, studies/metric_list.hpp: the names a guard
  /// may match).
  const char* entries = nullptr;
  const char* entry_word = nullptr;
  std::string full_entry;
  /// The members every results file of the kind has besides the header
  /// (io/record.hpp: check_header), at its top and in each entry, with
  /// their types: a file without one, or with one of another type, is
  /// refused by every reader (studies/results_file.hpp).
  struct Member {
    const char* name;
    JsonType type;
  };
  std::vector<Member> top_members, entry_members;
  /// compare: what makes two runs of the kind the same run, the top-level
  /// fields and the fields of each entry that say what was solved (scene,
  /// shapes, poses, solver options: dotted paths, an object compared member
  /// by member), and the fields that files made before them lack, with the
  /// value they had then (a sweep's timing.path: every earlier sweep was
  /// timed through the loop). Which shard a file holds, or which shards a
  /// merge came from, is not among them: merged shards are the single run
  /// (compare names the entries a shard lacks).
  struct RunIdentity {
    std::vector<const char*> top, entry;
    std::map<std::string, std::string> absent_means = {};
  };
  RunIdentity identity;

  /// Reads the scene's name and the sections of its kind into `s` (its
  /// KindSpec among them), after parse_scene has read the description and
  /// [solver], through `top`, the file's top-level table (which then refuses
  /// every key no reader asked for).
  virtual void read_scene(Reader& top, const std::string& file, Scene& s) const = 0;
  /// The study of a scene of this kind (a SceneError where this build cannot run it).
  virtual std::unique_ptr<Study> make(Scene s) const = 0;
  /// The scene as read, which `check` prints, where prints_scene().
  virtual bool prints_scene() const { return false; }
  virtual std::string scene_text(const Scene&) const {
    throw std::logic_error(std::string(name) + ": a kind whose scenes `check` does not print");
  }
  /// The Markdown report of a results file, where has_table(); else
  /// `tables_from` says where its tables come from.
  virtual bool has_table() const { return false; }
  virtual std::string table(const nlohmann::json&, const std::string&) const {
    throw std::logic_error(std::string(name) + ": no Markdown table; its tables come from " + (tables_from ? tables_from : "its folder"));
  }
  /// The lines `info` prints on a results file, after its header.
  virtual std::string info(const nlohmann::json& results) const = 0;
  /// compare: each entry's key, and the declared metrics of an entry
  /// (studies/metric.hpp).
  virtual std::string entry_key(const nlohmann::json& results, const nlohmann::json& entry) const = 0;
  virtual const MetricTable& metrics() const = 0;
  /// merge: the shards 0..N-1 of one scene of this kind into the results of
  /// the whole run (names: the inputs' paths, for errors; allow_mixed:
  /// shards of different builds, where the kind refuses them).
  virtual nlohmann::json merge(const std::vector<nlohmann::json>& shards, const nlohmann::json& metadata,
                               const std::vector<std::string>& names, bool allow_mixed) const = 0;
};

/// Every kind of study, in the registry's order (each converts to a
/// const StudyKind&).
const std::vector<std::reference_wrapper<const StudyKind>>& study_kinds();
/// The kind whose results files have this schema; nullptr if none.
const StudyKind* study_kind_of_schema(const std::string& schema);
/// The kind named so (a scene kind's name), or nullptr.
const StudyKind* study_kind_named(const std::string& name);

class Study {
 public:
  virtual ~Study() = default;
  virtual const StudyKind& kind() const = 0;
  virtual const SceneText& scene() const = 0;
  virtual const SolverOptions& solver() const = 0;
  /// The command-line flags it takes besides -o, --failures and --no-progress.
  virtual std::vector<std::string> flags() const = 0;
  /// Whether it writes a failures file / a per-pose CSV.
  virtual bool records_failures() const { return true; }
  virtual bool records_per_pose() const { return false; }
  /// Runs every pass over the shard; failure records go to `sink`. Throws
  /// Interrupted (exec/chains.hpp) when interrupt_flag() is raised.
  virtual nlohmann::json run(const StudyOptions& opt, const nlohmann::json& metadata, RecordSink& sink) = 0;
  /// A few lines for the terminal, from the results file.
  virtual std::string summary(const nlohmann::json& results) const = 0;
  /// What a run with `opt` costs: its solves (pairs or cases x passes x
  /// poses), and a rough estimate of its wall time on this machine class
  /// with opt.threads (0: the kind's default), in named parts ("solves",
  /// "oracles", "baselines", ...) from the per-query constants of
  /// studies/cost_model.hpp. Parts that cost nothing are left out.
  /// A count past 2^64 - 1 is kCountSaturated (count_product, count_sum),
  /// never a wrapped one.
  virtual std::uint64_t solves(const StudyOptions& opt) const = 0;
  virtual std::vector<CostPart> estimate(const StudyOptions& opt) const = 0;
  /// The sum of estimate()'s parts, in seconds.
  double estimated_seconds(const StudyOptions& opt) const {
    double t = 0.0;
    for (const CostPart& p : estimate(opt)) t += p.seconds;
    return t;
  }
};

/// What a count of work that a scene asks for reads when it is 2^64 - 1 or
/// more (2^63 poses of 500,500 pairs in two passes): the largest count,
/// printed as "more than" it, never a product wrapped modulo 2^64.
inline constexpr std::uint64_t kCountSaturated = UINT64_MAX;
/// a * b and a + b of counts, saturating at kCountSaturated.
inline std::uint64_t count_product(std::uint64_t a, std::uint64_t b) {
  std::uint64_t p = 0;
  return __builtin_mul_overflow(a, b, &p) ? kCountSaturated : p;
}
inline std::uint64_t count_sum(std::uint64_t a, std::uint64_t b) {
  std::uint64_t s = 0;
  return __builtin_add_overflow(a, b, &s) ? kCountSaturated : s;
}

/// Parses a scene of any kind from TOML text: the first kind of
/// study_kinds() whose section the file has (a [[case]] makes it a stress
/// scene, a [grid] a smoothing grid), else the kind without one, reads it.
/// `file` names it in error messages, which read "<file>: <field>: <what
/// was expected>".
Scene parse_scene(const std::string& text, const std::string& file);
/// Reads and parses a scene file.
Scene load_scene(const std::string& path);

/// Reads a scene of any kind; `kind` ("sweep", "stress", "smoothing", "toi"),
/// when given, is what the caller expects, and a file of another kind is a
/// SceneError.
std::unique_ptr<Study> load_study(const std::string& path, const std::string& kind = "");

/// "cost: 40000 solves, roughly 12 s on 1 core (solves ~0.1 s, oracles ~9 s,
/// baselines ~2.5 s; ...)": the line `check` prints, and `run` before a long run.
std::string cost_line(const Study& s, const StudyOptions& opt);

}  // namespace idcol::harness
