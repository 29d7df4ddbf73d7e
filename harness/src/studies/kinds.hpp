// The study kinds, one per folder: each defines its StudyKind subclass and
// returns its one object here (studies/registry.cpp lists them).
#pragma once

#include <memory>

#include "scene/scene.hpp"
#include "studies/study.hpp"

namespace idcol::harness {

const StudyKind& sweep_kind();      // studies/sweep/sweep_study.cpp
const StudyKind& stress_kind();     // studies/stress/stress_study.cpp
const StudyKind& smoothing_kind();  // studies/smoothing/smoothing_kind.cpp
const StudyKind& toi_kind();        // studies/toi/toi_kind.cpp

/// The smoothing study of a scene: smoothing_study.cpp where the baselines
/// were built; smoothing_none.cpp (a SceneError) where they were not.
std::unique_ptr<Study> make_smoothing_study(Scene s);

}  // namespace idcol::harness
