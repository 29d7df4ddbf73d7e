// The smoothing study: error against run time over a sharpness grid. A grid
// file (configs/smoothing_*.toml: a scene with a [grid], GridSpec in
// smoothing_spec.hpp) names one family's shape without its sharpness, the
// parameter ("beta" or "n") and its values, the partner sphere, the sweep,
// and optionally a [solver] table; see smoothing.cpp for what is measured
// at each grid point. Built only with the baselines (the exact oracles).
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "studies/study.hpp"
#include "scene/scene.hpp"

namespace idcol::harness {

/// Runs the study, the non-timing passes on opt.threads threads and the
/// timing passes on one, pinned to opt.pin (-1: none); returns the results
/// file (schema kSmoothingSchema) and appends the failed solves to
/// `failures` (numbered for opt.failures_path).
nlohmann::json run_smoothing(const Scene& scene, const StudyOptions& opt, const nlohmann::json& metadata,
                             nlohmann::json& failures);

/// The smoothing study of a scene: smoothing_study.cpp where the baselines
/// were built; smoothing_none.cpp (a SceneError) where they were not.
std::unique_ptr<Study> make_smoothing_study(Scene s);

}  // namespace idcol::harness
