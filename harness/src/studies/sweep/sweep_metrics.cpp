// The sweep's metrics, per pair: every figure compare reads from a sweep
// results file, declared once (study/metric.hpp explains the fields).
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
}  // namespace

const MetricTable& sweep_metrics() {
  static const MetricTable t{{
      {"passes.*", "{key}.",
       {{k::convergence_rate, "", "fraction", B::Higher, M::Ratio, kExact},
        {k::failures, "", "count", B::Lower, M::Sum, kExact},
        {k::dotted<k::iterations, k::mean>, "", k::iterations, B::Lower, M::Ratio, kInfo, false, 1.0, k::iterations},
        {k::dotted<k::iterations, k::max>, "", k::iterations, B::Lower, M::Max, kInfo, false, 1.0, k::iterations},
        {k::dotted<k::checks, k::false_convergence, k::total>, "", "count", B::Lower, M::Sum, kExact, false, 1.0, k::checks},
        {k::dotted<k::checks, k::oracle_failed>, "", "count", B::Lower, M::Sum, kInfo, false, 1.0, k::checks},
        {"time.median_us", k::dotted<k::time, k::all, k::median_ns>, "us", B::Lower, M::Quantile, kMedianTime, true, 1e-3, k::dotted<k::time, k::all>},
        {"time.p99_us", k::dotted<k::time, k::all, k::p99_ns>, "us", B::Lower, M::Quantile, kTailTime, true, 1e-3, k::dotted<k::time, k::all>}}},
      {"baselines", "baselines.",
       {{k::genuine_total, "", "count", B::Lower, M::Sum},
        {k::idcol_outside_bracket, "", "count", B::Lower, M::Sum},
        {k::oracle_failed, "", "count", B::Lower, M::Sum}}},
      {"baselines.status.*", "baselines.{key}.",
       {{k::genuine, "", "count", B::Lower, M::Sum},
        {k::band, "", "count", B::Neither, M::Sum},
        {k::failed, "", "count", B::Lower, M::Sum}}},
      {"baselines", "baselines.",
       {{k::dotted<k::alpha_abs_err, k::mean>, "", "1", B::Lower, M::Ratio},
        {k::dotted<k::alpha_abs_err, k::p99>, "", "1", B::Lower, M::Quantile},
        {k::dotted<k::alpha_abs_err, k::max>, "", "1", B::Lower, M::Max},
        {k::dotted<k::alpha_rel_err, k::mean>, "", "1", B::Lower, M::Ratio},
        {k::dotted<k::alpha_rel_err, k::p99>, "", "1", B::Lower, M::Quantile},
        {k::dotted<k::alpha_rel_err, k::max>, "", "1", B::Lower, M::Max},
        {k::dotted<k::normal_angle_rad, k::p99>, "", "rad", B::Lower, M::Quantile},
        {k::dotted<k::normal_angle_rad, k::max>, "", "rad", B::Lower, M::Max}}},
      // Each method's median time per query over FCL's collide, on the same poses.
      {"baselines.timing.methods.*", "timing.{key}/",
       {{"fcl_collide", k::median_ns, "1", B::Lower, M::Quantile, kInfo, true}}, "fcl_collide"},
      {"derivatives", "derivatives.",
       {{k::agreement, "", "fraction", B::Higher, M::Ratio},
        {k::disagree_unflagged, "", "count", B::Lower, M::Sum},
        {k::worst_error, "", "1", B::Lower, M::Max}}},
  }};
  return t;
}

}  // namespace idcol::harness
