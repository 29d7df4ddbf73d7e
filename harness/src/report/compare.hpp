// Comparing two results files (after google/benchmark's tools/compare.py):
// per pair and metric, old, new, change and a verdict from the guards of a
// thresholds file. See results/baseline/thresholds.toml for the format.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace idcol::harness {

/// One guard: metrics whose name matches `pattern` (fnmatch glob, e.g.
/// "*.convergence_rate", "baselines.*.genuine") worsen beyond
/// max(abs, rel |old|) in the direction opposite to `better` -> verdict FAIL
/// (or WARN when fail = false). The first matching guard applies.
struct Guard {
  std::string pattern;
  bool higher_is_better = false;
  double abs = 0.0, rel = 0.0;
  bool fail = true;
  std::string origin;  // where it was defined ("T.toml: guard[3]"), for errors
};

/// The guards compare applies without a thresholds file: any drop in
/// convergence (sweep convergence_rate, stress genuine_rate, smoothing
/// converged_fraction) and any new failed solve or false convergence fails.
std::vector<Guard> default_guards();

/// A malformed input to compare (corrupt file, missing pair, bad thresholds).
struct CompareError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Reads a thresholds TOML file ([[guard]] entries); throws CompareError.
std::vector<Guard> load_guards(const std::string& path);


struct CompareRow {
  std::string pair, metric;  // pair: the pair, stress case or smoothing point compared
  std::string unit;          // the metric's declared unit (study/metric.hpp)
  double old_value = 0.0, new_value = 0.0;
  std::string verdict;  // FAIL, WARN, worse, better, same, info, missing
  bool guarded = false;  // a guard matched the metric
};

struct CompareReport {
  std::vector<CompareRow> rows;
  int failed = 0, warned = 0;
  std::vector<std::string> notes;  // e.g. the sweeps differ
  /// The tables, one per pair, and a summary line with the number of metrics
  /// compared; without all_rows only the rows whose verdict is not "same".
  std::string text(bool all_rows = false) const;
};

/// Compares two results files of the same kind (sweep, stress or smoothing
/// study) entry by entry. Throws CompareError if either file is not a results
/// file, the kinds differ, an entry of one is missing from the other (unless
/// `common_only`: then only the shared entries are compared, and the others
/// named in the notes), or a guard matches no metric of these files nor any
/// metric name compare knows (a typo such as "*.convergance_rate" would
/// otherwise guard nothing).
CompareReport compare_results(const nlohmann::json& old_results, const nlohmann::json& new_results,
                              const std::vector<Guard>& guards, bool common_only = false);

}  // namespace idcol::harness
