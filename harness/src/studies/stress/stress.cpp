// The stress suite: see stress.hpp for the scene schema and the checks.
#include "studies/stress/stress.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "referee/checks.hpp"
#include "gen/poses.hpp"
#include "exec/chains.hpp"
#include "stats/stats.hpp"
#include "io/files.hpp"
#include "studies/entry_shards.hpp"
#include "studies/stress/stress_keys.hpp"
#include "studies/stress/stress_tally.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double pair_length(const Scene& s, const StressCase& c) {
  return radii(*s.shapes[c.body1].shape).outer + radii(*s.shapes[c.body2].shape).outer;
}

// co: the case's oracles (read only for kind Touching).
Pose stress_pose_with(const Scene& s, const StressCase& c, const AnswerChecker* co, std::uint64_t k, TouchReference* ref,
                      double* expected_alpha) {
  if (expected_alpha) *expected_alpha = kNaN;
  if (c.kind == StressKind::Explicit) return c.explicit_poses.at(k);
  // The pose families live in the pose library; a new kind adds its generator there and a case here.
  if (c.kind == StressKind::RandomBodies) return random_body_pose(c.random, k).X_12;
  const double L = pair_length(s, c);
  if (c.kind == StressKind::Shell) return shell_pose(k, L, c.rmin, c.rmax, c.zero_every);
  // Touching: an orientation family at |r| = L, then scaled by the independent oracle's answer there.
  Pose X = touching_pose(k, c.orientation, L);
  TouchReference t = co->reference(X);
  if (!t.ok) {  // the caller records the failed reference
    if (ref) *ref = t;
    return X;
  }
  // alpha* is homogeneous of degree 1 in r: scale the bracket with the pose.
  const double eps = c.touch_eps[k % c.touch_eps.size()];
  const double a_ref = 0.5 * (t.lo + t.hi), scale = (1.0 + eps) / a_ref;
  X.p = X.p * scale;
  t.lo *= scale, t.hi *= scale;
  if (ref) *ref = t;
  if (expected_alpha) *expected_alpha = 1.0 + eps;
  return X;
}
}  // namespace

void limit_stress_poses(Scene& s, std::uint64_t max_poses) {
  for (StressCase& c : s.spec.as<StressSpec>().cases) {
    c.poses = std::min(c.poses, max_poses);
    if (c.explicit_poses.size() > c.poses) c.explicit_poses.resize(c.poses);
  }
}

Pose stress_pose(const Scene& s, const StressCase& c, std::uint64_t k, TouchReference* ref, double* expected_alpha) {
  if (c.kind != StressKind::Touching) return stress_pose_with(s, c, nullptr, k, ref, expected_alpha);
  const AnswerChecker co(*s.shapes[c.body1].shape, *s.shapes[c.body2].shape, c.oracle, s.solver);
  return stress_pose_with(s, c, &co, k, ref, expected_alpha);
}

void StressTally::merge(const StressTally& o) {
  pass.merge(o.pass);
  if (o.checks.worst_alpha_error > checks.worst_alpha_error ||
      (o.checks.worst_alpha_error == checks.worst_alpha_error && o.worst_alpha_k < worst_alpha_k))
    worst_alpha_k = o.worst_alpha_k;
  checks.merge(o.checks);
  using T = StressTally;
  for (auto n : {&T::genuine, &T::concentric_expected, &T::concentric_wrong, &T::false_touch, &T::reference_failed,
                 &T::oracle_checked, &T::iter_sum_converged, &T::unreliable})
    this->*n += o.*n;
  for (auto w : {&T::worst_residual, &T::worst_surface_allowance, &T::worst_normal_allowance, &T::worst_oracle_error,
                 &T::worst_bracket_violation, &T::max_bracket_width, &T::worst_touch_error, &T::max_sensitivity})
    this->*w = std::max(this->*w, o.*w);
  min_pivot = std::min(min_pivot, o.min_pivot);
  for (const auto& [d, n] : o.pivot_decades) pivot_decades[d] += n;
  solve_seconds += o.solve_seconds;
}

