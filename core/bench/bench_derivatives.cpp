// Cost of the solution sensitivity dz*/dxi (and of the cheaper alpha
// gradient) beside a warm-started solve, for every ordered pair of the
// paper's four shapes. WarmSolve is the solve of a caller who wants alpha*
// alone; WarmSolveDeriv the same solve keeping the factorisation that the
// derivatives read (SolverOptions::derivatives), so the whole cost of
// derivatives is WarmSolveDeriv - WarmSolve + Sensitivity. Each pair runs along a seeded smooth trajectory of
// 256 poses near contact (alpha* about 1), so the warm starts are the
// realistic ones of a simulation. Every result is checked before timing.
//   taskset -c 0 idcol_bench_derivatives --benchmark_format=json
#include <benchmark/benchmark.h>

#include "bench_note.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "../examples/paper_shapes.hpp"

using namespace idcol;

namespace {

using examples::paper_poly;
using examples::with_derivatives;

struct Named {
  const char* name;
  Shape s;
};
const std::vector<Named>& shapes() {
  static const std::vector<Named> v = {{"Poly", paper_poly()},
                                       {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
                                       {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                       {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)}};
  return v;
}

constexpr int kPoses = 256;

std::vector<Pose> trajectory(const Shape& a, const Shape& b, unsigned seed) {
  return examples::near_contact_trajectory(a, b, seed, kPoses);
}

void BM_WarmSolve(benchmark::State& st, int i, int j, bool derivatives) {
  const Shape &a = shapes()[i].s, &b = shapes()[j].s;
  const std::vector<Pose> P = trajectory(a, b, 100 + 4 * i + j);
  ContactPair pair(a, b, derivatives ? with_derivatives() : SolverOptions{});
  for (const Pose& X : P)
    if (!pair.solve(X).converged()) return st.SkipWithError("solve did not converge");
  int k = 0;
  for (auto _ : st) {
    SolveResult r = pair.solve(P[k]);
    benchmark::DoNotOptimize(r);
    k = (k + 1) % kPoses;
  }
}

std::vector<SolveResult> solved(int i, int j) {
  const Shape &a = shapes()[i].s, &b = shapes()[j].s;
  std::vector<SolveResult> R;
  for (const Pose& X : trajectory(a, b, 100 + 4 * i + j)) R.push_back(solve(a, b, X, with_derivatives()));
  return R;
}

void BM_Sensitivity(benchmark::State& st, int i, int j) {
  const std::vector<SolveResult> R = solved(i, j);
  for (const SolveResult& r : R) {
    if (!r.converged()) return st.SkipWithError("solve did not converge");
    // Check before timing: the alpha row must match the adjoint gradient.
    const SolutionSensitivity s = solution_sensitivity(r);
    if (!s.valid || (s.dalpha_dxi() - alpha_gradient(r)).norm() > 1e-8 * (1.0 + s.dalpha_dxi().norm()))
      return st.SkipWithError("sensitivity check failed");
  }
  int k = 0;
  for (auto _ : st) {
    SolutionSensitivity s = solution_sensitivity(R[k]);
    benchmark::DoNotOptimize(s);
    k = (k + 1) % kPoses;
  }
}

void BM_AlphaGradient(benchmark::State& st, int i, int j) {
  const std::vector<SolveResult> R = solved(i, j);
  for (const SolveResult& r : R)
    if (!r.converged()) return st.SkipWithError("solve did not converge");
  int k = 0;
  for (auto _ : st) {
    Row6 g = alpha_gradient(R[k]);
    benchmark::DoNotOptimize(g);
    k = (k + 1) % kPoses;
  }
}

void BM_KinematicsAndWrenchDerivatives(benchmark::State& st, int i, int j) {
  const std::vector<SolveResult> R = solved(i, j);
  for (const SolveResult& r : R)
    if (!r.converged()) return st.SkipWithError("solve did not converge");
  const HertzModel m{1e4, 1.5};
  int k = 0;
  for (auto _ : st) {
    const SolutionSensitivity s = solution_sensitivity(R[k]);
    ContactKinematicsDerivatives d = contact_kinematics_derivatives(R[k], s);
    ContactWrenchDerivatives w = contact_wrench_derivatives(R[k], s, m);
    benchmark::DoNotOptimize(d);
    benchmark::DoNotOptimize(w);
    k = (k + 1) % kPoses;
  }
}

const int registered = [] {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const std::string p = std::string(shapes()[i].name) + "-" + shapes()[j].name;
      benchmark::RegisterBenchmark(("WarmSolve/" + p).c_str(), BM_WarmSolve, i, j, false);
      benchmark::RegisterBenchmark(("WarmSolveDeriv/" + p).c_str(), BM_WarmSolve, i, j, true);
      benchmark::RegisterBenchmark(("Sensitivity/" + p).c_str(), BM_Sensitivity, i, j);
      benchmark::RegisterBenchmark(("AlphaGradient/" + p).c_str(), BM_AlphaGradient, i, j);
      benchmark::RegisterBenchmark(("KinWrenchDeriv/" + p).c_str(), BM_KinematicsAndWrenchDerivatives, i, j);
    }
  return 0;
}();

}  // namespace

IDCOL_BENCHMARK_MAIN()
