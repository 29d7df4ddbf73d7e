// The three studies behind the Study interface (pass.hpp), one a kind of scene.
#include "idcol_harness/pass.hpp"

#include <cstdarg>
#include <cstdio>

#include "idcol_harness/runner.hpp"
#include "idcol_harness/scene.hpp"
#include "idcol_harness/stress.hpp"
#ifdef IDCOL_HARNESS_WITH_BASELINES
#include "idcol_harness/smoothing.hpp"
#endif

namespace idcol::harness {

using nlohmann::json;

namespace {

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return buf;
}

/// What every study keeps: its scene, and the scene's text for the results.
class SceneStudy : public Study {
 public:
  explicit SceneStudy(Scene s) : s_(std::move(s)), text_{s_.path, s_.name, s_.text} {}
  const char* kind() const override { return to_string(s_.kind()); }
  const SceneText& scene() const override { return text_; }
  const SolverOptions& solver() const override { return s_.solver; }

 protected:
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
    RunOptions r;
    r.shard_index = o.shard_index;
    r.shard_count = o.shard_count;
    r.progress = o.progress;
    r.max_traced_failures = o.max_traced_failures;
    r.failures_path = sink.failures_path;
    r.per_pose = o.per_pose;
    r.threads = o.threads > 0 ? o.threads : 1;
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
    StressOptions so;
    so.threads = o.threads > 0 ? o.threads : 1;
    so.failures_path = sink.failures_path;
    so.max_failures = o.max_failures;
    so.progress = o.progress;
    StressOutput out = run_stress(s_, so);
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
    SmoothingOptions so;
    so.threads = o.threads > 0 ? o.threads : 2;
    so.pin = o.pin;
    json failures = json::array();
    json results = run_smoothing(s_, so, metadata, failures, sink.failures_path);
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
  const std::string kind = to_string(s.kind());
  if (!expected.empty() && kind != expected)
    throw SceneError(path, kind == "stress" ? "case" : kind == "smoothing" ? "grid" : "(file)",
                     "a " + kind + " scene, not a " + expected + " scene (run it with `idcol_harness run`)");
  if (s.kind() == SceneKind::Stress) return std::make_unique<StressStudy>(std::move(s));
  if (s.kind() == SceneKind::Sweep) return std::make_unique<SweepStudy>(std::move(s));
#ifdef IDCOL_HARNESS_WITH_BASELINES
  return std::make_unique<SmoothingStudy>(std::move(s));
#else
  throw SceneError(path, "grid", "a smoothing grid needs the exact oracles, and this build has none (configure with -DIDCOL_BUILD_BASELINES=ON)");
#endif
}

}  // namespace idcol::harness