json StressTally::to_json() const {
  const std::uint64_t solves = pass.solves;
  json st = json::object();
  for (int i = 0; i < kNumSolveStatuses; ++i)
    if (pass.by_status[i]) st[to_string(static_cast<SolveStatus>(i))] = pass.by_status[i];
  json dec = json::object();
  for (const auto& [d, n] : pivot_decades) dec["1e" + std::to_string(d)] = n;
  const std::uint64_t conv = pass.converged();
  // The answer checks' counts as CheckCounts writes them, and the suite's own touching check.
  json false_convergence = checks.to_json().at(key::false_convergence);
  false_convergence["touching"] = false_touch;
  return {{key::solves, solves},
          {key::genuine, genuine},
          {key::genuine_rate, solves ? static_cast<double>(genuine) / solves : 0.0},
          {"by_status", st},
          {key::failures, solves - genuine},
          {key::concentric, {{"expected", concentric_expected}, {key::wrong, concentric_wrong}}},
          {key::false_convergence, false_convergence},
          {key::reference_solve_failed, reference_failed},
          {key::oracle,
           {{key::checked, oracle_checked},
            {key::oracle_failed, checks.oracle_failed},
            {key::worst_relative_error, worst_oracle_error},
            {key::worst_bracket_violation, worst_bracket_violation},
            {"max_bracket_width", max_bracket_width}}},
          {key::worst_residual, worst_residual},
          {key::worst_surface_error, checks.worst_surface},
          {key::worst_normal_error, checks.worst_normal},
          {"worst_surface_rounding_allowance", worst_surface_allowance},
          {"worst_normal_rounding_allowance", worst_normal_allowance},
          {"worst_touching_error", worst_touch_error},
          {key::worst_alpha_error, {{"value", checks.worst_alpha_error}, {"k", worst_alpha_k}}},
          {key::iterations,
           {{key::mean, solves ? json(static_cast<double>(pass.iter_sum) / solves) : json(nullptr)},  // over every solve
            {"mean_converged", conv ? json(static_cast<double>(iter_sum_converged) / conv) : json(nullptr)},
            {key::max, pass.iter_max}}},
          {"warm_fell_back", pass.warm_fell_back},
          {"used_continuation", pass.used_continuation},
          {"restarts", pass.restarts},
          {key::conditioning,
           {{"min_pivot_ratio", min_pivot},
            {"max_sensitivity", max_sensitivity},
            {key::unreliable, unreliable},
            {"pivot_ratio_decades", dec}}},
          {"time", {{"solve_seconds", solve_seconds}, {"mean_us", solves ? 1e6 * solve_seconds / solves : 0.0}}}};
}

AnswerCheck StressTally::check(const AnswerChecker& checker, const Pose& X, const SolveResult& r, std::uint64_t k, bool with_oracle,
                               double expected_alpha, const TouchReference& touch, std::optional<OracleVerdict>* memo) {
  AnswerCheck out;
  pass.add(r, false, 0.0);
  if (r.status == SolveStatus::Converged) iter_sum_converged += r.iterations;
  if (X.p.squaredNorm() == 0.0) {
    concentric_expected++;
    if (r.status == SolveStatus::Concentric) {
      genuine++;
    } else {
      concentric_wrong++;
      out.problem = "concentric pose (r = 0) not reported Concentric";
    }
    return out;
  }
  if (!r.converged()) {
    out.problem = std::string("status ") + to_string(r.status);
    return out;
  }
  worst_residual = std::max(worst_residual, r.residual_norm);
  if (with_oracle && memo && !*memo) *memo = checker.oracle_verdict(X);
  out = checker.check(X, r, with_oracle, expected_alpha, touch, with_oracle && memo ? &**memo : nullptr);
  if (out.alpha_error > checks.worst_alpha_error) worst_alpha_k = k;
  checks.add(out);
  worst_surface_allowance = std::max(worst_surface_allowance, out.surface_allowance);
  worst_normal_allowance = std::max(worst_normal_allowance, out.normal_allowance);
  if (std::isfinite(out.touching_error)) worst_touch_error = std::max(worst_touch_error, out.touching_error);
  false_touch += out.touching_failed;
  oracle_checked += out.oracle_checked;
  if (std::isfinite(out.oracle_error)) worst_oracle_error = std::max(worst_oracle_error, out.oracle_error);
  if (std::isfinite(out.bracket_violation)) worst_bracket_violation = std::max(worst_bracket_violation, out.bracket_violation);
  if (std::isfinite(out.bracket_width)) max_bracket_width = std::max(max_bracket_width, out.bracket_width);
  // KKT conditioning at the answer.
  const SolutionSensitivity sens = solution_sensitivity(r);
  const double pr = sens.cond.pivot_ratio;
  min_pivot = std::min(min_pivot, pr);
  max_sensitivity = std::max(max_sensitivity, std::isfinite(sens.cond.sensitivity) ? sens.cond.sensitivity : 1e308);
  if (!sens.cond.reliable) unreliable++;
  pivot_decades[pr > 0.0 ? static_cast<int>(std::floor(std::log10(pr))) : -400]++;
  genuine += out.genuine();
  return out;
}

