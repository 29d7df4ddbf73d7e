// Comparing two results files (after google/benchmark's tools/compare.py):
// per pair and metric, old, new, change and a verdict from the guards.
//
// What compare will not be fooled by:
//  - two runs of different things (scene, shapes, pose set or count, solver
//    options, study kind) are refused, naming only the fields that differ
//    (CompareMismatch), unless the caller allows the mismatch: then the
//    fields head the report;
//  - a thresholds file only adds guards to the declared defaults
//    (studies/metric.hpp) or tightens them; it replaces a default only where a
//    guard says `replace = true`;
//  - a guarded metric, or any count, that OLD has and NEW lacks (missing,
//    null, NaN) fails, so a figure cannot pass by vanishing;
//  - a file that is not a valid results file is bad input (CompareError),
//    not a regression: a member every such file has removed, a count below
//    0, a rate outside [0, 1], an entry listed twice, a schema version
//    other than the one this harness reads (studies/results_file.hpp, the
//    check every reader of a results file makes).
// See results/baseline/thresholds.toml and harness/README.md for the format.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace idcol::harness {

/// One guard: metrics whose name matches `pattern` (fnmatch glob, e.g.
/// "*.convergence_rate", "baselines.*.genuine") worsen beyond
/// max(abs, rel |old|) in the direction opposite to `better` (any change,
/// either way, with `same`) -> verdict FAIL (or WARN when fail = false).
/// Of a list of guards, the first that matches a metric applies.
struct Guard {
  std::string pattern;
  bool higher_is_better = false;
  bool same = false;  // a change either way worsens (a count of queries or poses, fixed by the scene)
  double abs = 0.0, rel = 0.0;
  bool fail = true;
  /// A thresholds file's guard that takes the place of the default guard of
  /// the metrics it matches, instead of applying with it.
  bool replace = false;
  std::string origin;  // where it was defined ("T.toml: guard[3]", "default guard"), for errors
};

/// The declared default guards (studies/metric.hpp), one per guarded metric
/// name: any drop in convergence, any new failed solve, false convergence
/// or disagreement fails, and the worst errors may not grow past their
/// declared tolerance; time per solve only warns.
std::vector<Guard> default_guards();

/// A malformed input to compare (corrupt file, missing pair or member, bad
/// thresholds): exit 2.
struct CompareError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// OLD and NEW are runs of different things: `fields` lists each field that
/// differs ("solver.max_iterations: OLD 25, NEW 50"), and only those.
struct CompareMismatch : CompareError {
  CompareMismatch(const std::string& what, std::vector<std::string> f) : CompareError(what), fields(std::move(f)) {}
  std::vector<std::string> fields;
};

/// Reads a thresholds TOML file ([[guard]] entries); throws CompareError.
std::vector<Guard> load_guards(const std::string& path);

/// The guards compare applies with a thresholds file's `guards`: those
/// first, then the declared defaults (a file adds to them; it does not
/// take their place). What `history add --thresholds` records.
std::vector<Guard> guards_in_force(const std::vector<Guard>& file_guards);

struct CompareRow {
  std::string pair, metric;  // pair: the pair, stress case or smoothing point compared
  std::string unit;          // the metric's declared unit (studies/metric.hpp)
  double old_value = 0.0, new_value = 0.0;
  std::string verdict;  // FAIL, WARN, worse, better, same, info, missing, new
  bool guarded = false;  // a guard matched the metric
  std::string guards;    // the guards applied, as "default guard", "T.toml: guard[2]"
};

struct CompareOptions {
  /// Guards of a thresholds file: added to the declared defaults (or, with
  /// replace = true, taking their place for the metrics they match).
  std::vector<Guard> guards;
  /// The declared default guards apply (false only for tests of one guard).
  bool defaults = true;
  /// Compare only the pairs (cases, points) both files hold, naming the others.
  bool common_only = false;
  /// Compare runs of different scenes, shapes, pose sets or solver options:
  /// the fields that differ head the report instead of refusing.
  bool allow_mismatch = false;
};

struct CompareReport {
  std::vector<CompareRow> rows;
  int failed = 0, warned = 0;
  /// The fields in which the runs differ (compared with allow_mismatch).
  std::vector<std::string> mismatches;
  std::vector<std::string> notes;  // e.g. a loose guard, an entry only one file holds
  /// Which file is which: "OLD" and "NEW" with their date and git revision.
  std::string old_made, new_made;
  /// The tables, one per pair, and a summary line with the number of metrics
  /// compared; without all_rows only the rows whose verdict is not "same".
  std::string text(bool all_rows = false) const;
  /// The report as JSON: verdict, counts, mismatches, notes and every row.
  nlohmann::json to_json() const;
};

/// Compares two results files of the same kind (sweep, stress, smoothing or
/// time-of-impact study) entry by entry. Throws CompareMismatch if the runs
/// differ in what they ran (unless options.allow_mismatch), CompareError if
/// either file is not a valid results file (check_results, naming "OLD" or
/// "NEW", the field and the value),
/// an entry of one is missing from the other (unless common_only: then only
/// the shared entries are compared, and the others named in the notes), or
/// a guard matches no metric of these files nor any metric name compare
/// knows (a typo such as "*.convergance_rate" would otherwise guard nothing).
CompareReport compare_results(const nlohmann::json& old_results, const nlohmann::json& new_results,
                              const CompareOptions& options);

/// compare_results with the guards of a thresholds file added to the defaults.
CompareReport compare_results(const nlohmann::json& old_results, const nlohmann::json& new_results,
                              const std::vector<Guard>& guards, bool common_only = false);

/// The fields in which two results files of the same kind differ in what
/// they ran, each once ("solver.tolerance: OLD 1e-10, NEW 1e-08"; a field of
/// many entries once, with the entries it differs in); empty if none.
std::vector<std::string> run_mismatches(const nlohmann::json& old_results, const nlohmann::json& new_results);

}  // namespace idcol::harness
