#include "idcol_harness/agreement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol_harness/poses.hpp"
#include "idcol_harness/runner.hpp"

#ifdef IDCOL_HARNESS_WITH_BASELINES
#include "idcol_baselines/baselines.hpp"
#endif

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

bool baselines_available() {
#ifdef IDCOL_HARNESS_WITH_BASELINES
  return true;
#else
  return false;
#endif
}

std::uint64_t baseline_aborts_trapped() {
#ifdef IDCOL_HARNESS_WITH_BASELINES
  return baselines::trapped_aborts();
#else
  return 0;
#endif
}

bool BaselineSpec::has(const std::string& m) const { return std::find(methods.begin(), methods.end(), m) != methods.end(); }
bool BaselineSpec::covers(int i1, int i2) const { return std::find(pairs.begin(), pairs.end(), std::pair{i1, i2}) != pairs.end(); }
bool DerivativeSpec::covers(int i1, int i2) const { return std::find(pairs.begin(), pairs.end(), std::pair{i1, i2}) != pairs.end(); }

const std::vector<std::string>& boolean_methods() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
#ifdef IDCOL_HARNESS_WITH_BASELINES
    for (const baselines::Competitor* c : baselines::competitors()) n.emplace_back(c->name);
#endif
    return n;
  }();
  return names;
}

std::string method_label(const std::string& m) {
#ifdef IDCOL_HARNESS_WITH_BASELINES
  if (const baselines::Competitor* c = baselines::find_competitor(m)) return c->label;
#endif
  return m;
}

bool answers_gap([[maybe_unused]] const std::string& m) {
#ifdef IDCOL_HARNESS_WITH_BASELINES
  if (const baselines::Competitor* c = baselines::find_competitor(m)) return c->answers.signed_distance;
#endif
  return false;
}

std::vector<std::string> in_report_order(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const auto& m : boolean_methods())
    if (std::find(names.begin(), names.end(), m) != names.end()) out.push_back(m);
  for (const auto& m : names)
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  return out;
}

std::string known_methods() {
  std::string t;
  for (const auto& m : boolean_methods()) t += m + ", ";
  return t + "oracle";
}

AgreementVerdict classify_answer(bool idcol_collide, bool baseline_collide, bool baseline_failed, bool oracle_ok, double lo,
                                 double hi, double tol) {
  if (baseline_failed) return AgreementVerdict::Failed;
  if (baseline_collide == idcol_collide) return AgreementVerdict::Agree;
  if (oracle_ok && lo * (1.0 - tol) <= 1.0 && 1.0 <= hi * (1.0 + tol)) return AgreementVerdict::Band;
  return AgreementVerdict::Genuine;  // also a NaN bracket: no comparison passes
}

bool in_widened_bracket(double alpha, double lo, double hi, double tol) { return lo * (1.0 - tol) <= alpha && alpha <= hi * (1.0 + tol); }

namespace {
const std::vector<std::string>& kBooleanMethods = boolean_methods();
}  // namespace

bool baseline_serves(const std::string& m, const Shape& b1, const Shape& b2, std::string* why) {
  if (m != "oracle" && std::find(kBooleanMethods.begin(), kBooleanMethods.end(), m) == kBooleanMethods.end()) {
    if (why) *why = "unknown method (expected one of: " + known_methods() + ")";
    return false;
  }
#ifdef IDCOL_HARNESS_WITH_BASELINES
  if (m == "oracle") {
    if (baselines::oracle_for(b1, b2) != baselines::OracleMethod::None) return true;
    if (why) *why = "no exact oracle for " + describe(b1) + " with " + describe(b2) + " (exact ellipsoids and polytopes only)";
    return false;
  }
  return baselines::can_serve(baselines::competitor(m), b1, b2, why);
#else
  (void)b1;
  (void)b2;
  if (why) *why = "this build has no baselines (configured with -DIDCOL_BUILD_BASELINES=OFF)";
  return false;
#endif
}

// ---------------------------------------------------------------- statistics

