// The stress suite's metrics, per case: every figure compare reads from a
// stress results file, declared once (study/metric.hpp explains the fields).
#include "studies/stress/stress_metrics.hpp"

#include "studies/stress/stress_keys.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
namespace k = key;
}  // namespace

const MetricTable& stress_metrics() {
  static const MetricTable t{{
      {"passes.*", "{key}.",
       {{k::genuine_rate, "", "fraction", B::Higher, M::Ratio, kExact},
        {k::failures, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::false_convergence, k::total>, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::concentric, k::wrong>, "", "count", B::Lower, M::Sum},
        {k::reference_solve_failed, "", "count", B::Lower, M::Sum},
        {k::dotted<k::oracle, k::oracle_failed>, "", "count", B::Lower, M::Sum},
        {k::dotted<k::oracle, k::worst_relative_error>, "", "1", B::Lower, M::Max},
        {k::dotted<k::oracle, k::worst_bracket_violation>, "", "1", B::Lower, M::Max},
        {k::worst_residual, "", "1", B::Lower, M::Max},
        {k::worst_surface_error, "", "1", B::Lower, M::Max},
        {k::worst_normal_error, "", "1", B::Lower, M::Max},
        {k::dotted<k::iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio},
        {k::dotted<k::iterations, k::max>, "", k::iterations, B::Lower, M::Max},
        {k::dotted<k::conditioning, k::unreliable>, "", "count", B::Lower, M::Sum}}},
      {"derivatives", "derivatives.",
       {{k::agreement, "", "fraction", B::Higher, M::Ratio},
        {k::disagree_unflagged, "", "count", B::Lower, M::Sum},
        {k::worst_error_unflagged, "", "1", B::Lower, M::Max}}},
  }};
  return t;
}

}  // namespace idcol::harness
