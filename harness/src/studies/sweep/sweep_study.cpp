// The sweep as a study kind: its Study, its `info` and its row of the table.
#include <algorithm>
#include <cmath>
#include "io/text.hpp"
#include "studies/sweep/sweep_metrics.hpp"
#include "studies/sweep/sweep_spec.hpp"
#include "studies/cost_model.hpp"
#include "studies/metric_list.hpp"
#include "studies/scene_study.hpp"
#include "studies/sweep/sweep.hpp"
#include "studies/sweep/sweep_keys.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

class SweepStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override {
    return {"--shard", "--pin", "--threads", "--max-traced-failures", "--per-pose"};
  }
  bool records_failures() const override { return sw().record.failures; }
  bool records_per_pose() const override { return sw().record.per_pose; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    const StudyOptions r = resolved(o, sink);
    if (r.threads > 1 && (sw().record.timing || sw().record.per_pose))
      throw std::invalid_argument("--threads > 1 is only for scenes that record neither timing nor per_pose");
    RunOutput out = run_scene(s_, r);
    json results = make_results(s_, out, metadata);
    sink.add(std::move(out.failures));
    return results;
  }
  /// The shard's poses are whole warm-start chains (shard_range), the same
  /// poses that run() solves.
  std::uint64_t solves(const StudyOptions& o) const override {
    return count_product(count_product(sw().pairs.size(), sw().passes.size()), shard_poses(o));
  }
  /// Estimated against measured wall time of the whole command (cost_model.hpp's
  /// machine): `run configs/paper_table2.toml --shard 0/100` 12 s against
  /// 10.7 s; the whole of it 11 min against the 997 s of
  /// results/paper_table2.json; `run configs/ci.toml` 40 s against 54 s;
  /// `run configs/quick.toml` 0.63 s against 0.73 s.
  std::vector<CostPart> estimate(const StudyOptions& o) const override {
    const double threads = std::max(1, o.threads);
    const double poses = static_cast<double>(shard_poses(o));
    const double passes = static_cast<double>(sw().passes.size());
    double solve_s = 0.0, check_s = 0.0, oracle_s = 0.0, baseline_s = 0.0, deriv_s = 0.0;
    for (const auto& [i1, i2] : sw().pairs) {
      const Shape& b1 = *s_.shapes[i1].shape;
      const Shape& b2 = *s_.shapes[i2].shape;
      solve_s += passes * (poses + static_cast<double>(std::min<std::uint64_t>(s_.warmup, s_.poses))) * cost::solve;
      if (sw().record.checks) check_s += passes * poses * (cost::answer_check + cost::oracle_query(b1, b2));
      if (sw().record.derivatives && sw().derivatives.covers(i1, i2))
        deriv_s += std::ceil(poses / static_cast<double>(std::max<std::uint64_t>(1, sw().derivatives.every))) * cost::derivative_check;
      if (!sw().record.baselines || !sw().baselines.covers(i1, i2)) continue;
      // The agreement pass: at every pose a cold solve, the oracle and each
      // boolean; then, with timing, every method on the first timing_poses
      // (each after up to 100 warm-up queries).
      double booleans = 0.0;
      for (const std::string& m : sw().baselines.methods)
        if (m != "oracle") booleans += cost::baseline_query(m, b1, b2);
      const double oracle = cost::oracle_query(b1, b2);
      solve_s += poses * cost::solve;
      oracle_s += poses * oracle;
      baseline_s += poses * booleans;
      if (sw().record.timing) {
        const double timed = std::min(static_cast<double>(sw().baselines.timing_poses), poses);
        const double runs = timed + std::min(timed, 100.0);
        solve_s += 2 * runs * cost::solve;
        baseline_s += runs * booleans;
        if (sw().baselines.has("oracle")) oracle_s += runs * oracle;
      }
    }
    // Threads share the untimed work: checks, derivatives and the agreement
    // pass; a timed scene runs on one.
    std::vector<CostPart> parts{{"solves", solve_s / threads}};
    if (check_s > 0) parts.push_back({"checks", check_s / threads});
    if (oracle_s > 0) parts.push_back({"oracles", oracle_s / threads});
    if (baseline_s > 0) parts.push_back({"baselines", baseline_s / threads});
    if (deriv_s > 0) parts.push_back({"derivatives", deriv_s / threads});
    return parts;
  }
  std::string summary(const json& results) const override {
    const json& sh = results.at("shard").at("poses");
    std::string o = format("%s: %zu pairs x %zu passes, poses [%llu, %llu) of %llu, %.1f s", s_.name.c_str(), sw().pairs.size(),
                         sw().passes.size(), sh.at(0).get<unsigned long long>(), sh.at(1).get<unsigned long long>(),
                         static_cast<unsigned long long>(s_.poses), results.at("wall_seconds").get<double>()) + "\n";
    for (const auto& p : results["pairs"])
      for (const auto& [name, pass] : p["passes"].items()) {
        o += format("  %-5s %-5s %-4s converged %.6f%% (%llu failed)", p["body1"].get<std::string>().c_str(),
                             p["body2"].get<std::string>().c_str(), name.c_str(), 100.0 * pass[key::convergence_rate].get<double>(),
                             pass[key::failures].get<unsigned long long>());
        if (pass.contains(key::time) && !pass[key::time][key::all]["mean_ns"].is_null())
          o += format("  mean %.2f us", pass[key::time][key::all]["mean_ns"].get<double>() / 1e3);
        if (pass.contains(key::iterations) && pass[key::iterations][key::mean].is_number())
          o += format("  iters %.2f", pass[key::iterations][key::mean].get<double>());
        o += "\n";
      }
    return o;
  }

 private:
  std::uint64_t shard_poses(const StudyOptions& o) const {
    const ShardRange r = shard_range(s_, o.shard_index, std::max(1, o.shard_count));
    return r.pose_hi - r.pose_lo;
  }
  const SweepSpec& sw() const { return s_.spec.as<SweepSpec>(); }
};