namespace {
// The counts of StatusAgreement and DerivativeStats (Fields, stats.hpp).
const Fields<StatusAgreement> kStatusCounts = {{"queries", &StatusAgreement::queries}, {"agree", &StatusAgreement::agree},
                                               {"band", &StatusAgreement::band}, {"genuine", &StatusAgreement::genuine},
                                               {"failed", &StatusAgreement::failed}};
// The count of each AgreementVerdict, in its declaration order (run_agreement).
[[maybe_unused]] std::uint64_t StatusAgreement::* const kVerdictCounts[] = {&StatusAgreement::agree, &StatusAgreement::band,
                                                           &StatusAgreement::genuine, &StatusAgreement::failed};
const Fields<DerivativeStats> kDerivativeCounts = {
    {"poses", &DerivativeStats::poses},   {"converged", &DerivativeStats::converged},
    {"fd_failed", &DerivativeStats::fd_failed}, {"agree", &DerivativeStats::agree},
    {"disagree_flagged", &DerivativeStats::disagree_flagged}, {"disagree_unflagged", &DerivativeStats::disagree_unflagged},
    {"flagged", &DerivativeStats::flagged}};
// AgreementStats: its counts, its alpha* and normal error histograms (written
// as err_summary), and the counts and seconds of its "timing" object.
const Fields<AgreementStats> kAgreementCounts = {
    {"poses", &AgreementStats::poses}, {"idcol_not_converged", &AgreementStats::idcol_not_converged},
    {"oracle_failed", &AgreementStats::oracle_failed}, {"idcol_outside_bracket", &AgreementStats::idcol_outside_bracket},
    {"normal_poses", &AgreementStats::normal_poses}};
const Fields<AgreementStats, LogHistogram> kErrorHistograms = {{"alpha_abs_err", &AgreementStats::alpha_abs_err},
                                                              {"alpha_rel_err", &AgreementStats::alpha_rel_err},
                                                              {"normal_angle_rad", &AgreementStats::normal_angle}};
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
  json j = {{"status", st}};
  write_fields(*this, j, kAgreementCounts);
  for (const auto& [key, h] : kErrorHistograms) j[key] = err_summary(this->*h);

