// The sweep's metrics, per pair: every figure compare reads from a sweep
// results file, declared once (study/metric.hpp explains the fields).
#include "studies/sweep/sweep_metrics.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
// Time per solve on shared machines moves by 10-30% from run to run: its
// default guards only warn.
constexpr DefaultGuard kMedianTime{DefaultGuard::Warn, 0.0, 0.3};
constexpr DefaultGuard kTailTime{DefaultGuard::Warn, 0.0, 0.5};
}  // namespace

const MetricTable& sweep_metrics() {
  static const MetricTable t{{
      {"passes.*", "{key}.",
       {{"convergence_rate", "", "fraction", B::Higher, M::Ratio, kExact},
        {"failures", "", "count", B::Lower, M::Sum, kExact},
        {"iterations.mean", "", "iterations", B::Lower, M::Ratio, kInfo, false, 1.0, "iterations"},
        {"iterations.max", "", "iterations", B::Lower, M::Max, kInfo, false, 1.0, "iterations"},
        {"checks.false_convergence.total", "", "count", B::Lower, M::Sum, kExact, false, 1.0, "checks"},
        {"checks.oracle_failed", "", "count", B::Lower, M::Sum, kInfo, false, 1.0, "checks"},
        {"time.median_us", "time.all.median_ns", "us", B::Lower, M::Quantile, kMedianTime, true, 1e-3, "time.all"},
        {"time.p99_us", "time.all.p99_ns", "us", B::Lower, M::Quantile, kTailTime, true, 1e-3, "time.all"}}},
      {"baselines", "baselines.",
       {{"genuine_total", "", "count", B::Lower, M::Sum},
        {"idcol_outside_bracket", "", "count", B::Lower, M::Sum},
        {"oracle_failed", "", "count", B::Lower, M::Sum}}},
      {"baselines.status.*", "baselines.{key}.",
       {{"genuine", "", "count", B::Lower, M::Sum},
        {"band", "", "count", B::Neither, M::Sum},
        {"failed", "", "count", B::Lower, M::Sum}}},
      {"baselines", "baselines.",
       {{"alpha_abs_err.mean", "", "1", B::Lower, M::Ratio},
        {"alpha_abs_err.p99", "", "1", B::Lower, M::Quantile},
        {"alpha_abs_err.max", "", "1", B::Lower, M::Max},
        {"alpha_rel_err.mean", "", "1", B::Lower, M::Ratio},
        {"alpha_rel_err.p99", "", "1", B::Lower, M::Quantile},
        {"alpha_rel_err.max", "", "1", B::Lower, M::Max},
        {"normal_angle_rad.p99", "", "rad", B::Lower, M::Quantile},
        {"normal_angle_rad.max", "", "rad", B::Lower, M::Max}}},
      // Each method's median time per query over FCL's collide, on the same poses.
      {"baselines.timing.methods.*", "timing.{key}/",
       {{"fcl_collide", "median_ns", "1", B::Lower, M::Quantile, kInfo, true}}, "fcl_collide"},
      {"derivatives", "derivatives.",
       {{"agreement", "", "fraction", B::Higher, M::Ratio},
        {"disagree_unflagged", "", "count", B::Lower, M::Sum},
        {"worst_error", "", "1", B::Lower, M::Max}}},
  }};
  return t;
}

}  // namespace idcol::harness
