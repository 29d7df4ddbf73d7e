// Cold and warm solve time and Newton iterations per solve, for every pair of
// the paper's shapes (beta = 20, n = 8) and the exact ellipsoid, on a fixed
// sequence of poses from the paper's sweep (dt = 1e-4, so consecutive poses
// are close, as in a simulation). Every pose is checked to converge before
// anything is timed.
//
//   taskset -c 0 build/core/idcol_bench --benchmark_repetitions=5 \
//       --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "bench_note.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/solver.hpp"
#include "../examples/paper_shapes.hpp"

using namespace idcol;

namespace {

constexpr int kPoses = 20000;

using examples::NamedShape;
// The paper's Table 1 shapes (core/examples/paper_shapes.hpp).
std::vector<NamedShape> shapes() { return examples::paper_catalogue(); }

void run_pair(benchmark::State& state, const Shape& a, const Shape& b, bool warm) {
  const std::vector<Pose> poses = examples::paper_sweep(a, b, kPoses);
  const SolverOptions opt;
  // Check before timing: every pose must converge, cold and warm.
  {
    WarmStart ws;
    for (const Pose& X : poses) {
      if (!solve(a, b, X, opt, warm ? &ws : nullptr).converged()) {
        state.SkipWithError("a pose did not converge");
        return;
      }
    }
  }
  WarmStart ws;
  long solves = 0, iterations = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    const SolveResult r = solve(a, b, poses[k], opt, warm ? &ws : nullptr);
    benchmark::DoNotOptimize(r.alpha);
    iterations += r.iterations;
    ++solves;
    if (++k == poses.size()) k = 0;
  }
  state.counters["newton_its"] = benchmark::Counter(static_cast<double>(iterations) / static_cast<double>(solves));
}

const int registered = [] {
  static const std::vector<NamedShape> S = shapes();
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j)
      for (bool warm : {false, true}) {
        const std::string name = std::string(warm ? "warm/" : "cold/") + S[i].name + "-" + S[j].name;
        benchmark::RegisterBenchmark(name.c_str(), [i, j, warm](benchmark::State& st) { run_pair(st, S[i].shape, S[j].shape, warm); })
            ->Unit(benchmark::kMicrosecond)
            ->MinTime(0.5);
      }
  return 0;
}();

}  // namespace

IDCOL_BENCHMARK_MAIN()