std::string pair_key(const json&, const json& p) { return p.at("body1").get<std::string>() + "-" + p.at("body2").get<std::string>(); }

/// A count as `info` prints it ("?" where the file has none: null).
std::string count_text(double v) { return std::isnan(v) ? "?" : format("%.0f", v); }

/// `info` on a sweep: its rows, the verdict, and the times where timed. The
/// file was checked (studies/results_file.hpp): a figure may still be null or
/// absent, as in a file made for compare alone.
std::string sweep_info(const json& r) {
  double worst = 1.0;
  std::string worst_at;
  std::size_t n = 0;
  for (const json& p : r.at("pairs"))
    for (const auto& [pass, st] : p.at("passes").items()) {
      ++n;
      const double c = number_at(st, key::convergence_rate);
      if (!std::isnan(c) && (c < worst || worst_at.empty())) {
        worst = c;
        worst_at = escaped(pair_key(r, p) + " " + pass);
      }
    }
  const json* sh = at_path(r, "shard.poses");
  const bool has_poses = sh && sh->is_array() && sh->size() == 2;
  const std::string poses = has_poses ? "poses [" + (*sh)[0].dump() + ", " + (*sh)[1].dump() + ")" : "poses ?";
  std::string o = format("sweep: %zu (pair, pass) rows, %s, %.1f s\n", n, poses.c_str(), std::max(0.0, number_at(r, "wall_seconds")));
  // The verdict: did every pair converge, and how fast (median, p99).
  std::vector<std::string> not_converged;
  std::size_t width = 4;
  bool timed = false;
  for (const json& p : r.at("pairs")) {
    const std::string name = escaped(pair_key(r, p));  // names from the file, which may have been edited by hand
    width = std::max(width, name.size());
    for (const auto& [pass, st] : p.at("passes").items()) {
      const double failed = number_at(st, key::failures);
      if (failed > 0)
        not_converged.push_back(name + " " + escaped(pass) + ": " + count_text(failed) + " of " + count_text(number_at(st, "solves")) + " failed");
      timed |= !std::isnan(number_at(st, key::dotted<key::time, key::all, key::median_ns>));
    }
  }
  if (not_converged.empty()) o += "VERDICT: every pose of every pair converged, in every pass\n";
  else {
    o += format("VERDICT: %zu (pair, pass) rows did not converge everywhere:\n", not_converged.size());
    for (const std::string& l : not_converged) o += "  " + l + "\n";
  }
  if (!timed) return o + format("lowest convergence %.6f%% (%s)\n", 100.0 * worst, worst_at.c_str());
  o += format("%-*s  %21s  %21s  %s\n", static_cast<int>(width), "pair", "cold median / p99 us", "warm median / p99 us", "converged");
  auto us = [](const json& passes, const char* pass) {
    const json* t = at_path(passes, std::string(pass) + "." + key::dotted<key::time, key::all>);
    if (!t || std::isnan(number_at(*t, key::median_ns))) return std::string(kMissing);
    return format("%.2f / %.2f", number_at(*t, key::median_ns) / 1e3, number_at(*t, key::p99_ns) / 1e3);
  };
  for (const json& p : r.at("pairs")) {
    const std::string name = escaped(pair_key(r, p));  // names from the file, which may have been edited by hand
    double conv = 1.0;
    for (const auto& [pass, st] : p.at("passes").items()) conv = std::min(conv, number_at(st, key::convergence_rate));
    o += format("%-*s  %21s  %21s  %.4f%%\n", static_cast<int>(width), name.c_str(), us(p.at("passes"), "cold").c_str(),
                us(p.at("passes"), "warm").c_str(), 100.0 * conv);
  }
  return o;
}

}  // namespace

