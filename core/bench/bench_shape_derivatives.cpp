// Cost of the shape-parameter derivatives (shape_derivatives.hpp) beside a
// warm-started solve, per family: each family against itself (so every
// parameter of body 1 is one of that family), along a seeded smooth
// trajectory of 256 poses near contact, as in bench_derivatives.cpp.
//   WarmSolveDeriv/F   warm solve keeping the factorisation derivatives read
//   EvalParams/F       eval_params() alone (phi, grad, hess and the mixed
//                      derivatives) at the contact point
//   ShapeSens/F        shape_sensitivity(): dz*/dtheta for body 1
//   ShapeSensAll/F     the same plus kinematics and wrench derivatives
// Before timing, the alpha row of dz*/dtheta is checked against central
// differences in theta (re-constructed shapes, re-solved) on 4 poses.
//   taskset -c 0 idcol_bench_shape_derivatives --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "bench_note.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/shape_derivatives.hpp"
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
  static const std::vector<Named> v = {{"Sphere", Sphere(0.8)},
                                       {"Poly", paper_poly()},
                                       {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
                                       {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                       {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)}};
  return v;
}

constexpr int kPoses = 256;

std::vector<Pose> trajectory(const Shape& a, const Shape& b, unsigned seed) {
  return examples::near_contact_trajectory(a, b, seed, kPoses);
}

/// The trajectory's results, or an error message if a solve failed or the
/// alpha row disagrees with central differences in theta.
std::string solved(int i, std::vector<SolveResult>& R) {
  const Shape& a = shapes()[i].s;
  const std::vector<Pose> P = trajectory(a, a, 200 + i);
  R.clear();
  for (const Pose& X : P) R.push_back(solve(a, a, X, with_derivatives()));
  for (const SolveResult& r : R)
    if (!r.converged()) return "solve did not converge";
  SolverOptions tight;
  tight.tolerance = 1e-13;
  const VecX theta = shape_params(a);
  for (int k = 0; k < 4; ++k) {
    const Pose& X = P[k * 64];
    const ShapeSensitivity s = shape_sensitivity(R[k * 64], a, a, 1);
    for (int j = 0; j < theta.size(); ++j) {
      const double h = 1e-6 * std::max(1.0, std::abs(theta[j]));
      VecX tp = theta, tm = theta;
      tp[j] += h;
      tm[j] -= h;
      const SolveResult rp = solve(shape_with_params(a, tp), a, X, tight);
      const SolveResult rm = solve(shape_with_params(a, tm), a, X, tight);
      if (!rp.converged() || !rm.converged()) return "perturbed solve did not converge";
      const double fd = (rp.alpha - rm.alpha) / (2.0 * h);
      if (!(std::abs(fd - s.dz_dtheta(3, j)) <= 1e-4 * std::max(1.0, std::abs(fd))))
        return "d alpha / d " + param_names(a)[j] + " disagrees with central differences";
    }
  }
  return "";
}

void BM_WarmSolveDeriv(benchmark::State& st, int i) {
  const Shape& a = shapes()[i].s;
  const std::vector<Pose> P = trajectory(a, a, 200 + i);
  ContactPair pair(a, a, with_derivatives());
  for (const Pose& X : P)
    if (!pair.solve(X).converged()) return st.SkipWithError("solve did not converge");
  int k = 0;
  for (auto _ : st) {
    SolveResult r = pair.solve(P[k]);
    benchmark::DoNotOptimize(r);
    k = (k + 1) % kPoses;
  }
}

void BM_EvalParams(benchmark::State& st, int i) {
  std::vector<SolveResult> R;
  const std::string err = solved(i, R);
  if (!err.empty()) return st.SkipWithError(err.c_str());
  const Shape& a = shapes()[i].s;
  ShapeEval e;
  ShapeParamEval d;
  int k = 0;
  for (auto _ : st) {
    eval_params(a, R[k].internal.y1, e, d);
    benchmark::DoNotOptimize(d.dgrad.data());
    k = (k + 1) % kPoses;
  }
}

void BM_ShapeSens(benchmark::State& st, int i, bool all) {
  std::vector<SolveResult> R;
  const std::string err = solved(i, R);
  if (!err.empty()) return st.SkipWithError(err.c_str());
  const Shape& a = shapes()[i].s;
  const HertzModel m{1e4, 1.5};
  int k = 0;
  for (auto _ : st) {
    const ShapeSensitivity s = shape_sensitivity(R[k], a, a, 1);
    benchmark::DoNotOptimize(s.dz_dtheta.data());
    if (all) {
      const ShapeKinematicsDerivatives d = shape_kinematics_derivatives(R[k], s);
      const ShapeWrenchDerivatives w = shape_wrench_derivatives(R[k], s, m);
      benchmark::DoNotOptimize(d.dgap.data());
      benchmark::DoNotOptimize(w.dF2_2.data());
    }
    k = (k + 1) % kPoses;
  }
  st.counters["params"] = num_params(a);
}

const int registered = [] {
  for (int i = 0; i < static_cast<int>(shapes().size()); ++i) {
    const std::string f = shapes()[i].name;
    benchmark::RegisterBenchmark(("WarmSolveDeriv/" + f).c_str(), BM_WarmSolveDeriv, i);
    benchmark::RegisterBenchmark(("EvalParams/" + f).c_str(), BM_EvalParams, i);
    benchmark::RegisterBenchmark(("ShapeSens/" + f).c_str(), BM_ShapeSens, i, false);
    benchmark::RegisterBenchmark(("ShapeSensAll/" + f).c_str(), BM_ShapeSens, i, true);
  }
  return 0;
}();

}  // namespace

IDCOL_BENCHMARK_MAIN()
