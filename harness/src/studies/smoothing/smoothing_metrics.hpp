#pragma once

#include "studies/metric.hpp"

namespace idcol::harness {

/// The metrics of a smoothing results file's grid points.
const MetricTable& smoothing_metrics();

}  // namespace idcol::harness
