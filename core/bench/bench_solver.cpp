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

/// Pose k of the paper's sweep (Sec. "Simulations and Benchmarking").
Pose sweep_pose(int k, double rmin, double rmax) {
  const double t = k * 1e-4, tp = 2.0 * M_PI;
  const double u = 0.5 * (1.0 + std::sin(tp * std::sqrt(2.0) * t));
  const double rad = std::cbrt(rmin * rmin * rmin + (rmax * rmax * rmax - rmin * rmin * rmin) * u);
  const double th = 0.5 * M_PI * std::sin(tp * std::sqrt(3.0) * t), ph = tp * std::sqrt(5.0) * t;
  Eigen::Quaterniond q(std::sin(tp * std::sqrt(7.0) * t), std::cos(tp * std::sqrt(11.0) * t), std::sin(tp * std::sqrt(13.0) * t),
                       std::cos(tp * std::sqrt(17.0) * t));
  q.normalize();
  return Pose{q.toRotationMatrix(), rad * Vec3(std::cos(th) * std::cos(ph), std::cos(th) * std::sin(ph), std::sin(th))};
}

void run_pair(benchmark::State& state, const Shape& a, const Shape& b, bool warm) {
  const Radii ra = radii(a), rb = radii(b);
  const double rmin = 0.1 * std::min(ra.inner, rb.inner), rmax = 2.0 * std::max(ra.outer, rb.outer);
  std::vector<Pose> poses(kPoses);
  for (int k = 0; k < kPoses; ++k) poses[k] = sweep_pose(k, rmin, rmax);
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
