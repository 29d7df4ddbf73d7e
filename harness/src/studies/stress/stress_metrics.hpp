#pragma once

#include "studies/metric.hpp"

namespace idcol::harness {

/// The metrics of a stress results file's cases.
const MetricTable& stress_metrics();

}  // namespace idcol::harness
