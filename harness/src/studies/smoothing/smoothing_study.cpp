// The smoothing study of a scene (a build with the baselines' exact oracles).
#include <algorithm>
#include <optional>
#include <variant>

#include "io/text.hpp"
#include "scene/scene.hpp"
#include "studies/smoothing/smoothing.hpp"
#include "studies/smoothing/smoothing_spec.hpp"
#include "studies/cost_model.hpp"
#include "studies/entry_shards.hpp"
#include "studies/scene_study.hpp"

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
  /// Cold and warm at each of the shard's grid values (i, i + N, ...).
  std::uint64_t solves(const StudyOptions& o) const override {
    const std::size_t n = s_.spec.as<GridSpec>().values.size();
    std::uint64_t values = 0;
    for (std::size_t i = 0; i < n; ++i) values += in_shard(i, o.shard_index, o.shard_count);
    return count_product(2 * values, o.poses > 0 ? static_cast<std::uint64_t>(o.poses) : s_.poses);
  }
  /// Per valid grid point: the Hausdorff directions, the accuracy pass on
  /// the threads, the two timed passes on one, and (superellipsoid) the
  /// support-function oracle's cross-check. Estimated against measured
  /// wall time of the command: `smoothing configs/smoothing_polytope.toml
  /// --poses 2000` 4.3 s against 2.97 s (200 poses: 1.6 s against 2.06 s;
  /// 8000: 13 s against 15.95 s; the 100000 of
  /// results/smoothing_polytope.json: 2.5 min against 182 s);
  /// smoothing_superellipsoid --poses 2000 3.5 s against 2.28 s (100000:
  /// 28 s against 18.8 s); smoothing_cone --poses 2000 1.8 s against 1.54 s
  /// (100000: 20 s against 16.5 s).
  std::vector<CostPart> estimate(const StudyOptions& o) const override {
    const GridSpec& g = s_.spec.as<GridSpec>();
    const double threads = o.threads > 0 ? o.threads : kind().default_threads;
    const double poses = static_cast<double>(o.poses > 0 ? o.poses : s_.poses);
    const double warmup = std::min(static_cast<double>(s_.warmup), poses);
    const Shape partner = Sphere(g.partner_radius);
    double geometry_s = 0.0, accuracy_s = 0.0, solve_s = 0.0, oracle_s = 0.0;
    for (std::size_t i = 0; i < g.values.size(); ++i) {
      if (!in_shard(i, o.shard_index, o.shard_count)) continue;
      std::optional<Shape> S;
      try {
        S = parse_shape_inline(g.shape_texts[i], s_.path, "grid.values[" + std::to_string(i) + "]").shape;
      } catch (const std::exception&) {
        continue;  // an invalid grid value is recorded as such, not run
      }
      if (!S) continue;
      const bool polytope = std::holds_alternative<SmoothPolytope>(*S);
      geometry_s += g.directions * cost::smoothing_direction;
      accuracy_s += poses * (polytope ? cost::smoothing_pose_polytope : cost::smoothing_pose_smooth) / threads;
      solve_s += 2 * (poses + warmup) * cost::solve;
      if (std::holds_alternative<Superellipsoid>(*S)) oracle_s += g.oracle_check_poses * cost::oracle_query(partner, *S);
    }
    std::vector<CostPart> parts{{"solves", solve_s}, {"accuracy pass", accuracy_s}, {"geometry", geometry_s}};
    if (oracle_s > 0) parts.push_back({"oracles", oracle_s});
    return parts;
  }
  std::string summary(const json& results) const override {
    return format("%s: %zu grid points, %.1f s\n", s_.name.c_str(), results.at("points").size(),
                  results.at("wall_seconds").get<double>());
  }
};
}  // namespace

std::unique_ptr<Study> make_smoothing_study(Scene s) { return std::make_unique<SmoothingStudy>(std::move(s)); }

}  // namespace idcol::harness
