// The declared metrics of a results file: each figure that `compare` reads,
// with its unit, which direction is better, its default guard, how shards
// merge it, and whether it is timing (varies from run to run, so it is not
// expected to match between a merge and the single run). Each study kind
// declares its table once (studies/<kind>/<kind>_metrics.cpp); compare's
// metric names, its default guards and the list of names a thresholds file
// may guard are all read off the tables, so a metric is named in one place.
//
// A table is a list of groups. A group is a JSON object of each entry of the
// results file (a sweep pair, a stress case, a smoothing grid point), found
// at a dotted path whose last component may be "*" (each member of that
// object: each pass, each method), and the metrics read from it; the
// metric's full name is the group's prefix, with {key} replaced by the
// member's name, followed by the metric's name (cold. + convergence_rate: cold.convergence_rate).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace idcol::harness {

enum class Better { Higher, Lower, Neither };

/// How the shards of one run combine into the figure of the whole run.
enum class MergeRule {
  Sum,       // counts: the sum over shards
  Max,       // worst values: the largest over shards
  Ratio,     // a rate or mean recomputed from the merged counts or sums
  Quantile,  // read from the merged fixed-binned histogram
  Same,      // a property of the scene, not of the poses: equal in every shard
};

/// The guard compare applies when no thresholds file is given. Info: shown,
/// never a verdict. Warn: beyond the tolerance a WARN. Fail: beyond it a FAIL.
struct DefaultGuard {
  enum Level { Info, Warn, Fail } level = Info;
  double abs = 0.0, rel = 0.0;
};
constexpr DefaultGuard kInfo{};
constexpr DefaultGuard kExact{DefaultGuard::Fail, 0.0, 0.0};

struct Metric {
  const char* name;  // after the group's prefix, e.g. key::convergence_rate (io/keys.hpp), "time.median_us"
  const char* path;  // where it lies in the group's object (dotted); "" when the same as name
  const char* unit;  // "fraction" (of solves or poses: compare shows its change in points), "count", "us", "rad", "1" (a ratio)
  Better better;
  MergeRule merge;
  DefaultGuard guard = kInfo;
  bool timing = false;       // wall-clock figure: differs between runs of the same scene
  double scale = 1.0;        // compare reads the JSON value times this (ns -> us: 1e-3)
  const char* needs = nullptr;  // read only where the object has this member (a record the scene asked for)
};

struct MetricGroup {
  const char* where;   // dotted path from the entry; last component "*" for each member
  const char* prefix;  // "{key}." with where = "passes.*"; "derivatives." ...
  std::vector<Metric> metrics;
  /// Timing ratios: each member's metric divided by this member's (which is
  /// not reported itself); the group is skipped where it is missing.
  const char* ratio_to = nullptr;
};

struct MetricTable {
  std::vector<MetricGroup> groups;
  /// An entry whose member of this name is false was not run (a grid value
  /// the family rejects): it has no metrics.
  const char* valid_key = nullptr;
};

/// The member at a dotted path ("time.all.median_ns"); nullptr where any
/// step is missing.
const nlohmann::json* at_path(const nlohmann::json& j, const std::string& path);

/// The number at a dotted path; NaN where any step is missing or the value
/// is not a number (null: the writer had no finite value).
double number_at(const nlohmann::json& j, const std::string& path);

/// Every metric of one entry of a results file, by its full name, in the
/// table's order; NaN where the file has no number at the path.
std::vector<std::pair<std::string, double>> entry_metrics(const MetricTable& t, const nlohmann::json& entry);

/// Each declared metric's value as an entry holds it, with the metric and
/// its JSON path in the entry ("passes.cold.failures"): what a reader
/// checks before it reads the figures. Values absent from the entry are
/// skipped (compare names a figure that vanished), as are the entries that
/// were not run (valid_key false).
void for_each_metric_value(const MetricTable& t, const nlohmann::json& entry,
                           const std::function<void(const Metric&, const std::string&, const nlohmann::json&)>& f);

/// Whether `v` is a value of `m` as its declaration says: null (no figure,
/// which compare fails where OLD had one; a NaN in a results file not yet
/// written, which is written as null), or a number; a count (unit
/// "count") an integer in [0, 2^64), unless it is merged as a ratio (a mean
/// count, such as solves per query: then a number >= 0); a fraction (unit
/// "fraction") a number in [0, 1]. With `as_double`, the value was written
/// as a double (a history line holds every figure so): a count is then a
/// whole number in [0, 2^64), whether written 3 or 3.0.
bool metric_value_ok(const Metric& m, const nlohmann::json& v, bool as_double = false);
/// What metric_value_ok takes for `m`, in the words of errors.
std::string metric_value_expected(const Metric& m);

/// The declaration behind a full metric name ("cold.time.median_us"), or
/// nullptr: the declared metric whose group prefix and name match it.
const Metric* find_metric(const MetricTable& t, const std::string& full_name);

}  // namespace idcol::harness