namespace {

/// The sweep's row of the table of kinds.
class SweepStudyKind : public StudyKind {
 public:
  SweepStudyKind() {
    name = "sweep";
    noun = "sweep";
    schema = kResultsSchema;
    default_threads = 1;
    pin_whole_run = true;
    entries = "pairs";
    entry_word = "pair";
    scene_is = "a sweep ([shapes], [sweep], [run])";
    run_options =
        "shards are whole warm-start chains\n"
        "--pin CPU (default: not pinned)   --threads T (default 1; > 1 only without timing and per_pose)\n"
        "--per-pose P.csv (default: RESULTS with .poses.csv, when the scene records per_pose)\n"
        "--max-traced-failures M (default 20): the failures re-solved with their iteration trace";
    top_members = {{"sweep", JsonType::Object}, {"passes", JsonType::Array}};
    entry_members = {{"body1", JsonType::String}, {"body2", JsonType::String}, {"shape1", JsonType::String},
                     {"shape2", JsonType::String}, {"passes", JsonType::Object}};
    identity = {{"scene.name", "solver", "sweep", "passes", "shard.poses", "timing.path"}, {"shape1", "shape2"},
                {{"timing.path", "\"loop\""}}};
    // A pass named cold, and a method of each table of the baselines.
    full_entry = full_entry_of(metrics(), {{"passes.*", {"cold"}},
                                           {"baselines.status.*", {"fcl_collide"}},
                                           {"baselines.answers.*", {"dcol"}},
                                           {"baselines.timing.methods.*", {"fcl_collide", "idcol"}}})
                     .dump();
  }
  void read_scene(Reader& top, const std::string& file, Scene& s) const override { read_sweep_scene(top, file, s); }
  std::unique_ptr<Study> make(Scene s) const override { return std::make_unique<SweepStudy>(std::move(s)); }
  bool prints_scene() const override { return true; }
  std::string scene_text(const Scene& s) const override { return scene_to_toml(s); }
  bool has_table() const override { return true; }
  std::string table(const json& results, const std::string& path) const override { return markdown_table(results, path); }
  std::string info(const json& results) const override { return sweep_info(results); }
  std::string entry_key(const json& results, const json& entry) const override { return pair_key(results, entry); }
  const MetricTable& metrics() const override { return sweep_metrics(); }
  json merge(const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names,
             bool allow_mixed) const override {
    return merge_results(shards, metadata, names, allow_mixed);
  }
};

}  // namespace

const StudyKind& sweep_kind() {
  static const SweepStudyKind kind;
  return kind;
}

}  // namespace idcol::harness
