// The stress suite as a study kind: its Study, its `info` and its row of the table.
#include <algorithm>
#include <cmath>
#include "io/text.hpp"
#include "studies/stress/stress_metrics.hpp"
#include "studies/entry_shards.hpp"
#include "studies/metric_list.hpp"
#include "studies/scene_study.hpp"
#include "studies/stress/stress.hpp"
#include "studies/stress/stress_keys.hpp"
#include "studies/stress/stress_spec.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

class StressStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override { return {"--shard", "--threads", "--max-failures", "--max-poses", "--oracle-every"}; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    if (o.max_poses > 0) limit_stress_poses(s_, o.max_poses);
    if (o.oracle_every > 0)
      for (StressCase& c : s_.spec.as<StressSpec>().cases) c.oracle_every = o.oracle_every;
    StressOutput out = run_stress(s_, resolved(o, sink));
    json results = make_stress_results(s_, out, metadata);
    sink.add(std::move(out.failures));
    return results;
  }
  /// The shard's cases (i, i + N, ...), each cut to --max-poses.
  std::uint64_t solves(const StudyOptions& o) const override {
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < cases().size(); ++i)
      if (in_shard(i, o.shard_index, o.shard_count)) n = count_sum(n, case_solves(cases()[i], o));
    return n;
  }
  std::vector<CostPart> estimate(const StudyOptions& o) const override {
    // Per checked solve, in seconds of one core on the development machine:
    // the solve with its surface and normal checks (and, for random bodies,
    // drawing the bodies) about 0.15 ms; the oracle about 0.3 ms more where
    // it runs (every oracle_every-th pose). Measured: the CI's random-body
    // cut, 1,078,560 solves with the oracle on every 40th pose, 174 s of CPU;
    // its first 100 poses per case with the oracle on every pose, 28,800
    // solves in 12.6 s; the CI's stress cut, 41,000 solves in 25 s.
    double checks = 0.0, oracles = 0.0;
    for (std::size_t i = 0; i < cases().size(); ++i) {
      if (!in_shard(i, o.shard_index, o.shard_count)) continue;
      const StressCase& c = cases()[i];
      const double n = static_cast<double>(case_solves(c, o));
      const std::uint64_t every = o.oracle_every > 0 ? o.oracle_every : std::max<std::uint64_t>(1, c.oracle_every);
      checks += 0.15e-3 * n;
      oracles += 0.3e-3 * n / static_cast<double>(every);
    }
    const double t = std::max(1, o.threads);
    return {{"solves and their checks", checks / t}, {"oracles", oracles / t}};
  }
  /// A case's solves: its poses (cut to --max-poses) in each pass, and for
  /// random bodies in both body orders.
  static std::uint64_t case_solves(const StressCase& c, const StudyOptions& o) {
    const std::uint64_t poses = o.max_poses > 0 ? std::min(c.poses, o.max_poses) : c.poses;
    return count_product(count_product(poses, c.passes.size()), c.kind == StressKind::RandomBodies ? 2 : 1);
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

 private:
  const std::vector<StressCase>& cases() const { return s_.spec.as<StressSpec>().cases; }
};

std::string stress_info(const json& r) {
  // Sums of the counts the file has (a null one, no figure, is left out).
  double solves = 0, genuine = 0, falses = 0;
  const auto add = [](double& sum, double v) { sum += std::isnan(v) ? 0.0 : v; };
  for (const json& c : r.at("cases"))
    for (const auto& [pass, p] : c.at("passes").items()) {
      add(solves, number_at(p, "solves"));
      add(genuine, number_at(p, key::genuine));
      add(falses, number_at(p, std::string(key::false_convergence) + "." + key::total));
    }
  return format("stress: %zu cases, %.0f solves, %.0f genuine (%.4f%%), %.0f false convergences\n", r.at("cases").size(), solves,
                genuine, solves > 0 ? 100.0 * genuine / solves : 0.0, falses);
}

std::string case_key(const json&, const json& c) { return c.at("name").get<std::string>(); }
}  // namespace

namespace {

/// The stress suite's row of the table of kinds.
class StressStudyKind : public StudyKind {
 public:
  StressStudyKind() {
    name = "stress";
    section = "case";
    noun = "stress-suite";
    schema = kStressSchema;
    scene_is = "a stress suite ([[case]] tables; a random-body suite too)";
    run_options =
        "shards are cases i, i+N, ...   --threads T (default 1)\n"
        "--max-failures N (records kept per case and pass; default 2000; all are counted)\n"
        "--max-poses N (each case's first min(poses, N) poses; default all)\n"
        "--oracle-every K (the oracle on poses k = 0, K, 2K, ...; default: each case's oracle_every)";
    default_threads = 1;
    pin_whole_run = false;
    entries = "cases";
    entry_word = "case";
    top_members = {{"thresholds", JsonType::Object}};
    entry_members = {{"name", JsonType::String}, {"shape1", JsonType::String}, {"shape2", JsonType::String},
                     {"poses", JsonType::Count}, {"passes", JsonType::Object}};
    identity = {{"scene.name", "solver", "thresholds"},
                {"shape1", "shape2", "poses", "kind", "shell", "L", "oracle", "oracle_every", "random_bodies"}};
    full_entry = full_entry_of(metrics(), {{"passes.*", {"cold"}}}).dump();
  }
  void read_scene(Reader& top, const std::string& file, Scene& s) const override { read_stress_scene(top, file, s); }
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
