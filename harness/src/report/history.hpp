// The history of a scene's results over commits (after asv's published
// benchmark pages): `history add` turns a results file into one line of a
// JSON Lines file, `history show` prints the trend of each metric as a
// table or writes one static HTML page of SVG plots, with each step beyond
// the metric's guard marked at the first commit after which it stays.
//
// A line holds, with its keys in sorted order (so that a history merges well
// in git): the scene's identity and its series key, the run's machine, build
// and revision from the results file's metadata, the guards that applied,
// and per entry (pair, stress case, smoothing grid point) every metric a
// guard matches, read off the study kind's declared metric table
// (studies/metric.hpp). Instructions per solve, counted under callgrind by
// scripts/callgrind_instructions.sh, join the entries where given.
//
// Runs whose scenes cannot be compared (another scene text, other poses,
// another cut of them) have different series keys and are never plotted
// together. A run's place on the commit axis is the place of its revision's
// first line in the file: add runs in commit order.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "report/compare.hpp"

namespace idcol::harness {

constexpr const char* kHistorySchema = "idcol-harness-history";
constexpr const char* kInstructionsSchema = "idcol-instructions";

/// A malformed history, results or instructions file, or a bad filter.
struct HistoryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What two runs must share to be compared: the study kind, the scene's
/// name, a hash of its text without comments and blank lines (its shapes,
/// pairs or cases, poses and [solver] settings), the run's settings as the
/// results file records them (the sweep's poses, a stress cut, a smoothing
/// grid's poses; without the build's solver defaults, which are what the
/// history tracks), the shard when the file holds one of several, and the
/// entries' keys. Throws HistoryError when `results` is not a results file
/// of the harness.
nlohmann::json scene_identity(const nlohmann::json& results);

/// The series a run belongs to: "<kind>:<scene name>:<12 hex digits of a
/// hash of scene_identity>". Runs of one series are comparable.
std::string series_key(const nlohmann::json& identity);

/// The machine a run was made on, as the history separates series within a
/// plot: host, CPU, compiler, build type and flags.
std::string machine_label(const nlohmann::json& metadata);

/// The default guard of instructions per solve: callgrind counts are
/// deterministic for one build, so 1% is a change of the code.
Guard instructions_guard();

/// One history line (an object) for a results file: every metric of every
/// entry that one of `guards` matches (the first match applies, as in
/// compare), with those guards; `instructions` (an idcol-instructions
/// object, or null) adds "cold.instructions_per_solve" and
/// "warm.instructions_per_solve" to the entries of its pairs.
nlohmann::json history_record(const nlohmann::json& results, const std::vector<Guard>& guards,
                              const nlohmann::json& instructions, const std::string& source);

/// The line as written: one line, keys sorted, numbers round-tripping.
std::string history_line(const nlohmann::json& record);

/// The lines of a history file (none when it does not exist); throws
/// HistoryError naming the file and line of a malformed one.
std::vector<nlohmann::json> read_history(const std::string& path);

/// Appends `record` to the history file (atomically: the file is rewritten
/// whole). Throws HistoryError when the same run (series, revision, machine
/// and date) is already there.
void append_history(const std::string& path, const nlohmann::json& record);

/// Which metrics and entries `show` keeps: fnmatch globs, "" for all.
struct HistoryFilter {
  std::string metric, pair;
};

/// A step of one metric of one entry on one machine: from the commit at
/// `index` on, every value lies beyond the guard around the value before it,
/// on the same side, and that value was a level, not a one-commit spike.
/// A change undone later is not a step (it did not stay); its undoing is.
struct HistoryStep {
  std::size_t index;          // into the series' commits
  double before, after;       // the last value before the step, the first at it
  bool better;                // in the guard's better direction
};

/// The steps of a sequence of values (NaN: no value at that commit) under a
/// guard.
std::vector<HistoryStep> find_steps(const std::vector<double>& values, const Guard& g);

/// The terminal table: per series, per entry and metric, a row per machine
/// with its value at each commit and the steps.
std::string history_table(const std::vector<nlohmann::json>& records, const HistoryFilter& f);

/// The static page: per series, a table of the steps and one SVG plot per
/// metric and entry over the commits, one line per machine. Nothing is
/// fetched and there is no script. `plots` (if given) receives the number
/// of plots drawn.
std::string history_html(const std::vector<nlohmann::json>& records, const HistoryFilter& f, std::size_t* plots = nullptr);

}  // namespace idcol::harness
