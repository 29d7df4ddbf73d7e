// The sweep as a study kind: its Study, its `info` and its row of the table.
#include <algorithm>
#include <cmath>
#include "io/text.hpp"
#include "studies/sweep/sweep_metrics.hpp"
#include "studies/kinds.hpp"
#include "study/scene_study.hpp"
#include "studies/sweep/sweep.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

class SweepStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override {
    return {"--shard", "--pin", "--threads", "--max-traced-failures", "--per-pose"};
  }
  bool records_failures() const override { return s_.record.failures; }
  bool records_per_pose() const override { return s_.record.per_pose; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    const StudyOptions r = resolved(o, sink);
    if (r.threads > 1 && (s_.record.timing || s_.record.per_pose))
      throw std::invalid_argument("--threads > 1 is only for scenes that record neither timing nor per_pose");
    RunOutput out = run_scene(s_, r);
    json results = make_results(s_, out, metadata);
    sink.add(std::move(out.failures));
    return results;
  }
  std::uint64_t solves(const StudyOptions& o) const override {
    const std::uint64_t poses = s_.poses / std::max(1, o.shard_count) + (s_.poses % std::max(1, o.shard_count) ? 1 : 0);
    return s_.pairs.size() * s_.passes.size() * poses;
  }
  double estimated_seconds(const StudyOptions& o) const override {
    // ~3 us per solve (paper_table1 on this machine class), ~40 us with the
    // baselines' agreement pass, ~20 us with derivatives checked.
    const double per = s_.record.baselines ? 40e-6 : s_.record.derivatives ? 20e-6 : 3e-6;
    return per * static_cast<double>(solves(o)) / std::max(1, o.threads);
  }
  std::string summary(const json& results) const override {
    const json& sh = results.at("shard").at("poses");
    std::string o = format("%s: %zu pairs x %zu passes, poses [%llu, %llu) of %llu, %.1f s", s_.name.c_str(), s_.pairs.size(),
                         s_.passes.size(), sh.at(0).get<unsigned long long>(), sh.at(1).get<unsigned long long>(),
                         static_cast<unsigned long long>(s_.poses), results.at("wall_seconds").get<double>()) + "\n";
    for (const auto& p : results["pairs"])
      for (const auto& [name, pass] : p["passes"].items()) {
        o += format("  %-5s %-5s %-4s converged %.6f%% (%llu failed)", p["body1"].get<std::string>().c_str(),
                             p["body2"].get<std::string>().c_str(), name.c_str(), 100.0 * pass["convergence_rate"].get<double>(),
                             pass["failures"].get<unsigned long long>());
        if (pass.contains("time") && !pass["time"]["all"]["mean_ns"].is_null())
          o += format("  mean %.2f us", pass["time"]["all"]["mean_ns"].get<double>() / 1e3);
        if (pass.contains("iterations") && pass["iterations"]["mean"].is_number())
          o += format("  iters %.2f", pass["iterations"]["mean"].get<double>());
        o += "\n";
      }
    return o;
  }
};

std::string pair_key(const json&, const json& p) { return p.at("body1").get<std::string>() + "-" + p.at("body2").get<std::string>(); }

/// `info` on a sweep: its rows, the verdict, and the times where timed.
std::string sweep_info(const json& r) {
  double worst = 1.0;
  std::string worst_at;
  std::size_t n = 0;
  for (const json& p : r.at("pairs"))
    for (const auto& [pass, st] : p.at("passes").items()) {
      ++n;
      const double c = st.at("convergence_rate").get<double>();
      if (c < worst || worst_at.empty()) {
        worst = c;
        worst_at = pair_key(r, p) + " " + pass;
      }
    }
  const json& sh = r.at("shard").at("poses");
  std::string o = format("sweep: %zu (pair, pass) rows, poses [%s, %s), %.1f s\n", n, sh.at(0).dump().c_str(), sh.at(1).dump().c_str(),
                         r.value("wall_seconds", 0.0));
  // The verdict: did every pair converge, and how fast (median, p99).
  std::vector<std::string> not_converged;
  std::size_t width = 4;
  bool timed = false;
  for (const json& p : r.at("pairs")) {
    const std::string name = pair_key(r, p);
    width = std::max(width, name.size());
    for (const auto& [pass, st] : p.at("passes").items()) {
      if (st.at("failures").get<unsigned long long>() > 0)
        not_converged.push_back(name + " " + pass + ": " + std::to_string(st.at("failures").get<unsigned long long>()) + " of " +
                                std::to_string(st.at("solves").get<unsigned long long>()) + " failed");
      timed |= st.contains("time") && st["time"]["all"]["median_ns"].is_number();
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
    if (!passes.contains(pass) || !passes[pass].contains("time") || !passes[pass]["time"]["all"]["median_ns"].is_number())
      return std::string(kMissing);
    const json& t = passes[pass]["time"]["all"];
    return format("%.2f / %.2f", t["median_ns"].get<double>() / 1e3, t["p99_ns"].get<double>() / 1e3);
  };
  for (const json& p : r.at("pairs")) {
    const std::string name = pair_key(r, p);
    double conv = 1.0;
    for (const auto& [pass, st] : p.at("passes").items()) conv = std::min(conv, st.at("convergence_rate").get<double>());
    o += format("%-*s  %21s  %21s  %.4f%%\n", static_cast<int>(width), name.c_str(), us(p.at("passes"), "cold").c_str(),
                us(p.at("passes"), "warm").c_str(), 100.0 * conv);
  }
  return o;
}

}  // namespace

const StudyKind& sweep_kind() {
  static const StudyKind kind = {"sweep", "sweep", kResultsSchema,
       [](Scene s) -> std::unique_ptr<Study> { return std::make_unique<SweepStudy>(std::move(s)); }, 1, true, scene_to_toml,
       markdown_table, nullptr, sweep_info, "pairs", "pair", pair_key, sweep_metrics,
       R"({"passes": {"cold": {"convergence_rate": 0, "failures": 0, "iterations": {"mean": 0, "max": 0}, "time": {"all": {"median_ns": 0, "p99_ns": 0}},
                               "checks": {"false_convergence": {"total": 0}, "oracle_failed": 0, "checked": 0,
                                          "worst_surface_error": 0, "worst_normal_error": 0, "worst_alpha_error": 0}, "solves": 0}},
           "baselines": {"genuine_total": 0, "idcol_outside_bracket": 0, "oracle_failed": 0, "status": {"fcl_collide": {"queries": 0, "genuine": 0, "band": 0, "failed": 0}},
                         "alpha_abs_err": {"mean": 0, "p99": 0, "max": 0}, "alpha_rel_err": {"mean": 0, "p99": 0, "max": 0},
                         "normal_angle_rad": {"p99": 0, "max": 0}, "timing": {"methods": {"fcl_collide": {"median_ns": 1}, "idcol": {"median_ns": 1}}}},
           "derivatives": {"poses": 0, "agreement": 0, "disagree_unflagged": 0, "worst_error": 0}})",
       [](const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names, bool allow_mixed) {
         return merge_results(shards, metadata, names, allow_mixed);
       }};
  return kind;
}

}  // namespace idcol::harness