namespace {
/// The failure record of pose k of an ordinary case (its two shapes of [shapes]).
json failure_record(const Scene& s, const StressCase& c, Pass pass, std::uint64_t k, const Pose& X,
                    const SolveResult* r, const WarmStart* before, const std::string& problem, double oracle_alpha,
                    double expected_alpha) {
  const ShapeSpec &s1 = s.shapes[c.body1], &s2 = s.shapes[c.body2];
  return stress_failure_record(c, {s1.name, s2.name, &*s1.shape, &*s2.shape, to_string(pass), k, std::string("stress:") + to_string(c.kind)},
                               X, r, before, problem, oracle_alpha, expected_alpha);
}

}  // namespace

json stress_failure_record(const StressCase& c, const FailureSite& site, const Pose& X, const SolveResult* r,
                           const WarmStart* before, const std::string& problem, double oracle_alpha, double expected_alpha) {
  json f = harness::failure_record(site, X, r, before);
  f["case"] = c.name;
  f["problem"] = problem;
  f["oracle_alpha"] = std::isfinite(oracle_alpha) ? json(oracle_alpha) : json(nullptr);
  f["expected_alpha"] = std::isfinite(expected_alpha) ? json(expected_alpha) : json(nullptr);
  return f;
}

void run_case_passes(const StressCase& c, const std::vector<std::string>& names, std::uint64_t chain, int threads,
                     const StudyOptions& opt, const std::function<void(std::uint64_t, std::uint64_t, StressShare&)>& run_range,
                     json& cj, json& failures) {
  std::vector<StressShare> shares(threads, StressShare(names.size()));
  run_in_chains(0, c.poses, chain, threads, [&](int t, std::uint64_t lo, std::uint64_t hi) { run_range(lo, hi, shares[t]); });
  for (std::size_t i = 0; i < names.size(); ++i) {
    StressTally total;
    double cpu = 0.0;
    json kept = json::array();
    for (StressShare& sh : shares) {  // threads took whole chains in order: records stay in pose order
      total.merge(sh.tallies[i]);
      cpu += sh.cpu[i];
      for (json& f : sh.fails[i])
        if (kept.size() < opt.max_failures) kept.push_back(std::move(f));
    }
    json pj = total.to_json();
    pj["time"]["cpu_seconds"] = cpu;
    pj["failure_records_kept"] = kept.size();
    append_failures(failures, std::move(kept), opt.failures_path);
    cj["passes"][names[i]] = pj;
  }
}

