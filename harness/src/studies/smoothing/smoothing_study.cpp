// The smoothing study of a scene (a build with the baselines' exact oracles).
#include "io/text.hpp"
#include "studies/kinds.hpp"
#include "studies/smoothing/smoothing.hpp"
#include "study/scene_study.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

class SmoothingStudy : public SceneStudy {
 public:
  using SceneStudy::SceneStudy;
  std::vector<std::string> flags() const override { return {"--shard", "--threads", "--pin", "--poses"}; }
  json run(const StudyOptions& o, const json& metadata, RecordSink& sink) override {
    if (o.poses > 0) s_.poses = o.poses;
    json failures = json::array();
    json results = run_smoothing(s_, resolved(o, sink), metadata, failures);
    sink.add(std::move(failures));
    return results;
  }
  std::uint64_t solves(const StudyOptions& o) const override {
    return s_.grid->values.size() * 2 * (o.poses > 0 ? o.poses : s_.poses);  // cold and warm at each grid value
  }
  double estimated_seconds(const StudyOptions&) const override { return 0.0; }  // dominated by the oracles' geometry
  std::string summary(const json& results) const override {
    return format("%s: %zu grid points, %.1f s\n", s_.name.c_str(), results.at("points").size(),
                  results.at("wall_seconds").get<double>());
  }
};
}  // namespace

std::unique_ptr<Study> make_smoothing_study(Scene s) { return std::make_unique<SmoothingStudy>(std::move(s)); }

}  // namespace idcol::harness
