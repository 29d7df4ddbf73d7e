// Random bodies of every family at random poses, each solved cold, in the
// swapped order (body 2 at the inverse pose) and warm (from the solution of
// a nearby pose), and every converged answer checked against the
// support-function bracket (support_oracle.hpp), which shares no code with
// the solver. A converged alpha* outside its bracket is a false convergence.
//
// Bodies and poses: the harness's generator (harness/src/gen/
// random_bodies.hpp, which documents the ranges), the same one the stress
// suite's kind = "random_bodies" (configs/random_bodies.toml) draws from.
//
//   build/harness/idcol_check_random_bodies [poses per ordered pair = 1000] [wide = 0] [seed = 1] [strict = 0]
//
// Prints one row per ordered family pair and the totals; exit status 1 if any
// converged answer falls outside its bracket, or (strict) if any solve does
// not converge.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "idcol/solver.hpp"
#include "gen/random_bodies.hpp"
#include "io/keys.hpp"
#include "../../../core/examples/cli_args.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/support_oracle.hpp"

using namespace idcol;
using namespace idcol::baselines;

namespace {

struct Row {
  long solves = 0, converged = 0, outside = 0, oracle_failed = 0, iterations = 0, barrier = 0;
  std::map<std::string, long> failures;
  void add(const Row& o) {
    solves += o.solves;
    converged += o.converged;
    outside += o.outside;
    oracle_failed += o.oracle_failed;
    iterations += o.iterations;
    barrier += o.barrier;
    for (const auto& [k, v] : o.failures) failures[k] += v;
  }
  /// "status=count " for each failure status.
  std::string failure_text() const {
    std::string why;
    for (const auto& [k, v] : failures) why += k + "=" + std::to_string(v) + " ";
    return why;
  }
};

/// Converged alpha against the bracket of the same pose: 0 inside, else the relative distance.
double outside(double alpha, const AlphaBracket& b) {
  // The solver's tolerance (1e-10 relative) on top of the oracle's own margin.
  const double tol = 1e-9;
  if (alpha < b.lo * (1.0 - tol)) return b.lo / alpha - 1.0;
  if (alpha > b.hi * (1.0 + tol)) return alpha / b.hi - 1.0;
  return 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kTool = "idcol_check_random_bodies";
  examples::positional_args("idcol_check_random_bodies [poses per ordered pair = 1000] [wide = 0] [seed = 1] [strict = 0]", argc,
                            argv, 4);
  const int per = argc > 1 ? static_cast<int>(examples::count_arg(kTool, "poses per pair", argv[1], 1, 100000000)) : 1000;
  const bool wide = argc > 2 && examples::count_arg(kTool, "wide", argv[2], 0, 1) != 0;
  const unsigned seed = argc > 3 ? static_cast<unsigned>(examples::count_arg(kTool, "seed", argv[3], 0, 2147483647)) : 1u;
  const bool strict = argc > 4 && examples::count_arg(kTool, "strict", argv[4], 0, 1) != 0;
  std::printf("random bodies, %s range, %d poses per ordered pair, seed %u; each pose solved cold, swapped and warm\n",
              wide ? "wide" : "normal", per, seed);
  std::printf("%-30s %8s %10s %8s %8s %10s %s\n", "pair", "solves", "converged", "outside", "no_oracle", "mean_iter", harness::key::failures);
  Row total;
  for (int f1 = 0; f1 < harness::kNumBodyFamilies; ++f1)
    for (int f2 = 0; f2 < harness::kNumBodyFamilies; ++f2) {
      const harness::RandomBodyCase rc{static_cast<harness::BodyFamily>(f1), static_cast<harness::BodyFamily>(f2),
                                       wide ? harness::BodyRange::Wide : harness::BodyRange::Normal, seed};
      Row row;
      for (int k = 0; k < per; ++k) {
        const harness::RandomBodyPose P = harness::random_body_pose(rc, static_cast<std::uint64_t>(k));
        const Shape &a = P.body1, &b = P.body2;
        const Pose &X = P.X_12, &X2 = P.X_12_near;
        WarmStart w;
        (void)solve(a, b, X, {}, &w);
        const SolveResult r[3] = {solve(a, b, X), solve(b, a, X.inverse()), solve(a, b, X2, {}, &w)};
        const Pose* poses[3] = {&X, &X, &X2};
        const SupportOracle oracle(to_desc(a), to_desc(b));
        AlphaBracket br[2];
        for (int j = 0; j < 2; ++j) {
          const Pose& Xj = j == 0 ? X : X2;
          br[j] = oracle.bracket(geom::Pose{Xj.R, Xj.p});
        }
        for (int j = 0; j < 3; ++j) {
          ++row.solves;
          row.iterations += r[j].iterations;
          row.barrier += r[j].used_barrier;
          if (!r[j].converged()) {
            ++row.failures[to_string(r[j].status)];
            // A record to replay: both bodies and the pose at 17 digits
            // (solve 1 is body 2 against body 1 at the inverse pose).
            const Pose& Xj = *poses[j];
            std::printf("  FAILED %s-%s pose %d solve %d: %s, residual %.3g, %d iterations%s%s\n    %s\n    %s\n"
                        "    R = [%.17g, %.17g, %.17g; %.17g, %.17g, %.17g; %.17g, %.17g, %.17g], p = [%.17g, %.17g, %.17g]\n",
                        harness::to_string(rc.family1), harness::to_string(rc.family2), k, j, to_string(r[j].status), r[j].residual_norm, r[j].iterations,
                        r[j].used_continuation ? ", continuation" : "", r[j].used_barrier ? ", barrier" : "", describe(a).c_str(),
                        describe(b).c_str(), Xj.R(0, 0), Xj.R(0, 1), Xj.R(0, 2), Xj.R(1, 0), Xj.R(1, 1), Xj.R(1, 2), Xj.R(2, 0), Xj.R(2, 1),
                        Xj.R(2, 2), Xj.p[0], Xj.p[1], Xj.p[2]);
            continue;
          }
          ++row.converged;
          const AlphaBracket& bj = br[poses[j] == &X ? 0 : 1];
          if (!bj.ok) {
            ++row.oracle_failed;
            continue;
          }
          const double d = outside(r[j].alpha, bj);
          if (d > 0.0) {
            ++row.outside;
            std::printf("  OUTSIDE %s-%s pose %d solve %d: alpha %.17g, bracket [%.17g, %.17g], residual %.3g, %d iterations%s%s\n    %s\n    %s\n",
                        harness::to_string(rc.family1), harness::to_string(rc.family2), k, j, r[j].alpha, bj.lo, bj.hi, r[j].residual_norm, r[j].iterations,
                        r[j].used_continuation ? ", continuation" : "", r[j].used_barrier ? ", barrier" : "", describe(a).c_str(),
                        describe(b).c_str());
          }
        }
      }
      const std::string name = std::string(harness::to_string(rc.family1)) + "-" + harness::to_string(rc.family2);
      std::printf("%-30s %8ld %9.3f%% %8ld %8ld %10.1f %s\n", name.c_str(), row.solves, 100.0 * row.converged / row.solves, row.outside,
                  row.oracle_failed, static_cast<double>(row.iterations) / row.solves, row.failure_text().c_str());
      total.add(row);
    }
  const std::string why = total.failure_text();
  std::printf("total: %ld solves, %ld converged (%.4f%%), %ld not converged (%s), %ld converged outside the bracket "
              "(false convergences), %ld without an oracle bracket, %ld used the barrier\n",
              total.solves, total.converged, 100.0 * total.converged / total.solves, total.solves - total.converged,
              why.empty() ? "none" : why.c_str(), total.outside, total.oracle_failed, total.barrier);
  return total.outside == 0 && (!strict || total.converged == total.solves) ? 0 : 1;
}
