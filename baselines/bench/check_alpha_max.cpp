// Checks the certified lower bound behind SolverOptions::alpha_max on many
// poses against oracles that share no code with core:
//  - ellipsoid pairs against Perram-Wertheim (exact to rounding), N poses;
//  - every pair of the paper's shapes and the ellipsoid against the upper end
//    of the support-function bracket, N / 100 poses per pair.
// Poses: |r| log-uniform in [0.05, 20], uniform rotations, seeded.
// Prints the count checked, the violations (must be 0), the range of
// bound / alpha*, and the fraction of poses that alpha_max = 1 answers
// Separated. Exit status 1 on any violation.
//
//   build/baselines/idcol_check_alpha_max [N = 1000000]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "idcol/solver.hpp"
#include "../../core/examples/cli_args.hpp"
#include "idcol_baselines/baselines.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/support_oracle.hpp"
#include "test_util.hpp"

using namespace idcol;
using namespace idcol::baselines;

namespace {

struct Tally {
  long checked = 0, violations = 0, separated_at_1 = 0, truly_above_1 = 0;
  double qmin = 1e300, qmax = 0.0;
  void add(double bound, double alpha_hi, double alpha_star) {
    ++checked;
    if (!(bound <= alpha_hi * (1.0 + 1e-12))) ++violations;
    const double q = bound / alpha_star;
    qmin = std::min(qmin, q);
    qmax = std::max(qmax, q);
    separated_at_1 += bound > 1.0;
    truly_above_1 += alpha_star > 1.0;
  }
  void print(const std::string& name) const {
    std::printf("%-16s %9ld poses  violations %ld  bound/alpha* in [%.4f, %.6f]  Separated at alpha_max=1: %.1f%% of poses (alpha* > 1: %.1f%%)\n",
                name.c_str(), checked, violations, qmin, qmax, 100.0 * separated_at_1 / checked, 100.0 * truly_above_1 / checked);
  }
};

}  // namespace

int main(int argc, char** argv) {
  examples::positional_args("idcol_check_alpha_max [N = 1000000]", argc, argv, 1);
  const long N = argc > 1 ? examples::count_arg("idcol_check_alpha_max", "N", argv[1], 1, 1000000000) : 1000000;
  SolverOptions o;
  o.alpha_max = std::numeric_limits<double>::min();  // every pose returns its bound
  long violations = 0;

  {  // ellipsoids against Perram-Wertheim
    const Vec3 ax(0.5, 1.0, 1.5);
    const Superellipsoid e(ax[0], ax[1], ax[2], 1.0);
    std::mt19937_64 rng(1);
    Tally t;
    for (long k = 0; k < N; ++k) {
      const Pose X = test::random_pose(rng, 0.05, 20.0);
      const OracleAnswer pw = perram_wertheim(ax, ax, X);
      const SolveResult r = solve(e, e, X, o);
      if (!pw.ok || r.status != SolveStatus::Separated) {
        std::printf("pose %ld: oracle ok %d, status %s\n", k, pw.ok, to_string(r.status));
        ++t.violations;
        continue;
      }
      t.add(r.alpha, pw.alpha, pw.alpha);
    }
    t.print("Ellip-Ellip/PW");
    violations += t.violations;
  }

  // Every pair of the paper's shapes and the ellipsoid, against the support
  // oracle's certified upper end (alpha* itself unknown: the ratio is to the
  // bracket's midpoint).
  const auto shapes = [] {
    auto v = test::paper_shapes();
    v.push_back({"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)});
    return v;
  }();
  std::mt19937_64 rng(2);
  for (std::size_t i = 0; i < shapes.size(); ++i)
    for (std::size_t j = i; j < shapes.size(); ++j) {
      const SupportOracle oracle(to_desc(shapes[i].shape), to_desc(shapes[j].shape));
      Tally t;
      for (long k = 0; k < std::max(1L, N / 100); ++k) {
        const Pose X = test::random_pose(rng, 0.05, 20.0);
        const AlphaBracket b = oracle.bracket(X);
        const SolveResult r = solve(shapes[i].shape, shapes[j].shape, X, o);
        if (!b.ok || r.status != SolveStatus::Separated) {
          std::printf("pose %ld: oracle ok %d (%s), status %s\n", k, b.ok, b.error.c_str(), to_string(r.status));
          ++t.violations;
          continue;
        }
        t.add(r.alpha, b.hi, b.mid());
      }
      t.print(shapes[i].name + "-" + shapes[j].name);
      violations += t.violations;
    }
  std::printf("%s: %ld violations\n", violations ? "FAIL" : "PASS", violations);
  return violations ? 1 : 0;
}
