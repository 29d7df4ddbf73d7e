#pragma once

#include "studies/metric.hpp"

namespace idcol::harness {

/// The metrics of a sweep results file's pairs.
const MetricTable& sweep_metrics();

}  // namespace idcol::harness
