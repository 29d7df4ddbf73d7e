// The three studies behind the Study interface (pass.hpp), one a kind of
// scene, and study_kinds(), the table of those kinds.
#include "idcol_harness/pass.hpp"

#include <algorithm>
#include <cmath>

#include "idcol_harness/compare.hpp"
#include "idcol_harness/runner.hpp"
#include "idcol_harness/scene.hpp"
#include "idcol_harness/stress.hpp"
#include "idcol_harness/writers.hpp"
#ifdef IDCOL_HARNESS_WITH_BASELINES
#include "idcol_harness/smoothing.hpp"
#endif

namespace idcol::harness {

using nlohmann::json;

namespace {

/// What every study keeps: its scene, and the scene's text for the results.
class SceneStudy : public Study {
 public:
  explicit SceneStudy(Scene s) : s_(std::move(s)), text_{s_.path, s_.name, s_.text} {}
  const StudyKind& kind() const override { return *s_.kind; }
  const SceneText& scene() const override { return text_; }
  const SolverOptions& solver() const override { return s_.solver; }

 protected:
  /// `o` as the study's runner takes it: the failures file named, the
  /// study's default threads filled in.
  StudyOptions resolved(StudyOptions o, const RecordSink& sink) const {
    o.failures_path = sink.failures_path;
    if (o.threads <= 0) o.threads = kind().default_threads;
    return o;
  }

  Scene s_;
  SceneText text_;
};

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

class StressStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override { return {"--threads", "--max-failures", "--max-poses"}; }
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
  double estimated_seconds(const StudyOptions& o) const override {
    // Every answer is checked against an oracle: ~0.7 ms per checked solve.
    return 0.7e-3 * static_cast<double>(solves(o)) / std::max(1, o.threads);
  }
  std::string summary(const json& results) const override {
    std::string o;
    for (const json& c : results.at("cases"))
      for (const auto& [name, p] : c.at("passes").items())
        o += format("  %-28s %-4s genuine %.4f%% (%llu of %llu), false convergence %llu", c.at("name").get<std::string>().c_str(),
                  name.c_str(), 100.0 * p.at("genuine_rate").get<double>(), p.at("genuine").get<unsigned long long>(),
                  p.at("solves").get<unsigned long long>(), p.at("false_convergence").at("total").get<unsigned long long>()) + "\n";
    return o;
  }
};

#ifdef IDCOL_HARNESS_WITH_BASELINES
class SmoothingStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override { return {"--threads", "--pin", "--poses"}; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    if (o.poses > 0) s_.poses = o.poses;
    json failures = json::array();
    json results = run_smoothing(s_, resolved(o, sink), metadata, failures);
    sink.add(std::move(failures));
    return results;
  }
  std::uint64_t solves(const StudyOptions& o) const override {
    return s_.grid->values.size() * 2 * (o.poses > 0 ? o.poses : s_.poses);  // cold and warm at each grid value
  }
  double estimated_seconds(const StudyOptions&) const override { return 0.0; }  // dominated by the oracles' geometry
  std::string summary(const json& results) const override {
    return format("%s: %zu grid points, %.1f s\n", s_.name.c_str(), results.at("points").size(),
                  results.at("wall_seconds").get<double>());
  }
};
#endif

}  // namespace

std::string cost_line(const Study& s, const StudyOptions& opt) {
  const double sec = s.estimated_seconds(opt);
  std::string t = format("cost: %llu solves", static_cast<unsigned long long>(s.solves(opt)));
  if (sec > 0.0) {
    const char* unit = sec < 120 ? "s" : sec < 7200 ? "min" : "h";
    const double v = sec < 120 ? sec : sec < 7200 ? sec / 60 : sec / 3600;
    t += format(", roughly %.3g %s on %d core%s (an estimate for this machine class, not a measurement)", v, unit,
                std::max(1, opt.threads), opt.threads > 1 ? "s" : "");
  }
  return t;
}

std::unique_ptr<Study> load_study(const std::string& path, const std::string& expected) {
  Scene s = parse_scene(read_scene_file(path), path);
  const StudyKind& k = *s.kind;
  if (!expected.empty() && k.name != expected)
    throw SceneError(path, k.section ? k.section : "(file)",
                     std::string("a ") + k.name + " scene, not a " + expected + " scene (run it with `idcol_harness run`)");
  return k.make(std::move(s));
}

