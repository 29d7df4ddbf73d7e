// The smoothing study as a study kind: its row of the table, which reads
// its results files in every build (the study itself needs the baselines).
#include <cmath>
#include "io/text.hpp"
#include "studies/smoothing/smoothing_metrics.hpp"
#include "studies/kinds.hpp"
#include "study/entry_shards.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

std::string point_key(const json& results, const json& p) {
  return results.value("parameter", std::string("value")) + " = " + format("%.17g", p.at("value").is_number() ? p.at("value").get<double>() : NAN);
}

}  // namespace

const StudyKind& smoothing_kind() {
  static const StudyKind kind = {"smoothing", "smoothing-study", kSmoothingSchema,
       make_smoothing_study,
       2, false, nullptr, nullptr, "scripts/plot_smoothing.py",
       [](const json& r) { return format("smoothing study: %zu grid points, %.1f s\n", r.value("points", json::array()).size(), r.value("wall_seconds", 0.0)); },
       "points", "point", point_key, smoothing_metrics,
       R"({"cold_accuracy_pass": {}, "timing": {"cold": {"iterations": {}}}})",
       [](const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names, bool) {
         return merge_entry_shards(shards, metadata, names, kSmoothingSchema, "points", "failure_count");
       }};
  return kind;
}

}  // namespace idcol::harness
