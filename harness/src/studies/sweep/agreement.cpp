#include "studies/sweep/agreement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "gen/poses.hpp"
#include "exec/chains.hpp"

#include "io/record.hpp"
#include "studies/sweep/sweep_keys.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;


AgreementVerdict classify_answer(bool idcol_collide, bool baseline_collide, bool baseline_failed, bool oracle_ok, double lo,
                                 double hi, double tol, double own) {
  if (baseline_failed) return AgreementVerdict::Failed;
  if (baseline_collide == idcol_collide) return AgreementVerdict::Agree;
  if (oracle_ok && lo * (1.0 - tol) - own <= 1.0 && 1.0 <= hi * (1.0 + tol) + own) return AgreementVerdict::Band;
  return AgreementVerdict::Genuine;  // also a NaN bracket: no comparison passes
}

bool in_widened_bracket(double alpha, double lo, double hi, double tol) { return lo * (1.0 - tol) <= alpha && alpha <= hi * (1.0 + tol); }

// ---------------------------------------------------------------- statistics

namespace {
// The counts of StatusAgreement and DerivativeStats (Fields, stats.hpp).
const Fields<StatusAgreement> kStatusCounts = {{key::queries, &StatusAgreement::queries}, {"agree", &StatusAgreement::agree},
                                               {key::band, &StatusAgreement::band}, {key::genuine, &StatusAgreement::genuine},
                                               {key::failed, &StatusAgreement::failed}};
// The count of each AgreementVerdict, in its declaration order (run_agreement).
std::uint64_t StatusAgreement::* const kVerdictCounts[] = {&StatusAgreement::agree, &StatusAgreement::band,
                                                           &StatusAgreement::genuine, &StatusAgreement::failed};
const Fields<DerivativeStats> kDerivativeCounts = {
    {"poses", &DerivativeStats::poses},   {"converged", &DerivativeStats::converged},
    {"fd_failed", &DerivativeStats::fd_failed}, {"agree", &DerivativeStats::agree},
    {"disagree_flagged", &DerivativeStats::disagree_flagged}, {key::disagree_unflagged, &DerivativeStats::disagree_unflagged},
    {"flagged", &DerivativeStats::flagged}};
// AgreementStats: its counts, its alpha* and normal error histograms (written
// as err_summary), and the counts and seconds of its "timing" object.
const Fields<AgreementStats> kAgreementCounts = {
    {"poses", &AgreementStats::poses}, {"idcol_not_converged", &AgreementStats::idcol_not_converged},
    {key::oracle_failed, &AgreementStats::oracle_failed}, {key::idcol_outside_bracket, &AgreementStats::idcol_outside_bracket}};
const Fields<AgreementStats, LogHistogram> kErrorHistograms = {{key::alpha_abs_err, &AgreementStats::alpha_abs_err},
                                                              {key::alpha_rel_err, &AgreementStats::alpha_rel_err}};
// MethodAnswerStats: its counts and its histograms (written as err_summary).
const Fields<MethodAnswerStats> kAnswerCounts = {{key::normal_poses, &MethodAnswerStats::normal_poses},
                                                 {key::alpha_poses, &MethodAnswerStats::alpha_poses},
                                                 {key::alpha_outside_bound, &MethodAnswerStats::alpha_outside_bound}};
const Fields<MethodAnswerStats, LogHistogram> kAnswerHistograms = {
    {key::normal_angle_rad, &MethodAnswerStats::normal_angle},
    {key::alpha_rel_err, &MethodAnswerStats::alpha_rel_err},
    {key::alpha_rel_diff_idcol, &MethodAnswerStats::alpha_rel_diff_idcol},
    {key::method_iterations, &MethodAnswerStats::iterations}};
const Fields<AgreementStats> kTimingCounts = {{"poses", &AgreementStats::timed_poses}};
const Fields<AgreementStats, double> kTimingSeconds = {{"thread_cpu_seconds", &AgreementStats::timing_cpu_seconds},
                                                        {"wall_seconds", &AgreementStats::timing_wall_seconds}};

json err_summary(const LogHistogram& h) {
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  // A percentile is its bin's centre; never report it above the exact max.
  auto q = [&](double p) { return std::min(h.quantile(p), h.max()); };
  return {{"count", h.count()}, {"mean", num(h.mean())}, {"p50", num(q(0.5))}, {"p99", num(q(0.99))},
          {"max", num(h.max())}, {"histogram", h.to_json()}};
}
}  // namespace

