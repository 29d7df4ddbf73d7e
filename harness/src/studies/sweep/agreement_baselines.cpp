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
#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol_baselines/baselines.hpp"
#include "io/record.hpp"
#include "io/text.hpp"
#include "studies/sweep/agreement.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

/// What the agreement pass over one pair reads at every pose: the scene,
/// the bodies, the poses, the baselines' settings, the boolean methods it
/// runs, and which answers on the timed poses [lo, lo + n_timed) were wrong
/// (wrong[method][k - lo]: a genuine disagreement or a failure, so that the
/// timing table shows "wrong" instead of a time).
struct AgreementRun {
  const Scene& scene;
  int i1, i2;
  const Shape& b1;
  const Shape& b2;
  const BaselineSpec& spec;
  PoseGenerator gen;
  std::vector<std::string> booleans;
  std::uint64_t lo, n_timed;
  std::map<std::string, std::vector<char>> wrong;
  /// Marks method m wrong at pose k, where k is a timed pose. Each pose is
  /// one thread's: the threads write different elements.
  void mark_wrong(const std::string& m, std::uint64_t k) {
    if (k - lo < n_timed) wrong.at(m)[k - lo] = 1;
  }
};

/// The alpha* of a method that solves for it, against the oracle's bracket
/// of the exact alpha* (its own bound allowed) and against iDCOL's smooth
/// alpha*, with its iteration count; true if it lies beyond its own bound
/// (a genuine disagreement, which marks it wrong on a timed pose).
bool compare_alpha(AgreementRun& run, const std::string& m, std::uint64_t k, const SolveResult& r, const baselines::OracleAnswer& o,
                   const baselines::BaselineAnswer& ans, MethodAnswerStats& an, json& disagreeing) {
  if (ans.iterations >= 0) an.iterations.add(ans.iterations);
  an.alpha_rel_diff_idcol.add(std::abs(ans.alpha - r.alpha) / r.alpha);
  if (!o.ok) return false;
  ++an.alpha_poses;
  const double out = std::max({0.0, o.alpha_lo - ans.alpha, ans.alpha - o.alpha_hi});
  an.alpha_rel_err.add(out / o.alpha);
  const double bound = std::isfinite(ans.alpha_bound) ? ans.alpha_bound : 0.0;
  if (out <= bound * (1.0 + run.spec.band_tolerance) + run.spec.band_tolerance * o.alpha) return false;
  ++an.alpha_outside_bound;
  run.mark_wrong(m, k);
  disagreeing.push_back({{"method", m}, {"alpha", ans.alpha}, {"alpha_bound", bound}, {"oracle_bracket", {o.alpha_lo, o.alpha_hi}}});
  return true;
}

/// Each boolean method's answer at pose X (iDCOL converged to r; o and its
/// smoothing bracket br from the oracle) into st; a genuine disagreement
/// goes to `disagreeing`. Also the angle between iDCOL's normal and the
/// method's, near contact. Returns whether any method disagreed genuinely.
bool compare_methods(AgreementRun& run, const baselines::BaselinePair& bp, std::uint64_t k, const Pose& X, const SolveResult& r,
                     const baselines::OracleAnswer& o, const std::array<double, 2>& br, AgreementStats& st, json& disagreeing) {
  bool bad = false;
  const bool idcol_collide = r.alpha < 1.0;
  for (const auto& m : run.booleans) {
    const baselines::Competitor& comp = baselines::competitor(m);
    const baselines::BaselineAnswer ans = bp.run(comp, X);
    StatusAgreement& sa = st.status[m];
    ++sa.queries;
    const bool answered = !ans.failed && !ans.threw;
    // A method that solves for alpha* to a tolerance disagrees with iDCOL's
    // status only beyond its own bound too.
    const double own = answered && ans.has_alpha && std::isfinite(ans.alpha_bound) ? ans.alpha_bound : 0.0;
    // intersect is each competitor's boolean (FCL distance: distance <= 0).
    const AgreementVerdict v =
        classify_answer(idcol_collide, ans.intersect, !answered, o.ok, br[0], br[1], run.spec.band_tolerance, own);
    ++sa.of(v);
    if (v >= AgreementVerdict::Genuine) run.mark_wrong(m, k);
    if (v == AgreementVerdict::Genuine) {
      bad = true;
      disagreeing.push_back({{"method", m},
                             {"intersect", ans.intersect},
                             {"signed_distance", ans.has_distance ? json(ans.signed_distance) : json(nullptr)},
                             {"alpha", ans.has_alpha ? json(ans.alpha) : json(nullptr)}});
    }
    if (!answered) continue;
    if (comp.answers.normal && ans.has_normal && std::abs(r.alpha - 1.0) <= run.spec.near_contact) {
      const Vec3 n_idcol = contact_kinematics(r).nhat_1;
      const double c = std::clamp(n_idcol.normalized().dot(ans.normal_1.normalized()), -1.0, 1.0);
      MethodAnswerStats& an = st.answers[m];
      an.normal_angle.add(std::acos(c));
      ++an.normal_poses;
    }
    if (ans.has_alpha) bad |= compare_alpha(run, m, k, r, o, ans, st.answers[m], disagreeing);
  }
  return bad;
}