namespace {

/// A case's entry in the results file before its passes run: what it
/// solves and how its poses are made.
json case_header(const Scene& s, const StressCase& c, const Shape& b1, const Shape& b2) {
  json cj = {{"name", c.name},
             {"body1", s.shapes[c.body1].name},
             {"body2", s.shapes[c.body2].name},
             {"shape1", describe(b1)},
             {"shape2", describe(b2)},
             {"kind", to_string(c.kind)},
             {"poses", c.poses},
             {"L", pair_length(s, c)},
             {"oracle", to_string(c.oracle)},
             {"oracle_every", c.oracle_every},
             {"passes", json::object()}};
  if (c.kind == StressKind::Shell)
    cj["shell"] = {{"rmin", c.rmin}, {"rmax", c.rmax}, {"zero_every", c.zero_every}};
  if (c.kind == StressKind::Touching) cj["touching"] = {{"orientation", to_string(c.orientation)}, {"eps", c.touch_eps}};
  return cj;
}

/// Derivatives against finite differences on an evenly spaced subsample of
/// the case's poses (c.derivative_samples of them).
json case_derivatives(const Scene& s, const StressCase& c, const Shape& b1, const Shape& b2, const AnswerChecker& oracles) {
  std::vector<Pose> sample;
  std::vector<std::uint64_t> ks;
  // Finite differences step the pose by h L (DerivativeCheckOptions::h):
  // they mean something only while that is small against |r| and the
  // answer is not swamped by rounding, so poses with |r| outside
  // [1e-3 L, 1e3 L] (and r = 0, where no derivative exists) are skipped.
  const std::uint64_t m = std::min<std::uint64_t>(c.derivative_samples, c.poses);
  const double L = pair_length(s, c);
  std::uint64_t skipped = 0;
  const std::uint64_t candidates = std::min<std::uint64_t>(c.poses, 8 * m);
  for (std::uint64_t j = 0; j < candidates && sample.size() < m; ++j) {
    const std::uint64_t k = j * c.poses / candidates;
    const Pose X = stress_pose_with(s, c, &oracles, k, nullptr, nullptr);
    const double rr = X.p.norm() / L;
    if (!(rr >= 1e-3 && rr <= 1e3)) {
      ++skipped;
      continue;
    }
    sample.push_back(X);
    ks.push_back(k);
  }
  DerivativeCheckOptions dopt;
  dopt.solver.max_iterations = s.solver.max_iterations;
  dopt.solver.max_restarts = s.solver.max_restarts;
  dopt.solver.continuation = s.solver.continuation;
  const DerivativeCheckReport rep = check_derivatives(b1, b2, sample, dopt);
  json fl = json::array();
  for (std::size_t i = 0; i < rep.failures.size() && i < 20; ++i) fl.push_back(rep.failures[i]);
  return {{"poses", rep.poses},
          {"skipped_outside_fd_range", skipped},
          {"converged", rep.converged},
          {"fd_failed", rep.fd_failed},
          {"agree", rep.agree},
          {key::agreement, rep.converged - rep.fd_failed > 0 ? rep.agreement() : 0.0},
          {"disagree_flagged", rep.disagree_flagged},
          {key::disagree_unflagged, rep.disagree_unflagged},
          {"flagged", rep.flagged},
          {key::worst_error_unflagged, rep.worst_error},
          {"step", dopt.h},
          {"tolerance", dopt.tolerance},
                       {"disagreements", fl}};
}

/// Pass i of case c at pose k (pose X, its touching reference and expected
/// alpha*), with its warm start ws: the solve timed into the pass's tally,
/// its answer checked, and a failed reference or a wrong answer kept as a
/// failure record while the pass has fewer than opt.max_failures.
void stress_solve(const Scene& s, const StressCase& c, const AnswerChecker& oracles, const StudyOptions& opt, std::size_t i,
                  std::uint64_t k, const Pose& X, const TouchReference& ref, double expected, WarmStart& ws, StressShare& sh) {
  const double cpu0 = thread_cpu_seconds();
  StressTally& st = sh.tallies[i];
  std::vector<json>& fails = sh.fails[i];
  const bool warm = c.passes[i] == Pass::Warm;
  if (k % c.warm_chain == 0) ws.reset();
  if (c.kind == StressKind::Touching && !ref.ok) {
    st.reference_failed++;
    if (fails.size() < opt.max_failures)
      fails.push_back(failure_record(s, c, Pass::Cold, k, X, nullptr, nullptr,
                                     "the touching construction's oracle (" + ref.method + ") failed: " + ref.error, kNaN, kNaN));
  }
  const WarmStart before = ws;
  const auto t0 = Clock::now();
  const SolveResult r = solve(*s.shapes[c.body1].shape, *s.shapes[c.body2].shape, X, s.solver, warm ? &ws : nullptr);
  st.solve_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  const AnswerCheck ch = st.check(oracles, X, r, k, k % c.oracle_every == 0, expected, ref);
  if (!ch.genuine() && fails.size() < opt.max_failures)
    fails.push_back(failure_record(s, c, c.passes[i], k, X, &r, warm ? &before : nullptr, ch.problem, ch.oracle_alpha, expected));
  sh.cpu[i] += thread_cpu_seconds() - cpu0;
}

/// One case of fixed bodies: every pose through each of its passes, on
/// `threads` threads taking whole chains (run_case_passes), then its
/// derivatives on a subsample. Returns the case's entry; its failure
/// records are appended to `failures`.
json run_case(const Scene& s, const StressCase& c, const StudyOptions& opt, int threads, json& failures) {
  const auto case0 = Clock::now();
  const Shape& b1 = *s.shapes[c.body1].shape;
  const Shape& b2 = *s.shapes[c.body2].shape;
  json cj = case_header(s, c, b1, b2);
  const AnswerChecker oracles(b1, b2, c.oracle, s.solver);  // built once, read by every thread
  std::vector<std::string> names;
  for (const Pass pass : c.passes) names.emplace_back(to_string(pass));
  auto run_range = [&](std::uint64_t lo, std::uint64_t hi, StressShare& sh) {
    std::vector<WarmStart> ws(c.passes.size());
    for (std::uint64_t k = lo; k < hi; ++k) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      TouchReference ref;
      double expected = kNaN;
      const Pose X = stress_pose_with(s, c, &oracles, k, &ref, &expected);
      for (std::size_t i = 0; i < c.passes.size(); ++i) stress_solve(s, c, oracles, opt, i, k, X, ref, expected, ws[i], sh);
    }
  };
  run_case_passes(c, names, c.warm_chain, threads, opt, run_range, cj, failures);
  if (c.derivative_samples > 0) cj["derivatives"] = case_derivatives(s, c, b1, b2, oracles);
  cj["wall_seconds"] = std::chrono::duration<double>(Clock::now() - case0).count();
  return cj;
}