void MethodAnswerStats::merge(const MethodAnswerStats& o) {
  add_fields(*this, o, kAnswerCounts);
  for (const auto& [key, h] : kAnswerHistograms) (this->*h).merge(o.*h);
}
json MethodAnswerStats::to_json() const {
  json j = json::object();
  write_fields(*this, j, kAnswerCounts);
  for (const auto& [key, h] : kAnswerHistograms) j[key] = err_summary(this->*h);
  return j;
}
MethodAnswerStats MethodAnswerStats::from_json(const json& j) {
  MethodAnswerStats s;
  read_fields(s, j, kAnswerCounts);
  for (const auto& [key, h] : kAnswerHistograms) s.*h = LogHistogram::from_json(j.at(key).at("histogram"));
  return s;
}

std::uint64_t& StatusAgreement::of(AgreementVerdict v) { return this->*kVerdictCounts[static_cast<int>(v)]; }
void StatusAgreement::merge(const StatusAgreement& o) { add_fields(*this, o, kStatusCounts); }
json StatusAgreement::to_json() const {
  json j = json::object();
  write_fields(*this, j, kStatusCounts);
  return j;
}
StatusAgreement StatusAgreement::from_json(const json& j) {
  StatusAgreement s;
  read_fields(s, j, kStatusCounts);
  return s;
}

void AgreementStats::merge(const AgreementStats& o) {
  add_fields(*this, o, kAgreementCounts);
  add_fields(*this, o, kTimingCounts);
  add_fields(*this, o, kTimingSeconds);
  for (const auto& [key, h] : kErrorHistograms) (this->*h).merge(o.*h);
  for (const auto& [k, v] : o.status) status[k].merge(v);
  for (const auto& [k, v] : o.answers) answers[k].merge(v);
  for (const auto& [k, v] : o.time) {
    auto it = time.find(k);
    if (it == time.end()) time.emplace(k, v);
    else it->second.merge(v);
  }
  for (const auto& [k, v] : o.timed_wrong) timed_wrong[k] += v;
}

json AgreementStats::to_json() const {
  json st = json::object();
  for (const auto& [k, v] : status) st[k] = v.to_json();
  json an = json::object();
  for (const auto& [k, v] : answers)
    if (!v.empty()) an[k] = v.to_json();
  json j = {{"status", st}, {key::answers, an}};
  write_fields(*this, j, kAgreementCounts);
  for (const auto& [key, h] : kErrorHistograms) j[key] = err_summary(this->*h);

  std::uint64_t g = idcol_outside_bracket;
  for (const auto& [k, v] : status) g += v.genuine;
  for (const auto& [k, v] : answers) g += v.alpha_outside_bound;
  j[key::genuine_total] = g;
  json tm = json::object();
  for (const auto& [k, h] : time) {
    const std::uint64_t wrong = timed_wrong.count(k) ? timed_wrong.at(k) : 0;
    auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    tm[k] = {{"count", h.count()},         {key::wrong, wrong},
             {key::median_ns, num(h.quantile(0.5))}, {"p90_ns", num(h.quantile(0.9))}, {key::p99_ns, num(h.quantile(0.99))},
             {"mean_ns", num(h.mean())},   {"histogram", h.to_json()}};
  }
  json& t = j["timing"] = {{"methods", tm}};
  write_fields(*this, t, kTimingCounts);
  write_fields(*this, t, kTimingSeconds);
  return j;
}

AgreementStats AgreementStats::from_json(const json& j) {
  AgreementStats s;
  read_fields(s, j, kAgreementCounts);
  for (const auto& [key, h] : kErrorHistograms) s.*h = LogHistogram::from_json(j.at(key).at("histogram"));
  for (const auto& [k, v] : j.at("status").items()) s.status[k] = StatusAgreement::from_json(v);
  for (const auto& [k, v] : j.at(key::answers).items()) s.answers[k] = MethodAnswerStats::from_json(v);
  const json& t = j.at("timing");
  read_fields(s, t, kTimingCounts);
  read_fields(s, t, kTimingSeconds);
  for (const auto& [k, v] : t.at("methods").items()) {
    s.time.emplace(k, LogHistogram::from_json(v.at("histogram")));
    s.timed_wrong[k] = v.at(key::wrong);
  }
  return s;
}

