// The smoothing study's metrics, per grid point: every figure compare reads
// from a smoothing results file, declared once (studies/metric.hpp explains
// the fields). The accuracy pass is named "accuracy", the timed passes by
// their pass; a grid value the family rejects has none.
#include "studies/smoothing/smoothing_metrics.hpp"

#include "studies/smoothing/smoothing_keys.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
namespace k = key;
}  // namespace

const MetricTable& smoothing_metrics() {
  static const MetricTable t{
      {
          {"cold_accuracy_pass", "accuracy.",
           {{k::converged_fraction, "", "fraction", B::Higher, M::Ratio, kExact},
            {k::oracle_failures, "", "count", B::Lower, M::Sum, kExact},
            {k::dotted<k::alpha_rel_error, k::mean>, "", "1", B::Lower, M::Ratio},
            {k::dotted<k::alpha_rel_error, k::p99>, "", "1", B::Lower, M::Quantile},
            {k::dotted<k::alpha_rel_error, k::max>, "", "1", B::Lower, M::Max},
            {k::dotted<k::iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio}}},
          {"", "",
           {{k::dotted<k::geometry, k::hausdorff_lower_rel>, "", "1", B::Lower, M::Same},
            {k::dotted<k::geometry, k::radial_gap_max_rel>, "", "1", B::Lower, M::Same},
            {k::dotted<k::geometry, k::smooth_outside_exact_count>, "", "count", B::Lower, M::Same},
            {k::dotted<k::smoothness, k::alpha_jump_rel_per_step, k::p99>, "", "1", B::Lower, M::Quantile},
            {k::dotted<k::smoothness, k::normal_jump_per_step, k::p99>, "", "rad", B::Lower, M::Quantile}}},
          {"timing.*", "{key}.",
           {{k::converged_fraction, "", "fraction", B::Higher, M::Ratio, kExact, false, 1.0, k::iterations},
            {k::dotted<k::iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio, kInfo, false, 1.0, k::iterations},
            {k::dotted<k::iterations, k::max>, "", k::iterations, B::Lower, M::Max, kInfo, false, 1.0, k::iterations}}},
      },
      "valid"};
  return t;
}

}  // namespace idcol::harness