/// Pose k: iDCOL's cold answer against the oracle's bracket and each
/// boolean method, into st; a pose with a genuine disagreement becomes a
/// failure record in `failures`.
void agreement_at_pose(AgreementRun& run, const baselines::BaselinePair& bp, std::uint64_t k, AgreementStats& st, json& failures) {
  const Pose X = run.gen(k);
  ++st.poses;
  const SolveResult r = solve(run.b1, run.b2, X, run.scene.solver);
  const baselines::OracleAnswer o = bp.oracle(X);
  if (!o.ok) {
    ++st.oracle_failed;
    run.mark_wrong("oracle", k);
  }
  if (r.status != SolveStatus::Converged) {
    ++st.idcol_not_converged;
    run.mark_wrong("idcol_cold", k);
    run.mark_wrong("idcol_warm", k);
    return;  // the solve failure itself is counted by the cold/warm passes
  }
  const std::array<double, 2> br = o.ok ? bp.smoothing_bracket(o) : std::array<double, 2>{NAN, NAN};
  json f = detail::failure_head(run.scene, run.i1, run.i2, k, X, "baseline_disagreement");
  f["idcol_alpha"] = r.alpha;
  f["oracle_alpha"] = o.ok ? json(o.alpha) : json(nullptr);
  f["bracket"] = o.ok ? json({br[0], br[1]}) : json(nullptr);
  bool bad = false;
  json disagreeing = json::array();
  if (o.ok) {
    const double e = std::abs(r.alpha - o.alpha);
    st.alpha_abs_err.add(e);
    st.alpha_rel_err.add(e / o.alpha);
    if (!in_widened_bracket(r.alpha, br[0], br[1], run.spec.band_tolerance)) {
      ++st.idcol_outside_bracket;
      run.mark_wrong("idcol_cold", k);
      run.mark_wrong("idcol_warm", k);
      disagreeing.push_back(key::idcol_outside_bracket);
      bad = true;
    }
  }
  bad |= compare_methods(run, bp, k, X, r, o, br, st, disagreeing);
  if (bad) {
    f["disagreeing"] = disagreeing;
    failures.push_back(std::move(f));
  }
}

/// iDCOL through solve_batch on one thread (the SIMD lanes where the pair
/// has them), cold and warm, on the timed poses: blocks of kBatchBlock
/// consecutive poses, each timed whole and each row given its block's mean,
/// as a planner's batch call would see it; warm, each block is 16 chains of
/// kBatchBlock / 16 consecutive poses (the lanes take a row of chains at a
/// time: one chain would leave all but one lane idle). Its answers are the
/// loop's bit for bit (batch.hpp), so it is wrong where iDCOL cold is.
void time_batch(AgreementRun& run, const std::vector<Pose>& Xs, double overhead_ns, AgreementStats& total) {
  constexpr std::size_t kBatchBlock = 16384;
  const std::size_t n = Xs.size();
  std::vector<double> alpha(kBatchBlock), x(3 * kBatchBlock);
  std::vector<std::int32_t> status(kBatchBlock), iterations(kBatchBlock);
  for (const bool warm : {false, true}) {
    BatchOptions o;
    o.solver = run.scene.solver;
    o.warm_start = warm;
    o.warm_chain = kBatchBlock / 16;
    o.threads = 1;
    auto block = [&](std::size_t a) {
      const std::size_t m = std::min(kBatchBlock, n - a);
      BatchOutput out;
      out.alpha = {alpha.data(), m}, out.x_1 = {x.data(), 3 * m}, out.status = {status.data(), m};
      out.iterations = {iterations.data(), m};
      solve_batch(run.b1, run.b2, Span<const Pose>(Xs.data() + a, m), o, out);
      return m;
    };
    for (std::size_t a = 0; a < std::min<std::size_t>(n, 4 * kBatchBlock); a += kBatchBlock) block(a);  // warm-up
    LogHistogram h{0, 10, 100};
    for (std::size_t a = 0; a < n;) {
      const auto t0 = Clock::now();
      const std::size_t m = block(a);
      const auto t1 = Clock::now();
      const double per_row = (std::chrono::duration<double, std::nano>(t1 - t0).count() - overhead_ns) / static_cast<double>(m);
      for (std::size_t i = 0; i < m; ++i) h.add(per_row);
      a += m;
    }
    const std::string name = warm ? "idcol_batch_warm" : "idcol_batch_cold";
    total.time.emplace(name, h);
    std::uint64_t nw = 0;
    for (char c : run.wrong["idcol_cold"]) nw += c;
    total.timed_wrong[name] = nw;
  }
}