double DerivativeStats::agreement() const {
  const std::uint64_t n = converged - fd_failed;
  return n ? static_cast<double>(agree) / n : 1.0;
}
void DerivativeStats::merge(const DerivativeStats& o) {
  add_fields(*this, o, kDerivativeCounts);
  if (o.worst_error > worst_error || (o.worst_error == worst_error && o.worst_k < worst_k && o.worst_error > 0)) {
    worst_error = o.worst_error;
    worst_k = o.worst_k;
  }
}
json DerivativeStats::to_json() const {
  json j = json::object();
  write_fields(*this, j, kDerivativeCounts);
  j.update({{key::agreement, agreement()}, {key::worst_error, worst_error}, {"worst_k", worst_k}});
  return j;
}
DerivativeStats DerivativeStats::from_json(const json& j) {
  DerivativeStats s;
  read_fields(s, j, kDerivativeCounts);
  s.worst_error = j.at(key::worst_error);
  s.worst_k = j.at("worst_k");
  return s;
}

// ---------------------------------------------------------------- passes

namespace detail {
json failure_head(const Scene& scene, int i1, int i2, std::uint64_t k, const Pose& X, const char* kind) {
  const ShapeSpec& s1 = scene.shapes[i1];
  const ShapeSpec& s2 = scene.shapes[i2];
  json f = failure_record({s1.name, s2.name, &*s1.shape, &*s2.shape, "cold", k, to_string(scene.generator)}, X);
  f["kind"] = kind;
  f["t"] = static_cast<double>(k) * scene.dt;
  return f;
}

}  // namespace detail

DerivativeStats run_derivatives(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                                json& failures) {
  const Shape& b1 = *scene.shapes[i1].shape;
  const Shape& b2 = *scene.shapes[i2].shape;
  const PoseGenerator gen(scene.generator, radial_range(b1, b2), scene.dt);
  const DerivativeSpec& spec = scene.spec.as<SweepSpec>().derivatives;
  const std::uint64_t every = spec.every;
  std::vector<std::uint64_t> ks;
  for (std::uint64_t k = (lo + every - 1) / every * every; k < hi; k += every) ks.push_back(k);
  DerivativeCheckOptions opt;
  opt.h = spec.h;
  opt.tolerance = spec.tolerance;
  const int nt = std::max(1, threads);
  std::vector<DerivativeStats> sts(nt);
  std::vector<json> fs(nt, json::array());
  run_in_chains(0, ks.size(), 1, nt, [&](int t, std::uint64_t a, std::uint64_t b) {
    DerivativeStats& st = sts[t];
    for (std::uint64_t i = a; i < b; ++i) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      const Pose X = gen(ks[i]);
      const DerivativeCheckReport rep = check_derivatives(b1, b2, {X}, opt);
      ++st.poses;
      st.converged += rep.converged;
      st.fd_failed += rep.fd_failed;
      st.agree += rep.agree;
      st.disagree_flagged += rep.disagree_flagged;
      st.disagree_unflagged += rep.disagree_unflagged;
      st.flagged += rep.flagged;
      if (rep.worst_index >= 0 && rep.worst_error > st.worst_error) {
        st.worst_error = rep.worst_error;
        st.worst_k = ks[i];
      }
      if (rep.disagree_unflagged > 0) {
        json f = detail::failure_head(scene, i1, i2, ks[i], X, "derivative_disagreement");
        f["error"] = rep.worst_error;
        f["pivot_ratio"] = rep.worst_pivot_ratio;
        f["h"] = opt.h;
        f["tolerance"] = opt.tolerance;
        fs[t].push_back(std::move(f));
      }
    }
  });
  DerivativeStats total;
  for (int t = 0; t < nt; ++t) {
    total.merge(sts[t]);
    for (auto& f : fs[t]) failures.push_back(std::move(f));
  }
  return total;
}

int replay_agreement_record(const json& f, const Shape& b1, const Shape& b2, const SolverOptions& opt) {
  const Pose X = pose_from_json(f.at("pose"));
  const std::string kind = f.at("kind");
  if (kind == "derivative_disagreement") {
    DerivativeCheckOptions o;
    o.h = f.at("h");
    o.tolerance = f.at("tolerance");
    const DerivativeCheckReport rep = check_derivatives(b1, b2, {X}, o);
    std::printf("derivatives: converged %d, agree %d, disagree unflagged %d (flagged %d), error %.3e\n", rep.converged,
                rep.agree, rep.disagree_unflagged, rep.disagree_flagged, rep.worst_error);
    for (const auto& l : rep.failures) std::printf("  %s\n", l.c_str());
    const bool same = rep.disagree_unflagged > 0;
    std::printf("%s\n", same ? "reproduced" : "NOT reproduced (derivatives agree now)");
    return same ? 0 : 3;
  }
  return detail::replay_baseline_disagreement(X, b1, b2, opt);
}

}  // namespace idcol::harness
