// The stress suite's metrics, per case: every figure compare reads from a
// stress results file, declared once (study/metric.hpp explains the fields).
#include "studies/stress/stress_metrics.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
}  // namespace

const MetricTable& stress_metrics() {
  static const MetricTable t{{
      {"passes.*", "{key}.",
       {{"genuine_rate", "", "fraction", B::Higher, M::Ratio, kExact},
        {"failures", "", "count", B::Lower, M::Sum, kExact},
        {"false_convergence.total", "", "count", B::Lower, M::Sum, kExact},
        {"concentric.wrong", "", "count", B::Lower, M::Sum},
        {"reference_solve_failed", "", "count", B::Lower, M::Sum},
        {"oracle.oracle_failed", "", "count", B::Lower, M::Sum},
        {"oracle.worst_relative_error", "", "1", B::Lower, M::Max},
        {"oracle.worst_bracket_violation", "", "1", B::Lower, M::Max},
        {"worst_residual", "", "1", B::Lower, M::Max},
        {"worst_surface_error", "", "1", B::Lower, M::Max},
        {"worst_normal_error", "", "1", B::Lower, M::Max},
        {"iterations.mean", "", "iterations", B::Lower, M::Ratio},
        {"iterations.max", "", "iterations", B::Lower, M::Max},
        {"conditioning.unreliable", "", "count", B::Lower, M::Sum}}},
      {"derivatives", "derivatives.",
       {{"agreement", "", "fraction", B::Higher, M::Ratio},
        {"disagree_unflagged", "", "count", B::Lower, M::Sum},
        {"worst_error_unflagged", "", "1", B::Lower, M::Max}}},
  }};
  return t;
}

}  // namespace idcol::harness