/// The progress line before case number `done` (counting from 0) of the
/// suite: cases differ in cost by 1000x, so the estimate is by cases done.
void show_case_progress(const Scene& s, const StressCase& c, std::size_t done, Clock::time_point wall0) {
  const double el = std::chrono::duration<double>(Clock::now() - wall0).count();
  const std::size_t n = s.spec.as<StressSpec>().cases.size();
  const double eta = done > 0 ? el / done * (n - done) : 0.0;
  std::fprintf(stderr, "\rcase %zu/%zu %-32s %6.0f s elapsed, ~%.0f s left   ", done + 1, n, c.name.c_str(), el, eta);
  std::fflush(stderr);
}

}  // namespace

StressOutput run_stress(const Scene& s, const StudyOptions& opt) {
  StressOutput out;
  const auto wall0 = Clock::now();
  const int threads = std::max(1, opt.threads);
  std::vector<std::size_t> ran;  // the scene's indices of the shard's cases
  const std::vector<StressCase>& cases = s.spec.as<StressSpec>().cases;
  for (std::size_t scene_index = 0; scene_index < cases.size(); ++scene_index) {
    const StressCase& c = cases[scene_index];
    if (!in_shard(scene_index, opt.shard_index, opt.shard_count)) continue;
    if (opt.progress) show_case_progress(s, c, ran.size(), wall0);
    ran.push_back(scene_index);
    if (c.kind == StressKind::RandomBodies)  // bodies drawn per pose: random_bodies_stress.cpp
      out.cases.push_back(run_random_bodies_case(s, c, opt, out.failures));
    else
      out.cases.push_back(run_case(s, c, opt, threads, out.failures));
  }
  out.wall_seconds = std::chrono::duration<double>(Clock::now() - wall0).count();
  if (opt.shard_count > 1) out.shard = entry_shard_json(opt.shard_index, opt.shard_count, ran);
  if (opt.progress) std::fprintf(stderr, "\r%90s\r", "");
  return out;
}

json make_stress_results(const Scene& s, const StressOutput& out, const json& metadata) {
  json r = results_header(kStressSchema, metadata, {s.path, s.name, s.text}, s.solver);
  r.update(json{{"thresholds", CheckTolerances{}.to_json()},
          {"failure_records", out.failures.size()},
          {"wall_seconds", out.wall_seconds},
          {"cases", out.cases}});
  if (!out.shard.is_null()) r["shard"] = out.shard;
  return r;
}