  std::uint64_t g = idcol_outside_bracket;
  for (const auto& [k, v] : status) g += v.genuine;
  j["genuine_total"] = g;
  json tm = json::object();
  for (const auto& [k, h] : time) {
    const std::uint64_t wrong = timed_wrong.count(k) ? timed_wrong.at(k) : 0;
    auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    tm[k] = {{"count", h.count()},         {"wrong", wrong},
             {"median_ns", num(h.quantile(0.5))}, {"p90_ns", num(h.quantile(0.9))},
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
  const json& t = j.at("timing");
  read_fields(s, t, kTimingCounts);
  read_fields(s, t, kTimingSeconds);
  for (const auto& [k, v] : t.at("methods").items()) {
    s.time.emplace(k, LogHistogram::from_json(v.at("histogram")));
    s.timed_wrong[k] = v.at("wrong");
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
  j.update({{"agreement", agreement()}, {"worst_error", worst_error}, {"worst_k", worst_k}});
  return j;
}
DerivativeStats DerivativeStats::from_json(const json& j) {
  DerivativeStats s;
  read_fields(s, j, kDerivativeCounts);
  s.worst_error = j.at("worst_error");
  s.worst_k = j.at("worst_k");
  return s;
}

// ---------------------------------------------------------------- passes

namespace {
json failure_head(const Scene& scene, int i1, int i2, std::uint64_t k, const Pose& X, const char* kind) {
  const ShapeSpec& s1 = scene.shapes[i1];
  const ShapeSpec& s2 = scene.shapes[i2];
  json f = failure_record({s1.name, s2.name, &*s1.shape, &*s2.shape, "cold", k, to_string(scene.generator)}, X);
  f["kind"] = kind;
  f["t"] = static_cast<double>(k) * scene.dt;
  return f;
}

}  // namespace

AgreementStats run_agreement(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                             double overhead_ns, json& failures) {
  AgreementStats total;
#ifdef IDCOL_HARNESS_WITH_BASELINES
  const Shape& b1 = *scene.shapes[i1].shape;
  const Shape& b2 = *scene.shapes[i2].shape;
  const BaselineSpec& spec = scene.baselines;
  const PoseGenerator gen(scene.generator, radial_range(b1, b2), scene.dt);
  const double tol = spec.band_tolerance;
  std::vector<std::string> booleans;
  for (const auto& m : kBooleanMethods)
    if (spec.has(m)) booleans.push_back(m);
  const std::uint64_t n_timed = scene.record.timing ? std::min<std::uint64_t>(spec.timing_poses, hi - lo) : 0;
  // wrong[m][k - lo] for the timed subset: the method's answer there was genuine-wrong or failed.
  std::map<std::string, std::vector<char>> wrong;
  for (const auto& m : booleans) wrong[m].assign(n_timed, 0);
  for (const char* m : {"idcol_cold", "idcol_warm", "oracle"}) wrong[m].assign(n_timed, 0);

  std::vector<AgreementStats> sts(std::max(1, threads));
  std::vector<json> fs(std::max(1, threads), json::array());
  run_in_chains(lo, hi, 1, threads, [&](int t, std::uint64_t a, std::uint64_t b) {
    const baselines::BaselinePair bp(b1, b2);
    AgreementStats& st = sts[t];
    for (const auto& m : booleans) st.status[m];
    for (std::uint64_t k = a; k < b; ++k) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      const Pose X = gen(k);
      ++st.poses;
      const SolveResult r = solve(b1, b2, X, scene.solver);
      const baselines::OracleAnswer o = bp.oracle(X);
      const bool in_subset = k - lo < n_timed;
      if (!o.ok) {
        ++st.oracle_failed;
        if (in_subset) wrong["oracle"][k - lo] = 1;
      }
      if (r.status != SolveStatus::Converged) {
        ++st.idcol_not_converged;
        if (in_subset) wrong["idcol_cold"][k - lo] = wrong["idcol_warm"][k - lo] = 1;
        continue;  // the solve failure itself is counted by the cold/warm passes
      }
      const std::array<double, 2> br = o.ok ? bp.smoothing_bracket(o) : std::array<double, 2>{NAN, NAN};
      json f = failure_head(scene, i1, i2, k, X, "baseline_disagreement");
      f["idcol_alpha"] = r.alpha;
      f["oracle_alpha"] = o.ok ? json(o.alpha) : json(nullptr);
      f["bracket"] = o.ok ? json({br[0], br[1]}) : json(nullptr);
      bool bad = false;
      json disagreeing = json::array();
      if (o.ok) {
        const double e = std::abs(r.alpha - o.alpha);
        st.alpha_abs_err.add(e);
        st.alpha_rel_err.add(e / o.alpha);
        if (!in_widened_bracket(r.alpha, br[0], br[1], tol)) {
          ++st.idcol_outside_bracket;
          if (in_subset) wrong["idcol_cold"][k - lo] = wrong["idcol_warm"][k - lo] = 1;
          disagreeing.push_back("idcol_outside_bracket");
          bad = true;
        }
      }
      const bool idcol_collide = r.alpha < 1.0;
      for (const auto& m : booleans) {
        const baselines::Competitor& comp = baselines::competitor(m);
        const baselines::BaselineAnswer ans = bp.run(comp, X);
        StatusAgreement& sa = st.status[m];
        ++sa.queries;
        // intersect is each competitor's boolean (FCL distance: distance <= 0).
        const AgreementVerdict v = classify_answer(idcol_collide, ans.intersect, ans.failed || ans.threw, o.ok, br[0], br[1], tol);
        ++(sa.*kVerdictCounts[static_cast<int>(v)]);
        if (in_subset && v >= AgreementVerdict::Genuine) wrong[m][k - lo] = 1;
        if (v == AgreementVerdict::Genuine) {
          bad = true;
          disagreeing.push_back({{"method", m},
                                 {"intersect", ans.intersect},
                                 {"signed_distance", ans.has_distance ? json(ans.signed_distance) : json(nullptr)}});
        }
        if (comp.answers.normal && ans.has_normal && !ans.failed && !ans.threw &&
            std::abs(r.alpha - 1.0) <= spec.near_contact) {
          const Vec3 n_idcol = contact_kinematics(r).nhat_1;
          const double c = std::clamp(n_idcol.normalized().dot(ans.normal_1.normalized()), -1.0, 1.0);
          st.normal_angle.add(std::acos(c));
          ++st.normal_poses;
        }
      }
      if (bad) {
        f["disagreeing"] = disagreeing;
        fs[t].push_back(std::move(f));
      }
    }
  });
  for (int t = 0; t < std::max(1, threads); ++t) {
    total.merge(sts[t]);
    for (auto& f : fs[t]) failures.push_back(std::move(f));
  }
  for (const auto& m : booleans) total.status[m];

  // Timing on the first n_timed poses, one method at a time, same poses for all.
  if (n_timed > 0) {
    const baselines::BaselinePair bp(b1, b2);
    std::vector<Pose> Xs(n_timed);
    for (std::uint64_t i = 0; i < n_timed; ++i) Xs[i] = gen(lo + i);
    const auto w0 = Clock::now();
    const double c0 = thread_cpu_seconds();
    auto time_method = [&](const std::string& name, auto&& query) {
      LogHistogram h{0, 10, 100};
      for (std::uint64_t i = 0; i < std::min<std::uint64_t>(n_timed, 100); ++i) query(i);  // warm-up
      for (std::uint64_t i = 0; i < n_timed; ++i) {
        const auto t0 = Clock::now();
        query(i);
        const auto t1 = Clock::now();
        h.add(std::chrono::duration<double, std::nano>(t1 - t0).count() - overhead_ns);
      }
      total.time.emplace(name, h);
      std::uint64_t nw = 0;
      for (char c : wrong[name]) nw += c;
      total.timed_wrong[name] = nw;
    };
    volatile double sink = 0.0;
    time_method("idcol_cold", [&](std::uint64_t i) { sink = solve(b1, b2, Xs[i], scene.solver).alpha; });
    {
      WarmStart ws;
      time_method("idcol_warm", [&](std::uint64_t i) {
        if (i == 0) ws.reset();
        sink = solve(b1, b2, Xs[i], scene.solver, &ws).alpha;
      });
    }
    for (const auto& m : booleans) {
      const baselines::PreparedPair& pp = bp.prepared(baselines::competitor(m));
      time_method(m, [&](std::uint64_t i) { sink = pp.run(Xs[i]).intersect ? 1.0 : 0.0; });
    }
    if (spec.has("oracle")) time_method("oracle", [&](std::uint64_t i) { sink = bp.oracle(Xs[i]).alpha; });
    (void)sink;
    total.timed_poses = n_timed;
    total.timing_cpu_seconds = thread_cpu_seconds() - c0;
    total.timing_wall_seconds = std::chrono::duration<double>(Clock::now() - w0).count();
  }
#else
  (void)scene, (void)i1, (void)i2, (void)lo, (void)hi, (void)threads, (void)overhead_ns, (void)failures;
  throw std::runtime_error("this build has no baselines (configured with -DIDCOL_BUILD_BASELINES=OFF)");
#endif
  return total;
}

DerivativeStats run_derivatives(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                                json& failures) {
  const Shape& b1 = *scene.shapes[i1].shape;
  const Shape& b2 = *scene.shapes[i2].shape;
  const PoseGenerator gen(scene.generator, radial_range(b1, b2), scene.dt);
  const std::uint64_t every = scene.derivatives.every;
  std::vector<std::uint64_t> ks;
  for (std::uint64_t k = (lo + every - 1) / every * every; k < hi; k += every) ks.push_back(k);
  DerivativeCheckOptions opt;
  opt.h = scene.derivatives.h;
  opt.tolerance = scene.derivatives.tolerance;
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
        json f = failure_head(scene, i1, i2, ks[i], X, "derivative_disagreement");
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
#ifdef IDCOL_HARNESS_WITH_BASELINES
  const SolveResult r = solve(b1, b2, X, opt);
  const baselines::BaselinePair bp(b1, b2);
  const baselines::OracleAnswer o = bp.oracle(X);
  std::printf("idcol: status %s alpha %.17g (collide %d)\n", to_string(r.status), r.alpha, r.alpha < 1.0 ? 1 : 0);
  if (o.ok) {
    const auto br = bp.smoothing_bracket(o);
    std::printf("oracle (%s): alpha %.17g, smoothing bracket [%.17g, %.17g]\n", baselines::to_string(o.method), o.alpha,
                br[0], br[1]);
  } else {
    std::printf("oracle failed: %s\n", o.error.c_str());
  }
  for (const auto& m : kBooleanMethods) {
    const auto a = bp.run(baselines::competitor(m), X);
    std::printf("%-13s intersect %d  signed distance %.6g  %s\n", m.c_str(), a.intersect ? 1 : 0, a.signed_distance,
                a.failed || a.threw ? ("failed: " + a.error).c_str() : "");
  }
  return 0;
#else
  (void)b1, (void)b2, (void)opt;
  std::printf("this build has no baselines; cannot replay a baseline disagreement\n");
  return 2;
#endif
}

}  // namespace idcol::harness
