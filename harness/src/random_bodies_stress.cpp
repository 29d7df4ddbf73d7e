// The stress suite's kind = "random_bodies" (stress.hpp): pose k of a case
// draws a new pair of bodies and a pose (random_bodies.hpp); each pose is
// solved in both body orders, cold at the pose and warm at the nearby pose
// from the answer at the pose, and every answer is checked as every stress
// answer is (StressTally: surfaces, normals, the support-function bracket).
#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "idcol/solver.hpp"
#include "idcol_harness/random_bodies.hpp"
#include "idcol_harness/runner.hpp"
#include "idcol_harness/stress.hpp"
#include "stress_tally.hpp"

namespace idcol::harness {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

/// One pass of the case: cold or warm, in the given or the swapped body order.
struct RandomPass {
  Pass pass;
  bool swapped;
  std::string name;  // "cold", "warm", "cold_swapped", "warm_swapped"
};

/// One thread's share of the poses.
struct Share {
  std::vector<StressTally> tallies;
  std::vector<std::vector<json>> fails;
  std::vector<double> cpu;
};

}  // namespace

json run_random_bodies_case(const Scene& s, const StressCase& c, const StressOptions& opt, json& failures) {
  const auto case0 = Clock::now();
  const RandomBodyCase& rc = c.random;
  const std::string f1 = to_string(rc.family1), f2 = to_string(rc.family2);
  std::vector<RandomPass> passes;
  for (const bool swapped : {false, true})
    for (const Pass p : c.passes) passes.push_back({p, swapped, std::string(to_string(p)) + (swapped ? "_swapped" : "")});

  auto run_range = [&](std::uint64_t lo, std::uint64_t hi, Share& sh) {
    sh.tallies.resize(passes.size());
    sh.fails.resize(passes.size());
    sh.cpu.assign(passes.size(), 0.0);
    for (std::uint64_t k = lo; k < hi; ++k) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      const RandomBodyPose P = random_body_pose(rc, k);
      const Pose X_21 = P.X_12.inverse(), X_21_near = P.X_12_near.inverse();
      std::unique_ptr<AnswerChecker> checkers[2];  // of the pair in the given and in the swapped order
      // The oracle's answer at the pose and at the nearby pose, each shared
      // by both body orders (alpha* does not depend on the order).
      std::optional<OracleVerdict> verdicts[2];
      for (std::size_t i = 0; i < passes.size(); ++i) {
        const double cpu0 = thread_cpu_seconds();
        const RandomPass& rp = passes[i];
        const bool warm = rp.pass == Pass::Warm;
        const Shape& b1 = rp.swapped ? P.body2 : P.body1;
        const Shape& b2 = rp.swapped ? P.body1 : P.body2;
        const Pose& X = rp.swapped ? X_21 : P.X_12;
        const Pose& X_solved = warm ? (rp.swapped ? X_21_near : P.X_12_near) : X;
        WarmStart ws;
        if (warm) (void)solve(b1, b2, X, s.solver, &ws);  // the answer at the pose, to start from
        const WarmStart before = ws;
        const auto t0 = Clock::now();
        const SolveResult r = solve(b1, b2, X_solved, s.solver, warm ? &ws : nullptr);
        sh.tallies[i].solve_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
        auto& checker = checkers[rp.swapped ? 1 : 0];
        if (!checker) checker = std::make_unique<AnswerChecker>(b1, b2, OracleChoice::SupportFunction, s.solver);
        const AnswerCheck ch = sh.tallies[i].check(*checker, X_solved, r, k, k % c.oracle_every == 0, kNaN, {}, &verdicts[warm ? 1 : 0]);
        if (!ch.genuine() && sh.fails[i].size() < opt.max_failures) {
          const FailureSite site{rp.swapped ? f2 : f1, rp.swapped ? f1 : f2, &b1, &b2, rp.name, k, "stress:random_bodies"};
          json f = stress_failure_record(c, site, X_solved, &r, warm ? &before : nullptr, ch.problem, ch.oracle_alpha);
          f["random_bodies"] = {{"family1", f1}, {"family2", f2}, {"range", to_string(rc.range)}, {"seed", rc.seed},
                                {"k", k},        {"swapped", rp.swapped}};
          sh.fails[i].push_back(std::move(f));
        }
        sh.cpu[i] += thread_cpu_seconds() - cpu0;
      }
    }
  };

  const int threads = static_cast<int>(std::min<std::uint64_t>(std::max(1, opt.threads), std::max<std::uint64_t>(1, c.poses)));
  std::vector<Share> shares(threads);
  run_in_chains(0, c.poses, 1, threads, [&](int t, std::uint64_t lo, std::uint64_t hi) { run_range(lo, hi, shares[t]); });

  json cj = {{"name", c.name},
             {"body1", f1},
             {"body2", f2},
             {"shape1", "random " + f1 + " (" + to_string(rc.range) + " range)"},
             {"shape2", "random " + f2 + " (" + to_string(rc.range) + " range)"},
             {"kind", "random_bodies"},
             {"poses", c.poses},
             {"random_bodies", {{"family1", f1}, {"family2", f2}, {"range", to_string(rc.range)}, {"seed", rc.seed}}},
             {"oracle", "support"},
             {"oracle_every", c.oracle_every},
             {"passes", json::object()}};
  for (std::size_t i = 0; i < passes.size(); ++i) {
    StressTally total;
    double cpu = 0.0;
    std::vector<json> kept;
    for (Share& sh : shares) {  // threads took contiguous ranges in order: records stay in pose order
      total.merge(sh.tallies[i]);
      cpu += sh.cpu[i];
      for (json& f : sh.fails[i])
        if (kept.size() < opt.max_failures) kept.push_back(std::move(f));
    }
    const std::size_t n_kept = kept.size();
    append_failures(failures, json(std::move(kept)), opt.failures_path);
    json pj = total.to_json();
    pj["time"]["cpu_seconds"] = cpu;
    pj["failure_records_kept"] = n_kept;
    cj["passes"][passes[i].name] = pj;
  }
  cj["wall_seconds"] = std::chrono::duration<double>(Clock::now() - case0).count();
  return cj;
}

}  // namespace idcol::harness