namespace {
std::string num_or(const json& j) { return sci(j, 2); }

/// The report's title, the build that made it, and what "genuine" means
/// with the thresholds the suite used.
void stress_preamble(std::ostream& o, const json& R, const std::string& results_path) {
  const json& m = R.at("metadata");
  o << "# Stress suite: " << md_text(R.at("scene").at("name").get<std::string>()) << "\n\n";
  o << "Generated by " << md_code("idcol_harness stress-table " + results_path) << " from the results file alone.\n";
  const std::string rev = m.contains("git_revision") && m.at("git_revision").is_string() ? m.at("git_revision").get<std::string>()
                                                                                         : m.value("git_revision_configure", std::string("?"));
  o << "git " << md_text(rev) << (m.value("git_dirty", false) ? " (dirty)" : "") << ", " << md_text(m.value("compiler", std::string("?")))
    << ", " << md_text(m.value("build_type", std::string("?"))) << ", " << md_text(m.value("cpu_model", std::string("?"))) << ", threads "
    << m.value("threads", 1) << ", wall " << sci(R.at("wall_seconds").get<double>(), 3) << " s.\n\n";
  const json& th = R.at("thresholds");
  o << "A solve is *genuine* when its status is Converged (Concentric for r = 0 exactly) and it passes every check that "
       "does not trust the solver: witness points on both surfaces (|phi|/|grad phi| <= "
    << sci(th.at("surface").get<double>(), 1) << " of the outer radius), opposite unit normals (|n1 + n2| <= "
    << sci(th.at("normal").get<double>(), 1)
    << "); each limit plus the largest change of its measure over the rounding of the witness point's coordinates, which "
       "matters only where bodies differ in size by orders of magnitude; the oracle (closed form " << sci(th.at("closed_form").get<double>(), 1)
    << " rel., Perram-Wertheim " << sci(th.at("pw").get<double>(), 1)
    << " rel., polytope LP and support function: inside their brackets, independent phi for the surface checks), and for touching poses alpha* = 1 + eps (from an independent oracle) to "
    << sci(th.at("touching").get<double>(), 1)
    << ". A Converged status failing a check is a *false convergence*. Times are sums of per-solve wall times "
       "(unpinned, shared VM: indicative only).\n\n";
}

/// One row of the suite's table: pass `pname` (its figures p) of case c.
void pass_row(std::ostream& o, const json& c, const std::string& pname, const json& p) {
  std::string bys;
  for (const auto& [k, v] : p.at("by_status").items())
    if (k != "converged" && k != "concentric") bys += (bys.empty() ? "" : ", ") + k + " " + std::to_string(v.get<std::uint64_t>());
  if (p.at(key::reference_solve_failed).get<std::uint64_t>())
    bys += (bys.empty() ? "" : ", ") + std::string("reference ") + std::to_string(p.at(key::reference_solve_failed).get<std::uint64_t>());
  if (p.at(key::concentric).at(key::wrong).get<std::uint64_t>())
    bys += (bys.empty() ? "" : ", ") + std::string("r=0 not concentric ") + std::to_string(p.at(key::concentric).at(key::wrong).get<std::uint64_t>());
  const json& orc = p.at(key::oracle);
  std::string oracle = md_text(c.at("oracle").get<std::string>());
  if (oracle != "none") {
    oracle += " " + std::to_string(orc.at("checked").get<std::uint64_t>()) + ", ";
    oracle += oracle.rfind("lp", 0) == 0 || oracle.rfind("support", 0) == 0 ? "viol. " + num_or(orc.at(key::worst_bracket_violation)) + " (bracket <= " +
                                               num_or(orc.at("max_bracket_width")) + ")"
                                         : num_or(orc.at(key::worst_relative_error));
    if (orc.at(key::oracle_failed).get<std::uint64_t>()) oracle += ", oracle failed " + std::to_string(orc.at(key::oracle_failed).get<std::uint64_t>());
  }
  const json& fc = p.at(key::false_convergence);
  std::string fcs = std::to_string(fc.at(key::total).get<std::uint64_t>());
  if (fc.at(key::total).get<std::uint64_t>())
    fcs += " (s " + std::to_string(fc.at("surface").get<std::uint64_t>()) + ", n " + std::to_string(fc.at("normal").get<std::uint64_t>()) +
           ", o " + std::to_string(fc.at("oracle").get<std::uint64_t>()) + ", t " + std::to_string(fc.at("touching").get<std::uint64_t>()) + ")";
  const json& it = p.at(key::iterations);
  o << "| " << md_text(c.at("name").get<std::string>()) << " | " << md_text(c.at("body1").get<std::string>()) << " x "
    << md_text(c.at("body2").get<std::string>()) << " | " << md_text(c.at("kind").get<std::string>()) << " | " << md_text(pname) << " | "
    << p.at("solves").get<std::uint64_t>() << " | " << format("%.4f%%", 100.0 * p.at(key::genuine_rate).get<double>()) << " | " << (bys.empty() ? "0" : bys) << " | " << fcs << " | "
    << oracle << " | " << num_or(p.at(key::worst_residual)) << " | " << num_or(p.at(key::worst_surface_error)) << " / "
    << num_or(p.at(key::worst_normal_error)) << " | " << num_or(p.at(key::worst_alpha_error).at("value")) << " | "
    << num_or(p.at(key::conditioning).at("min_pivot_ratio")) << " | " << num_or(p.at(key::conditioning).at("max_sensitivity"))
    << " | " << p.at(key::conditioning).at(key::unreliable).get<std::uint64_t>() << " | "
    << format("%.1f / %d", it.at(key::mean).is_number() ? it.at(key::mean).get<double>() : NAN, it.at(key::max).get<int>()) << " | "
    << format("%.1f", p.at("time").at("mean_us").get<double>()) << " |\n";
}

/// The table of every case and pass, and the suite's totals.
void stress_cases_table(std::ostream& o, const json& R) {
  o << "| case | pair | kind | pass | solves | genuine | failed by status | false conv. | oracle (checked, worst) | worst residual | "
       "worst surface / normal | worst alpha err | min pivot | max sens. | unreliable | iters mean/max | mean us |\n";
  o << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::uint64_t total = 0, genuine = 0, falsec = 0;
  for (const json& c : R.at("cases")) {
    for (const auto& [pname, p] : c.at("passes").items()) {
      total += p.at("solves").get<std::uint64_t>();
      genuine += p.at(key::genuine).get<std::uint64_t>();
      falsec += p.at(key::false_convergence).at(key::total).get<std::uint64_t>();
      pass_row(o, c, pname, p);
    }
  }
  o << "\n**Total: " << genuine << " genuine of " << total << " solves; " << falsec << " false convergences; "
    << R.at("failure_records").get<std::uint64_t>() << " failure records.**\n\n";
}

/// The derivatives against finite differences, per case that checked them.
void stress_derivatives_table(std::ostream& o, const json& R) {
  o << "## Derivatives against finite differences (subsample per case)\n\n";
  o << "IFT sensitivity (rows x and alpha) against Richardson central differences through the SE(3) exponential "
       "(check_derivatives). *flagged*: Conditioning::reliable is false there.\n\n";
  o << "| case | poses | converged | FD solve failed | agree | disagree (flagged) | disagree (unflagged) | worst unflagged error |\n";
  o << "|---|---|---|---|---|---|---|---|\n";
  for (const json& c : R.at("cases")) {
    if (!c.contains("derivatives")) continue;
    const json& d = c.at("derivatives");
    o << "| " << md_text(c.at("name").get<std::string>()) << " | " << d.at("poses").get<int>() << " | " << d.at("converged").get<int>()
      << " | " << d.at("fd_failed").get<int>() << " | " << d.at("agree").get<int>() << " | " << d.at("disagree_flagged").get<int>()
      << " | " << d.at(key::disagree_unflagged).get<int>() << " | " << num_or(d.at(key::worst_error_unflagged)) << " |\n";
  }
}

/// Each case's kind, pose family and bodies.
void stress_case_list(std::ostream& o, const json& R) {
  o << "\n## Cases\n\n";
  for (const json& c : R.at("cases")) {
    o << "* **" << md_text(c.at("name").get<std::string>()) << "** (" << md_text(c.at("kind").get<std::string>());
    if (c.contains("shell"))
      o << ", |r|/L in [" << sci(c.at("shell").at("rmin").get<double>(), 2) << ", " << sci(c.at("shell").at("rmax").get<double>(), 2)
        << "]" << (c.at("shell").at("zero_every").get<std::uint64_t>() ? ", r = 0 every " + std::to_string(c.at("shell").at("zero_every").get<std::uint64_t>()) : "");
    if (c.contains("touching")) o << ", " << md_text(c.at("touching").at("orientation").get<std::string>());
    std::string shape1 = c.at("shape1").get<std::string>(), shape2 = c.at("shape2").get<std::string>();
    auto cut = [](std::string s) { return s.size() > 160 ? s.substr(0, 160) + " ...}" : s; };
    o << "): " << md_code(cut(shape1)) << " x " << md_code(cut(shape2)) << "\n";
  }
}
}  // namespace

/// The stress suite's Markdown report, from its results file alone.
std::string stress_markdown(const json& R, const std::string& results_path) {
  if (R.value("schema", "") != kStressSchema) throw std::runtime_error(results_path + ": not a stress results file");
  std::ostringstream o;
  stress_preamble(o, R, results_path);
  stress_cases_table(o, R);
  stress_derivatives_table(o, R);
  stress_case_list(o, R);
  return o.str();
}

}  // namespace idcol::harness
