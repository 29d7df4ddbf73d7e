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
#include "gen/random_bodies.hpp"
#include "exec/chains.hpp"
#include "studies/stress/stress.hpp"
#include "studies/stress/stress_tally.hpp"

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
}  // namespace

json run_random_bodies_case(const Scene& s, const StressCase& c, const StudyOptions& opt, json& failures) {
  const auto case0 = Clock::now();
  const RandomBodyCase& rc = c.random;
  const std::string f1 = to_string(rc.family1), f2 = to_string(rc.family2);
  std::vector<RandomPass> passes;
  for (const bool swapped : {false, true})
    for (const Pass p : c.passes) passes.push_back({p, swapped, std::string(to_string(p)) + (swapped ? "_swapped" : "")});

  auto run_range = [&](std::uint64_t lo, std::uint64_t hi, StressShare& sh) {
    for (std::uint64_t k = lo; k < hi; ++k) {
      if (interrupt_flag().load(std::memory_order_relaxed)) throw Interrupted();
      const RandomBodyPose P = random_body_pose(rc, k);
      const Pose X_21 = P.X_12.inverse(), X_21_near = P.X_12_near.inverse();
      std::unique_ptr<AnswerChecker> checkers[2];  // of the pair in the given and in the swapped order
      // The oracle's answer at the pose and at the nearby pose, each shared
      // by both body orders (alpha* does not depend on the order).
      std::optional<OracleVerdict> verdicts[2];
      // The cold answer at the pose in each body order: a warm pass of the
      // same order starts from it rather than solving the pose again (the
      // same solve: an invalid WarmStart is a cold start).
      std::optional<WarmStart> at_pose[2];
      for (std::size_t i = 0; i < passes.size(); ++i) {
        const double cpu0 = thread_cpu_seconds();
        const RandomPass& rp = passes[i];
        const bool warm = rp.pass == Pass::Warm;
        const Shape& b1 = rp.swapped ? P.body2 : P.body1;
        const Shape& b2 = rp.swapped ? P.body1 : P.body2;
        const Pose& X = rp.swapped ? X_21 : P.X_12;
        const Pose& X_solved = warm ? (rp.swapped ? X_21_near : P.X_12_near) : X;
        std::optional<WarmStart>& cold_ws = at_pose[rp.swapped ? 1 : 0];
        WarmStart ws;
        if (warm) {
          if (cold_ws) ws = *cold_ws;
          else (void)solve(b1, b2, X, s.solver, &ws);  // the answer at the pose, to start from
        }
        const WarmStart before = ws;
        const auto t0 = Clock::now();
        const SolveResult r = solve(b1, b2, X_solved, s.solver, &ws);
        if (!warm) cold_ws = ws;
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
  std::vector<std::string> names;
  for (const RandomPass& p : passes) names.push_back(p.name);
  const int threads = static_cast<int>(std::min<std::uint64_t>(std::max(1, opt.threads), std::max<std::uint64_t>(1, c.poses)));
  run_case_passes(c, names, 1, threads, opt, run_range, cj, failures);
  cj["wall_seconds"] = std::chrono::duration<double>(Clock::now() - case0).count();
  return cj;
}

}  // namespace idcol::harness
