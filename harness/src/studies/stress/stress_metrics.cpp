// The stress suite's metrics, per case: every figure compare reads from a
// stress results file, declared once (studies/metric.hpp explains the fields).
#include "studies/stress/stress_metrics.hpp"

#include "studies/stress/stress_keys.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
namespace k = key;
// The worst errors of a pass, each against the check that judges a single
// answer (the file's "thresholds": surface 1e-8, normal 1e-6, bracket and
// closed form 1e-9; the solver's tolerance 1e-10 for the residual). On the
// CI cuts they sit one to three decades below their check. Each fails when
// it doubles and passes a tenth of its check: rounding moves a worst-of-10^3
// by a few ulps times the conditioning, far less; a change that makes
// answers worse moves it by decades before a single pose fails its check.
constexpr DefaultGuard kResidual{DefaultGuard::Fail, 1e-9, 1.0};
constexpr DefaultGuard kSurface{DefaultGuard::Fail, 1e-9, 1.0};
constexpr DefaultGuard kNormal{DefaultGuard::Fail, 1e-7, 1.0};
constexpr DefaultGuard kBracket{DefaultGuard::Fail, 1e-10, 1.0};
// The conditioning estimate flags a pose by a threshold on a pivot ratio:
// a pose at the threshold may flip with rounding (another compiler), so a
// couple of flips pass; a solver landing on worse-conditioned points, or a
// broken estimate, moves many.
constexpr DefaultGuard kUnreliable{DefaultGuard::Fail, 2.0, 0.01};
// The derivative checker's tolerance is 1e-5; see sweep_metrics.cpp.
constexpr DefaultGuard kDerivativeError{DefaultGuard::Fail, 1e-6, 0.5};
}  // namespace

const MetricTable& stress_metrics() {
  static const MetricTable t{{
      {"passes.*", "{key}.",
       {{k::solves, "", "count", B::Neither, M::Sum, kExact},  // fixed by the scene: a pass that empties fails
        {k::genuine_rate, "", "fraction", B::Higher, M::Ratio, kExact},
        {k::failures, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::false_convergence, k::total>, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::concentric, k::wrong>, "", "count", B::Lower, M::Sum, kExact},
        {k::reference_solve_failed, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::oracle, k::checked>, "", "count", B::Neither, M::Sum, kExact, false, 1.0, k::oracle},
        {k::dotted<k::oracle, k::oracle_failed>, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::oracle, k::worst_relative_error>, "", "1", B::Lower, M::Max, kBracket},
        {k::dotted<k::oracle, k::worst_bracket_violation>, "", "1", B::Lower, M::Max, kBracket},
        {k::worst_residual, "", "1", B::Lower, M::Max, kResidual},
        {k::worst_surface_error, "", "1", B::Lower, M::Max, kSurface},
        {k::worst_normal_error, "", "1", B::Lower, M::Max, kNormal},
        {k::dotted<k::iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio},
        {k::dotted<k::iterations, k::max>, "", k::iterations, B::Lower, M::Max},
        {k::dotted<k::conditioning, k::unreliable>, "", "count", B::Lower, M::Sum, kUnreliable}}},
      {"derivatives", "derivatives.",
       {{k::poses, "", "count", B::Neither, M::Sum, kExact},
        {k::agreement, "", "fraction", B::Higher, M::Ratio, kExact},
        {k::disagree_unflagged, "", "count", B::Lower, M::Sum, kExact},
        {k::worst_error_unflagged, "", "1", B::Lower, M::Max, kDerivativeError}}},
  }};
  return t;
}

}  // namespace idcol::harness
