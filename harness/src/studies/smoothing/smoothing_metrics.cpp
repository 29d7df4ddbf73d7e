// The smoothing study's metrics, per grid point: every figure compare reads
// from a smoothing results file, declared once (study/metric.hpp explains
// the fields). The accuracy pass is named "accuracy", the timed passes by
// their pass; a grid value the family rejects has none.
#include "studies/smoothing/smoothing_metrics.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
}  // namespace

const MetricTable& smoothing_metrics() {
  static const MetricTable t{
      {
          {"cold_accuracy_pass", "accuracy.",
           {{"converged_fraction", "", "fraction", B::Higher, M::Ratio, kExact},
            {"oracle_failures", "", "count", B::Lower, M::Sum, kExact},
            {"alpha_rel_error.mean", "", "1", B::Lower, M::Ratio},
            {"alpha_rel_error.p99", "", "1", B::Lower, M::Quantile},
            {"alpha_rel_error.max", "", "1", B::Lower, M::Max},
            {"iterations.mean", "", "iterations", B::Lower, M::Ratio}}},
          {"", "",
           {{"geometry.hausdorff_lower_rel", "", "1", B::Lower, M::Same},
            {"geometry.radial_gap_max_rel", "", "1", B::Lower, M::Same},
            {"geometry.smooth_outside_exact_count", "", "count", B::Lower, M::Same},
            {"smoothness.alpha_jump_rel_per_step.p99", "", "1", B::Lower, M::Quantile},
            {"smoothness.normal_jump_per_step.p99", "", "rad", B::Lower, M::Quantile}}},
          {"timing.*", "{key}.",
           {{"converged_fraction", "", "fraction", B::Higher, M::Ratio, kExact, false, 1.0, "iterations"},
            {"iterations.mean", "", "iterations", B::Lower, M::Ratio, kInfo, false, 1.0, "iterations"},
            {"iterations.max", "", "iterations", B::Lower, M::Max, kInfo, false, 1.0, "iterations"}}},
      },
      "valid"};
  return t;
}

}  // namespace idcol::harness
