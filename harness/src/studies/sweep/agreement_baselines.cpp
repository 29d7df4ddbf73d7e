// The agreement pass against the baselines (FCL, libccd, the exact oracle)
// and the replay of one of its disagreements: compiled where the baselines
// were built; agreement_none.cpp stands in for it where they were not.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "exec/chains.hpp"
#include "studies/sweep/sweep_keys.hpp"
#include "gen/poses.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol_baselines/baselines.hpp"
#include "io/record.hpp"
#include "studies/sweep/agreement.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

AgreementStats run_agreement(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                             double overhead_ns, json& failures) {
  AgreementStats total;
  const Shape& b1 = *scene.shapes[i1].shape;
  const Shape& b2 = *scene.shapes[i2].shape;
  const BaselineSpec& spec = scene.baselines;
  const PoseGenerator gen(scene.generator, radial_range(b1, b2), scene.dt);
  const double tol = spec.band_tolerance;
  std::vector<std::string> booleans;
  for (const auto& m : boolean_methods())
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
      json f = detail::failure_head(scene, i1, i2, k, X, "baseline_disagreement");
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
          disagreeing.push_back(key::idcol_outside_bracket);
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
        ++sa.of(v);
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
  return total;
}

namespace detail {
int replay_baseline_disagreement(const Pose& X, const Shape& b1, const Shape& b2, const SolverOptions& opt) {
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
  for (const auto& m : boolean_methods()) {
    const auto a = bp.run(baselines::competitor(m), X);
    std::printf("%-13s intersect %d  signed distance %.6g  %s\n", m.c_str(), a.intersect ? 1 : 0, a.signed_distance,
                a.failed || a.threw ? ("failed: " + a.error).c_str() : "");
  }
  return 0;
}
}  // namespace detail

}  // namespace idcol::harness