/// Timing on the first n_timed poses, one method after the other on the
/// same poses (iDCOL cold and warm, each boolean method, the oracle), each
/// after a warm-up, into total's time histograms with the count of wrong
/// answers among the timed poses.
void time_methods(AgreementRun& run, double overhead_ns, AgreementStats& total) {
  const baselines::BaselinePair bp(run.b1, run.b2);
  std::vector<Pose> Xs(run.n_timed);
  for (std::uint64_t i = 0; i < run.n_timed; ++i) Xs[i] = run.gen(run.lo + i);
  const auto w0 = Clock::now();
  const double c0 = thread_cpu_seconds();
  auto time_method = [&](const std::string& name, auto&& query) {
    LogHistogram h{0, 10, 100};
    for (std::uint64_t i = 0; i < std::min<std::uint64_t>(run.n_timed, 100); ++i) query(i);  // warm-up
    for (std::uint64_t i = 0; i < run.n_timed; ++i) {
      const auto t0 = Clock::now();
      query(i);
      const auto t1 = Clock::now();
      h.add(std::chrono::duration<double, std::nano>(t1 - t0).count() - overhead_ns);
    }
    total.time.emplace(name, h);
    std::uint64_t nw = 0;
    for (char c : run.wrong[name]) nw += c;
    total.timed_wrong[name] = nw;
  };
  const SolverOptions& opt = run.scene.solver;
  volatile double sink = 0.0;
  time_method("idcol_cold", [&](std::uint64_t i) { sink = solve(run.b1, run.b2, Xs[i], opt).alpha; });
  {
    WarmStart ws;
    time_method("idcol_warm", [&](std::uint64_t i) {
      if (i == 0) ws.reset();
      sink = solve(run.b1, run.b2, Xs[i], opt, &ws).alpha;
    });
  }
  time_batch(run, Xs, overhead_ns, total);
  for (const auto& m : run.booleans) {
    const baselines::PreparedPair& pp = bp.prepared(baselines::competitor(m));
    time_method(m, [&](std::uint64_t i) { sink = pp.run(Xs[i]).intersect ? 1.0 : 0.0; });
  }
  if (run.spec.has("oracle")) time_method("oracle", [&](std::uint64_t i) { sink = bp.oracle(Xs[i]).alpha; });
  (void)sink;
  total.timed_poses = run.n_timed;
  total.timing_cpu_seconds = thread_cpu_seconds() - c0;
  total.timing_wall_seconds = std::chrono::duration<double>(Clock::now() - w0).count();
}

}  // namespace

AgreementStats run_agreement(const Scene& scene, int i1, int i2, std::uint64_t lo, std::uint64_t hi, int threads,
                             double overhead_ns, json& failures) {
  const Shape& b1 = *scene.shapes[i1].shape;
  const Shape& b2 = *scene.shapes[i2].shape;
  const SweepSpec& sw = scene.spec.as<SweepSpec>();
  const BaselineSpec& spec = sw.baselines;
  AgreementRun run{scene, i1, i2, b1, b2, spec, PoseGenerator(scene.generator, radial_range(b1, b2), scene.dt), {}, lo,
                   sw.record.timing ? std::min<std::uint64_t>(spec.timing_poses, hi - lo) : 0, {}};
  for (const auto& m : boolean_methods())
    if (spec.has(m)) run.booleans.push_back(m);
  for (const auto& m : run.booleans) run.wrong[m].assign(run.n_timed, 0);
  for (const char* m : {"idcol_cold", "idcol_warm", "oracle"}) run.wrong[m].assign(run.n_timed, 0);

  // Every pose, threads taking whole ranges, merged in pose order.
  std::vector<AgreementStats> sts(std::max(1, threads));
  std::vector<json> fs(std::max(1, threads), json::array());
  run_in_chains(lo, hi, 1, threads, [&](int t, std::uint64_t a, std::uint64_t b) {
    const baselines::BaselinePair bp(b1, b2);
    for (const auto& m : run.booleans) sts[t].status[m];
    for (std::uint64_t k = a; k < b; ++k) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      agreement_at_pose(run, bp, k, sts[t], fs[t]);
    }
  });
  AgreementStats total;
  for (int t = 0; t < std::max(1, threads); ++t) {
    total.merge(sts[t]);
    for (auto& f : fs[t]) failures.push_back(std::move(f));
  }
  for (const auto& m : run.booleans) total.status[m];
  if (run.n_timed > 0) time_methods(run, overhead_ns, total);
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
    std::printf("%-13s intersect %d  signed distance %.6g%s  %s\n", m.c_str(), a.intersect ? 1 : 0, a.signed_distance,
                a.has_alpha ? ("  alpha " + fmt17(a.alpha) + " (its bound " + fmt17(a.alpha_bound) + ")").c_str() : "",
                a.failed || a.threw ? ("failed: " + a.error).c_str() : "");
  }
  return 0;
}
}  // namespace detail

}  // namespace idcol::harness
