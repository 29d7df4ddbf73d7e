// The time-of-impact study's metrics, per pair and motion model: every
// figure compare reads from a toi results file, declared once
// (studies/metric.hpp explains the fields). A contact idcol misses, or one it
// reports where the oracle sees none, fails; FCL's counts are shown beside
// it, never a verdict on this project.
#include "studies/toi/toi_metrics.hpp"

#include "studies/toi/toi_keys.hpp"

namespace idcol::harness {

namespace {
using B = Better;
using M = MergeRule;
namespace k = key;
// Time per query on a shared machine moves by tens of percent from run to
// run: it only warns.
constexpr DefaultGuard kQueryTime{DefaultGuard::Warn, 0.0, 0.5};
// The time of contact is found to 1e-10 of the motion; the oracle's bisection
// to 1e-18: beyond 1e-8 something changed.
constexpr DefaultGuard kTimeError{DefaultGuard::Fail, 1e-8, 0.0};
}  // namespace

const MetricTable& toi_metrics() {
  static const MetricTable t{{
      {k::oracle_verdicts, "oracle.",
       // The oracle's verdicts are fixed by the scene (the motions and the
       // oracle alone): a change either way means another set of motions.
       {{k::clear_hits, "", "count", B::Neither, M::Same, kExact},
        {k::clear_misses, "", "count", B::Neither, M::Same, kExact},
        {k::grazes, "", "count", B::Neither, M::Same, kExact}}},
      {k::idcol_toi, "idcol.",
       {{k::missed_contacts, "", "count", B::Lower, M::Sum, kExact},
        {k::false_impacts, "", "count", B::Lower, M::Sum, kExact},
        {k::failures, "", "count", B::Lower, M::Sum, kExact},
        {k::impacts, "", "count", B::Neither, M::Sum},
        {k::no_impacts, "", "count", B::Neither, M::Sum},
        {k::initially_in_contact, "", "count", B::Neither, M::Sum},
        {k::dotted<k::t_error, k::max>, "", "1", B::Lower, M::Max, kTimeError},
        {k::solves_per_query, "", "count", B::Lower, M::Ratio},
        {k::us_per_query, "", "us", B::Lower, M::Ratio, kQueryTime, true}}},
      {"fcl.*", "fcl_{key}.",
       {{k::missed_contacts, "", "count", B::Lower, M::Sum},
        {k::false_impacts, "", "count", B::Lower, M::Sum},
        {k::dotted<k::t_error, k::max>, "", "1", B::Lower, M::Max},
        {k::solves_per_query, "", "count", B::Lower, M::Ratio},
        {k::us_per_query, "", "us", B::Lower, M::Ratio, kQueryTime, true}}},
  }};
  return t;
}

}  // namespace idcol::harness
