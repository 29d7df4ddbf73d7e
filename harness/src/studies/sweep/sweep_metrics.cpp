// The sweep's metrics, per pair: every figure compare reads from a sweep
// results file, declared once (studies/metric.hpp explains the fields).
#include "studies/sweep/sweep_metrics.hpp"

#include "studies/sweep/sweep_keys.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
namespace k = key;
// Time per solve on shared machines moves by 10-30% from run to run: its
// default guards only warn.
constexpr DefaultGuard kMedianTime{DefaultGuard::Warn, 0.0, 0.3};
constexpr DefaultGuard kTailTime{DefaultGuard::Warn, 0.0, 0.5};
// Each method's median time over FCL's on the same poses in the same run:
// the machine's load cancels in part, but medians of a few hundred queries
// still move by tens of percent; it warns only (instructions per solve,
// counted by callgrind, are the speed guard that fails: ci_instructions.sh).
constexpr DefaultGuard kTimeRatio{DefaultGuard::Warn, 0.0, 0.5};
// The worst derivative error over the checked poses: the checker's verdict
// is agreement within 1e-5 (DerivativeCheckOptions::tolerance); the
// worst error sits at 1e-10..3e-6 on the CI scene. A growth beyond half
// again and beyond a tenth of the tolerance fails well before poses start
// to disagree, and a derivative off by 0.1% (an error of 1e-3) fails at once.
constexpr DefaultGuard kDerivativeError{DefaultGuard::Fail, 1e-6, 0.5};
// The answer checks' worst errors (record "checks"), guarded as the stress
// suite guards the same checks (stress_metrics.cpp): each fails when it
// doubles and passes a tenth of the check that judges a single answer.
constexpr DefaultGuard kCheckSurface{DefaultGuard::Fail, 1e-9, 1.0};
constexpr DefaultGuard kCheckNormal{DefaultGuard::Fail, 1e-7, 1.0};
constexpr DefaultGuard kCheckAlpha{DefaultGuard::Fail, 1e-10, 1.0};
}  // namespace

const MetricTable& sweep_metrics() {
  static const MetricTable t{{
      {"passes.*", "{key}.",
       {{k::solves, "", "count", B::Neither, M::Sum, kExact},  // fixed by the scene: a pass that empties fails
        {k::convergence_rate, "", "fraction", B::Higher, M::Ratio, kExact},
        {k::failures, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio, kInfo, false, 1.0, k::iterations},
        {k::dotted<k::iterations, k::max>, "", k::iterations, B::Lower, M::Max, kInfo, false, 1.0, k::iterations},
        {k::dotted<k::checks, k::false_convergence, k::total>, "", "count", B::Lower, M::Sum, kExact, false, 1.0, k::checks},
        {k::dotted<k::checks, k::oracle_failed>, "", "count", B::Lower, M::Sum, kExact, false, 1.0, k::checks},
        {k::dotted<k::checks, k::checked>, "", "count", B::Neither, M::Sum, kExact, false, 1.0, k::checks},
        {k::dotted<k::checks, k::worst_surface_error>, "", "1", B::Lower, M::Max, kCheckSurface, false, 1.0, k::checks},
        {k::dotted<k::checks, k::worst_normal_error>, "", "1", B::Lower, M::Max, kCheckNormal, false, 1.0, k::checks},
        {k::dotted<k::checks, k::worst_alpha_error>, "", "1", B::Lower, M::Max, kCheckAlpha, false, 1.0, k::checks},
        {"time.median_us", k::dotted<k::time, k::all, k::median_ns>, "us", B::Lower, M::Quantile, kMedianTime, true, 1e-3, k::dotted<k::time, k::all>},
        {"time.p99_us", k::dotted<k::time, k::all, k::p99_ns>, "us", B::Lower, M::Quantile, kTailTime, true, 1e-3, k::dotted<k::time, k::all>}}},
      {"baselines", "baselines.",
       {{k::genuine_total, "", "count", B::Lower, M::Sum, kExact},
        {k::idcol_outside_bracket, "", "count", B::Lower, M::Sum, kExact},
        {k::oracle_failed, "", "count", B::Lower, M::Sum, kExact}}},
      {"baselines.status.*", "baselines.{key}.",
       // queries: fixed by the scene; a method's table that empties fails.
       {{k::queries, "", "count", B::Neither, M::Sum, kExact},
        {k::genuine, "", "count", B::Lower, M::Sum, kExact},
        {k::band, "", "count", B::Neither, M::Sum},
        {k::failed, "", "count", B::Lower, M::Sum, kExact}}},
      {"baselines", "baselines.",
       {{k::dotted<k::alpha_abs_err, k::mean>, "", "1", B::Lower, M::Ratio},
        {k::dotted<k::alpha_abs_err, k::p99>, "", "1", B::Lower, M::Quantile},
        {k::dotted<k::alpha_abs_err, k::max>, "", "1", B::Lower, M::Max},
        {k::dotted<k::alpha_rel_err, k::mean>, "", "1", B::Lower, M::Ratio},
        {k::dotted<k::alpha_rel_err, k::p99>, "", "1", B::Lower, M::Quantile},
        {k::dotted<k::alpha_rel_err, k::max>, "", "1", B::Lower, M::Max}}},
      // What each method answers besides its boolean: its alpha* against the
      // oracle beyond its own bound fails (a genuine disagreement); the rest
      // is reported.
      {"baselines.answers.*", "baselines.{key}.",
       {{k::alpha_poses, "", "count", B::Neither, M::Sum},
        {k::alpha_outside_bound, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::alpha_rel_err, k::p99>, "", "1", B::Lower, M::Quantile},
        {k::dotted<k::alpha_rel_err, k::max>, "", "1", B::Lower, M::Max},
        {k::dotted<k::alpha_rel_diff_idcol, k::max>, "", "1", B::Neither, M::Max},
        {k::dotted<k::method_iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio},
        {k::dotted<k::normal_angle_rad, k::p99>, "", "rad", B::Lower, M::Quantile},
        {k::dotted<k::normal_angle_rad, k::max>, "", "rad", B::Lower, M::Max}}},
      // Each method's median time per query over FCL's collide, on the same poses.
      {"baselines.timing.methods.*", "timing.{key}/",
       {{"fcl_collide", k::median_ns, "1", B::Lower, M::Quantile, kTimeRatio, true}}, "fcl_collide"},
      {"derivatives", "derivatives.",
       {{k::poses, "", "count", B::Neither, M::Sum, kExact},
        {k::agreement, "", "fraction", B::Higher, M::Ratio, kExact},
        {k::disagree_unflagged, "", "count", B::Lower, M::Sum, kExact},
        {k::worst_error, "", "1", B::Lower, M::Max, kDerivativeError}}},
  }};
  return t;
}

}  // namespace idcol::harness
