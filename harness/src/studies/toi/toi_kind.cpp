// The time-of-impact study as a study kind: its Study and its row of the
// table of kinds. It runs in every build (its oracle is the independent
// geometry's); FCL's columns need FCL (toi_fcl.hpp).
#include <algorithm>
#include <cmath>

#include "io/text.hpp"
#include "studies/toi/toi.hpp"
#include "studies/toi/toi_keys.hpp"
#include "studies/toi/toi_metrics.hpp"
#include "studies/toi/toi_spec.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/toi_oracle.hpp"
#include "studies/cost_model.hpp"
#include "studies/entry_shards.hpp"
#include "studies/metric_list.hpp"
#include "studies/scene_study.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

class ToiStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override { return {"--shard", "--pin"}; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    json failures = json::array();
    json results = run_toi(s_, resolved(o, sink), metadata, failures);
    sink.add(std::move(failures));
    return results;
  }
  /// The shard's entries (pairs x models i, i + N, ...) x motions: queries, each some solves.
  std::uint64_t solves(const StudyOptions& o) const override {
    std::uint64_t entries = 0;
    const ToiSpec& spec = s_.spec.as<ToiSpec>();
    for (std::size_t e = 0; e < spec.pairs.size() * spec.models.size(); ++e) entries += in_shard(e, o.shard_index, o.shard_count);
    return count_product(entries, spec.motions);
  }
  /// Dominated by the oracle, whose method the pair decides. Estimated
  /// against measured wall time of the command: `run configs/ci_toi.toml`
  /// 2.7 s against 2.06 s, `run configs/toi.toml` 45 s against 65 s (load
  /// 4.8; results/toi.json took 131 s).
  std::vector<CostPart> estimate(const StudyOptions& o) const override {
    const ToiSpec& spec = s_.spec.as<ToiSpec>();
    double oracle_s = 0.0, idcol_s = 0.0, fcl_s = 0.0;
    std::size_t entry = 0;
    for (const auto& [i1, i2] : spec.pairs) {
      const baselines::ToiOracle oracle(baselines::to_desc(*s_.shapes[i1].shape), baselines::to_desc(*s_.shapes[i2].shape),
                                        {spec.oracle_samples, spec.graze, 60});
      for (std::size_t m = 0; m < spec.models.size(); ++m)
        if (in_shard(entry++, o.shard_index, o.shard_count)) {
          const double motions = static_cast<double>(spec.motions);
          oracle_s += motions * spec.oracle_samples * cost::toi_sample(oracle.method());
          idcol_s += motions * kToiTimingLoops * cost::toi_query;
          fcl_s += motions * kToiTimingLoops * cost::toi_fcl_query * static_cast<double>(spec.fcl.size());
        }
    }
    std::vector<CostPart> parts{{"oracle", oracle_s}, {"solves", idcol_s}};
    if (fcl_s > 0) parts.push_back({"fcl", fcl_s});
    return parts;
  }
  std::string summary(const json& results) const override {
    std::string o;
    for (const json& e : results.at(key::toi_pairs)) {
      const json& t = e.at(key::idcol_toi);
      o += format("  %-36s missed %llu, false impacts %llu, failures %llu, %.3g solves and %.3g us per query\n",
                  e.at("name").get<std::string>().c_str(), t.at(key::missed_contacts).get<unsigned long long>(),
                  t.at(key::false_impacts).get<unsigned long long>(), t.at(key::failures).get<unsigned long long>(),
                  t.at(key::solves_per_query).get<double>(), t.at(key::us_per_query).get<double>());
    }
    return o;
  }
};

class ToiStudyKind : public StudyKind {
 public:
  ToiStudyKind() {
    name = "toi";
    section = "toi";
    noun = "time-of-impact";
    schema = kToiSchema;
    scene_is = "a time-of-impact study ([toi])";
    run_options =
        "shards are entries (pairs x models) i, i+N, ...\n"
        "--pin CPU (the timed loops; default: not pinned)";
    default_threads = 1;
    pin_whole_run = true;
    entries = key::toi_pairs;
    entry_word = "pair";
    entry_members = {{"name", JsonType::String}, {"body1", JsonType::String}, {"body2", JsonType::String},
                     {"model", JsonType::String}, {key::motions, JsonType::Count}};
    identity = {{"scene.name", "solver"}, {"body1", "body2", "model", key::motions, "oracle_method"}};
    full_entry = full_entry_of(metrics(), {{"fcl.*", {"naive"}}}).dump();
  }
  void read_scene(Reader& top, const std::string& file, Scene& s) const override { read_toi_scene(top, file, s); }
  std::unique_ptr<Study> make(Scene s) const override { return std::make_unique<ToiStudy>(std::move(s)); }
  bool has_table() const override { return true; }
  std::string table(const json& results, const std::string& path) const override { return toi_markdown(results, path); }
  std::string info(const json& r) const override {
    double missed = 0, queries = 0;  // the counts the file has (a null one, no figure, left out)
    for (const json& e : r.at(key::toi_pairs)) {
      const double m = number_at(e, std::string(key::idcol_toi) + "." + key::missed_contacts);
      missed += std::isnan(m) ? 0.0 : m;
      queries += number_at(e, key::motions);
    }
    return format("time of impact: %zu pairs and models, %.0f motions, %.0f missed contacts, %.1f s\n",
                  r.at(key::toi_pairs).size(), queries, missed, std::max(0.0, number_at(r, "wall_seconds")));
  }
  std::string entry_key(const json&, const json& e) const override { return e.at("name").get<std::string>(); }
  const MetricTable& metrics() const override { return toi_metrics(); }
  json merge(const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names, bool) const override {
    return merge_entry_shards(shards, metadata, names, kToiSchema, key::toi_pairs, "failure_records");
  }
};

}  // namespace

const StudyKind& toi_kind() {
  static const ToiStudyKind kind;
  return kind;
}

}  // namespace idcol::harness
