// What every study of a scene keeps (its scene and the scene's text), the
// base of each kind's Study.
#pragma once

#include <utility>

#include "scene/scene.hpp"
#include "studies/study.hpp"

namespace idcol::harness {

/// What every study keeps: its scene, and the scene's text for the results.
class SceneStudy : public Study {
 public:
  explicit SceneStudy(Scene s) : s_(std::move(s)), text_{s_.path, s_.name, s_.text} {}
  const StudyKind& kind() const override { return *study_kind_named(s_.kind); }
  const SceneText& scene() const override { return text_; }
  const SolverOptions& solver() const override { return s_.solver; }

 protected:
  /// `o` as the study's runner takes it: the failures file named, the
  /// study's default threads filled in.
  StudyOptions resolved(StudyOptions o, const RecordSink& sink) const {
    o.failures_path = sink.failures_path;
    if (o.threads <= 0) o.threads = kind().default_threads;
    return o;
  }

  Scene s_;
  SceneText text_;
};

}  // namespace idcol::harness