namespace {

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
      return std::string("--");
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

std::string stress_info(const json& r) {
  unsigned long long solves = 0, genuine = 0, falses = 0;
  for (const json& c : r.at("cases"))
    for (const auto& [pass, p] : c.at("passes").items()) {
      solves += p.at("solves").get<unsigned long long>();
      genuine += p.at("genuine").get<unsigned long long>();
      falses += p.at("false_convergence").at("total").get<unsigned long long>();
    }
  return format("stress: %zu cases, %llu solves, %llu genuine (%.4f%%), %llu false convergences\n", r.at("cases").size(), solves,
                genuine, solves ? 100.0 * genuine / solves : 0.0, falses);
}

std::string case_key(const json&, const json& c) { return c.at("name").get<std::string>(); }
std::string point_key(const json& results, const json& p) {
  return results.value("parameter", std::string("value")) + " = " + format("%.17g", p.at("value").is_number() ? p.at("value").get<double>() : NAN);
}

}  // namespace

const std::vector<StudyKind>& study_kinds() {
  static const std::vector<StudyKind> kinds = {
      {"sweep", "sweep", kResultsSchema, nullptr, read_sweep_scene,
       [](Scene s) -> std::unique_ptr<Study> { return std::make_unique<SweepStudy>(std::move(s)); }, 1, true, scene_to_toml,
       markdown_table, nullptr, sweep_info, "pairs", "pair", pair_key, pair_metrics,
       R"({"passes": {"cold": {"convergence_rate": 0, "failures": 0, "iterations": {"mean": 0, "max": 0}, "time": {"all": {"median_ns": 0, "p99_ns": 0}},
                               "checks": {"false_convergence": {"total": 0}, "oracle_failed": 0}}},
           "baselines": {"genuine_total": 0, "idcol_outside_bracket": 0, "oracle_failed": 0, "status": {"fcl_collide": {"genuine": 0, "band": 0, "failed": 0}},
                         "alpha_abs_err": {"mean": 0, "p99": 0, "max": 0}, "alpha_rel_err": {"mean": 0, "p99": 0, "max": 0},
                         "normal_angle_rad": {"p99": 0, "max": 0}, "timing": {"methods": {"fcl_collide": {"median_ns": 1}, "idcol": {"median_ns": 1}}}},
           "derivatives": {"agreement": 0, "disagree_unflagged": 0, "worst_error": 0}})"},
      {"stress", "stress-suite", kStressSchema, "case", read_stress_scene,
       [](Scene s) -> std::unique_ptr<Study> { return std::make_unique<StressStudy>(std::move(s)); }, 1, false, nullptr,
       stress_markdown, nullptr, stress_info, "cases", "case", case_key, stress_case_metrics,
       R"({"passes": {"cold": {}}, "derivatives": {}})"},
      {"smoothing", "smoothing-study", kSmoothingSchema, "grid", read_smoothing_scene,
       [](Scene s) -> std::unique_ptr<Study> {
#ifdef IDCOL_HARNESS_WITH_BASELINES
         return std::make_unique<SmoothingStudy>(std::move(s));
#else
         throw SceneError(s.path, "grid", "a smoothing grid needs the exact oracles, and this build has none (configure with -DIDCOL_BUILD_BASELINES=ON)");
#endif
       },
       2, false, nullptr, nullptr, "scripts/plot_smoothing.py",
       [](const json& r) { return format("smoothing study: %zu grid points, %.1f s\n", r.value("points", json::array()).size(), r.value("wall_seconds", 0.0)); },
       "points", "point", point_key, smoothing_point_metrics,
       R"({"cold_accuracy_pass": {}, "timing": {"cold": {"iterations": {}}}})"},
  };
  return kinds;
}

const StudyKind* study_kind_of_schema(const std::string& schema) {
  for (const StudyKind& k : study_kinds())
    if (schema == k.schema) return &k;
  return nullptr;
}

}  // namespace idcol::harness
