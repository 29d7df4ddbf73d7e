// The stress suite as a study kind: its Study, its `info` and its row of the table.
#include <algorithm>
#include <cmath>
#include "io/text.hpp"
#include "studies/stress/stress_metrics.hpp"
#include "studies/kinds.hpp"
#include "study/entry_shards.hpp"
#include "study/metric_list.hpp"
#include "study/scene_study.hpp"
#include "studies/stress/stress.hpp"
#include "studies/stress/stress_keys.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

class StressStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override { return {"--shard", "--threads", "--max-failures", "--max-poses"}; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    if (o.max_poses > 0) limit_stress_poses(s_, o.max_poses);
    StressOutput out = run_stress(s_, resolved(o, sink));
    json results = make_stress_results(s_, out, metadata);
    sink.add(std::move(out.failures));
    return results;
  }
  std::uint64_t solves(const StudyOptions& o) const override {
    std::uint64_t n = 0;
    for (const StressCase& c : s_.cases) {
      const std::uint64_t poses = o.max_poses > 0 ? std::min(c.poses, o.max_poses) : c.poses;
      // random bodies: both body orders; warm: one more solve for the start
      const std::uint64_t orders = c.kind == StressKind::RandomBodies ? 2 : 1;
      n += poses * c.passes.size() * orders;
    }
    return n;
  }
  std::vector<CostPart> estimate(const StudyOptions& o) const override {
    // Every answer is checked against an oracle: ~0.7 ms per checked solve.
    return {{"solves and their oracle checks", 0.7e-3 * static_cast<double>(solves(o)) / std::max(1, o.threads)}};
  }
  std::string summary(const json& results) const override {
    std::string o;
    for (const json& c : results.at("cases"))
      for (const auto& [name, p] : c.at("passes").items())
        o += format("  %-28s %-4s genuine %.4f%% (%llu of %llu), false convergence %llu", c.at("name").get<std::string>().c_str(),
                  name.c_str(), 100.0 * p.at(key::genuine_rate).get<double>(), p.at(key::genuine).get<unsigned long long>(),
                  p.at("solves").get<unsigned long long>(), p.at(key::false_convergence).at(key::total).get<unsigned long long>()) + "\n";
    return o;
  }
};

std::string stress_info(const json& r) {
  unsigned long long solves = 0, genuine = 0, falses = 0;
  for (const json& c : r.at("cases"))
    for (const auto& [pass, p] : c.at("passes").items()) {
      solves += p.at("solves").get<unsigned long long>();
      genuine += p.at(key::genuine).get<unsigned long long>();
      falses += p.at(key::false_convergence).at(key::total).get<unsigned long long>();
    }
  return format("stress: %zu cases, %llu solves, %llu genuine (%.4f%%), %llu false convergences\n", r.at("cases").size(), solves,
                genuine, solves ? 100.0 * genuine / solves : 0.0, falses);
}

std::string case_key(const json&, const json& c) { return c.at("name").get<std::string>(); }
}  // namespace

namespace {

/// The stress suite's row of the table of kinds.
class StressStudyKind : public StudyKind {
 public:
  StressStudyKind() {
    name = "stress";
    noun = "stress-suite";
    schema = kStressSchema;
    default_threads = 1;
    pin_whole_run = false;
    entries = "cases";
    entry_word = "case";
    full_entry = full_entry_of(metrics(), {{"passes.*", {"cold"}}}).dump();
  }
  std::unique_ptr<Study> make(Scene s) const override { return std::make_unique<StressStudy>(std::move(s)); }
  bool has_table() const override { return true; }
  std::string table(const json& results, const std::string& path) const override { return stress_markdown(results, path); }
  std::string info(const json& results) const override { return stress_info(results); }
  std::string entry_key(const json& results, const json& entry) const override { return case_key(results, entry); }
  const MetricTable& metrics() const override { return stress_metrics(); }
  json merge(const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names, bool) const override {
    return merge_entry_shards(shards, metadata, names, kStressSchema, "cases", "failure_records");
  }
};

}  // namespace

const StudyKind& stress_kind() {
  static const StressStudyKind kind;
  return kind;
}

}  // namespace idcol::harness
