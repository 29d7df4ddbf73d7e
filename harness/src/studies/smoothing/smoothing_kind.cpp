// The smoothing study as a study kind: its row of the table, which reads
// its results files in every build (the study itself needs the baselines).
#include <cmath>
#include "io/text.hpp"
#include "studies/smoothing/smoothing.hpp"
#include "studies/smoothing/smoothing_metrics.hpp"
#include "studies/smoothing/smoothing_spec.hpp"
#include "studies/entry_shards.hpp"
#include "studies/metric_list.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

std::string point_key(const json& results, const json& p) {
  return results.value("parameter", std::string("value")) + " = " + format("%.17g", p.at("value").is_number() ? p.at("value").get<double>() : NAN);
}

}  // namespace

namespace {

/// The smoothing study's row of the table of kinds.
class SmoothingStudyKind : public StudyKind {
 public:
  SmoothingStudyKind() {
    name = "smoothing";
    section = "grid";
    noun = "smoothing-study";
    schema = kSmoothingSchema;
    scene_is = "a smoothing grid ([grid])";
    run_options =
        "shards are grid values i, i+N, ...   --threads T (the accuracy pass; default 2)\n"
        "--pin CPU (the timed passes; default: not pinned)   --poses N (default: the grid's)";
    default_threads = 2;
    pin_whole_run = false;
    tables_from = "scripts/plot_smoothing.py";
    entries = "points";
    entry_word = "point";
    top_members = {{"sweep", JsonType::Object}, {"parameter", JsonType::String}};
    entry_members = {{"value", JsonType::Number}, {"valid", JsonType::Bool}};
    identity = {{"scene.name", "solver", "sweep", "family", "parameter", "partner"}, {"value", "valid", "shape_text"}};
    full_entry = full_entry_of(metrics(), {{"timing.*", {"cold"}}}).dump();
  }
  void read_scene(Reader& top, const std::string& file, Scene& s) const override { read_smoothing_scene(top, file, s); }
  std::unique_ptr<Study> make(Scene s) const override { return make_smoothing_study(std::move(s)); }
  std::string info(const json& r) const override {
    return format("smoothing study: %zu grid points, %.1f s\n", r.value("points", json::array()).size(), r.value("wall_seconds", 0.0));
  }
  std::string entry_key(const json& results, const json& entry) const override { return point_key(results, entry); }
  const MetricTable& metrics() const override { return smoothing_metrics(); }
  json merge(const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names, bool) const override {
    return merge_entry_shards(shards, metadata, names, kSmoothingSchema, "points", "failure_count");
  }
};

}  // namespace

const StudyKind& smoothing_kind() {
  static const SmoothingStudyKind kind;
  return kind;
}

}  // namespace idcol::harness
