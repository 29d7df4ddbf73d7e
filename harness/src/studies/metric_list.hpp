// What is read off a kind's declared metrics (studies/metric.hpp) besides the
// figures of a results file: the entry compare takes the names a guard may
// match from, the key that names each metric in the results file, and the
// listing `idcol_harness metrics` prints (which the plot scripts and the
// test harness.metric_names read).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "studies/metric.hpp"

namespace idcol::harness {

class StudyKind;

/// An entry of a results file that holds every metric of the table (each
/// value 0, each record a metric needs present): each group's object, with
/// the member names `members` gives for a group's where ("passes.*" ->
/// {"cold"}); a group with "*" it does not list gets one member, "cold".
nlohmann::json full_entry_of(const MetricTable& t, const std::map<std::string, std::vector<std::string>>& members);

/// The key that names a metric in the results file: the last of its path,
/// or, where that is a summary statistic (io/keys.hpp: mean, max, p99,
/// total), the key it summarises ("iterations" for "iterations.mean").
std::string metric_key(const Metric& m);

/// The declared metrics of a kind, one object each: kind, name (with its
/// group's prefix, "{key}" for each member), where (the group's path in an
/// entry), path (in the group's object), key, unit, better, merge, guard
/// {level, abs, rel}, timing, scale, needs, ratio_to.
nlohmann::json metrics_listing(const StudyKind& k);

/// The same as a table for the terminal, one line per metric.
std::string metrics_text(const StudyKind& k);

}  // namespace idcol::harness
