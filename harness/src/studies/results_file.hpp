// The one check of a results file (sweep, stress, smoothing, time of
// impact) before anything reads its figures: compare, merge, table, info
// and history add all read results files through it, so that a file that is
// not a valid one is refused in one way, by one rule, whichever command
// reads it, naming the file, the field (its JSON path) and the value.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "studies/study.hpp"

namespace idcol::harness {

/// Checks a results file and returns its kind: the schema of a kind
/// (study_kinds()); the header (io/record.hpp: check_header: schema_version
/// exactly the one this harness reads); the kind's members, at the top and
/// in each entry, of their types (StudyKind::top_members, entry_members);
/// no entry listed twice (by the kind's entry_key, the name compare and
/// merge match entries by); and every declared metric's value in its
/// declared range (studies/metric.hpp: metric_value_ok: a count an integer
/// >= 0, a fraction in [0, 1]). Throws FileError naming `file`, the field
/// and the value.
const StudyKind& check_results(const nlohmann::json& results, const std::string& file);

/// read_json_file, then check_results.
nlohmann::json read_results_file(const std::string& path);

}  // namespace idcol::harness
