// A smoothing grid's own sections of its scene file ([grid] and [study]):
// their type, read by read_smoothing_scene (smoothing_scene.cpp) into the
// scene's KindSpec as a GridSpec. Its optional [sweep] is every kind's
// (scene/scene.hpp).
#pragma once

#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace idcol::harness {

/// [grid] of a smoothing study (smoothing.hpp): one family's shape without
/// its sharpness, the parameter and its values, and the partner sphere.
struct GridSpec {
  std::string parameter;               // "beta" or "n"
  std::vector<double> values;
  std::vector<std::string> shape_texts;  // the grid's shape at each value, as a [shapes] inline table
  double partner_radius = 0.75;
  int directions = 20000;               // [study] hausdorff_directions
  int oracle_check_poses = 200;         // [study]
  /// [study] recommend_error_below: the recommendation (scripts/plot_smoothing.py)
  /// is the smallest value whose alpha* p99 relative error is below this
  /// and whose every pose converged; in (0, 1), recorded in the results.
  double recommend_error_below = 0.01;
};

/// The name and sections of a smoothing grid's scene
/// (SmoothingStudyKind::read_scene), read after its description and [solver].
void read_smoothing_scene(Reader& top, const std::string& file, Scene& s);

}  // namespace idcol::harness
