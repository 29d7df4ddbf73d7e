#pragma once

#include "studies/metric.hpp"

namespace idcol::harness {

/// The metrics of a time-of-impact results file's entries (a pair under one motion model).
const MetricTable& toi_metrics();

}  // namespace idcol::harness
