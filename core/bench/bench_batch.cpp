// solve_batch against the plain loop of solve() it replaces, on 10^5 poses of
// the paper's sweep (dt = 1e-4), cold and warm (warm chains of 1024 poses in
// both), and its scaling with threads. One benchmark iteration is one pass
// over all the poses; the counter ns_per_pose is wall time per pose.
// The batch's answers are checked against the loop's before anything is
// timed (they must be equal bit for bit).
//
//   taskset -c 0 build/core/idcol_bench_batch --benchmark_filter='threads:1$|loop' \
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//   taskset -c 0,1 build/core/idcol_bench_batch --benchmark_filter='batch' ...
//
// scripts/bench_python_batch.py runs these and times the Python module on
// the same poses.
#include <benchmark/benchmark.h>

#include "bench_note.hpp"

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/batch.hpp"
#include "idcol/solver.hpp"
#include "../examples/paper_shapes.hpp"

using namespace idcol;

namespace {

constexpr std::size_t kPoses = 100000;
constexpr std::size_t kChain = 1024;

struct Pair {
  const char* name;
  Shape a, b;
};

const std::vector<Pair>& pairs() {
  static const std::vector<Pair> P = [] {
    const double s = 1.0 / std::sqrt(3.0);
    const Shape poly = SmoothPolytope(
        {{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}, {s, s, -s}},
        {s, s, s, s, 5 / 3.0 * s, 5 / 3.0 * s, 5 / 3.0 * s, 5 / 3.0 * s}, 20.0);
    const Shape se = Superellipsoid(0.5, 1.0, 1.5, 8.0);
    const Shape tc = SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0);
    const Shape sec = SuperellipticCylinder(1.0, 2.0, 8.0);
    return std::vector<Pair>{{"SE-Poly", se, poly}, {"TC-SEC", tc, sec}};
  }();
  return P;
}

/// Pose k of the paper's sweep (README, "Generators"), as row-major R and p:
/// the layout a NumPy caller hands to solve_batch.
struct Sweep {
  std::vector<double> R, p;
  std::vector<Pose> poses;
};

Sweep sweep(const Shape& a, const Shape& b) {
  Sweep s;
  s.R.resize(9 * kPoses);
  s.p.resize(3 * kPoses);
  s.poses = examples::paper_sweep(a, b, kPoses);
  for (std::size_t k = 0; k < kPoses; ++k) {
    const Pose& X = s.poses[k];
    for (int i = 0; i < 3; ++i) {
      s.p[3 * k + i] = X.p[i];
      for (int j = 0; j < 3; ++j) s.R[9 * k + 3 * i + j] = X.R(i, j);
    }
  }
  return s;
}

struct Out {
  std::vector<double> alpha, x;
  std::vector<std::int32_t> status, iterations;
  Out() : alpha(kPoses), x(3 * kPoses), status(kPoses), iterations(kPoses) {}
  BatchOutput view() { return {alpha, x, status, iterations, {}}; }
};

/// The loop a C++ caller writes without the batch: solve() per pose, the
/// same outputs stored, the warm start restarted every kChain poses.
void loop(const Shape& a, const Shape& b, const Sweep& s, bool warm, Out& o) {
  WarmStart ws;
  const SolverOptions opt;
  for (std::size_t k = 0; k < kPoses; ++k) {
    if (k % kChain == 0) ws.reset();
    const SolveResult r = solve(a, b, s.poses[k], opt, warm ? &ws : nullptr);
    o.alpha[k] = r.alpha;
    o.x[3 * k] = r.x_1[0];
    o.x[3 * k + 1] = r.x_1[1];
    o.x[3 * k + 2] = r.x_1[2];
    o.status[k] = static_cast<std::int32_t>(r.status);
    o.iterations[k] = r.iterations;
  }
}

void batch(const Shape& a, const Shape& b, const Sweep& s, bool warm, int threads, Out& o) {
  BatchOptions bo;
  bo.warm_start = warm;
  bo.warm_chain = kChain;
  bo.threads = threads;
  const Shape* pa = &a;
  const Shape* pb = &b;
  solve_batch(Span<const Shape* const>(&pa, 1), Span<const Shape* const>(&pb, 1), Span<const double>(s.R),
              Span<const double>(s.p), bo, o.view());
}

void run(benchmark::State& state, const Pair& P, bool warm, int threads) {
  static Sweep cache[2];
  static bool made[2] = {false, false};
  const std::size_t idx = &P == &pairs()[0] ? 0 : 1;
  if (!made[idx]) cache[idx] = sweep(P.a, P.b), made[idx] = true;
  const Sweep& s = cache[idx];
  Out want, got;
  // Check before timing: the batch must give the loop's answers exactly.
  loop(P.a, P.b, s, warm, want);
  if (threads > 0) {
    batch(P.a, P.b, s, warm, threads, got);
    if (std::memcmp(want.alpha.data(), got.alpha.data(), kPoses * sizeof(double)) != 0 || want.status != got.status) {
      state.SkipWithError("batch differs from the loop");
      return;
    }
  }
  double ns = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (threads == 0)
      loop(P.a, P.b, s, warm, got);
    else
      batch(P.a, P.b, s, warm, threads, got);
    benchmark::DoNotOptimize(got.alpha.data());
    benchmark::ClobberMemory();
    ns += std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kPoses));
  state.counters["ns_per_pose"] = ns / static_cast<double>(state.iterations() * kPoses);
}

const int registered = [] {
  for (const Pair& P : pairs())
    for (bool warm : {false, true}) {
      const std::string base = std::string(warm ? "warm/" : "cold/") + P.name;
      benchmark::RegisterBenchmark((base + "/loop").c_str(), [&P, warm](benchmark::State& st) { run(st, P, warm, 0); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->MinTime(0.5);
      for (int threads : {1, 2})
        benchmark::RegisterBenchmark((base + "/batch/threads:" + std::to_string(threads)).c_str(),
                                     [&P, warm, threads](benchmark::State& st) { run(st, P, warm, threads); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->MinTime(0.5);
    }
  return 0;
}();

}  // namespace

IDCOL_BENCHMARK_MAIN()
