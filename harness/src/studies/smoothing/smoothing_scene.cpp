// A smoothing grid's own sections of its scene file (smoothing_spec.hpp).
#include "studies/smoothing/smoothing_spec.hpp"

#include <cmath>
#include <sstream>

#include "scene/scene_toml.hpp"

namespace idcol::harness {

namespace {

/// A smoothing study's [grid] and [study].
void read_grid(Reader& top, const std::string& file, GridSpec& c) {
  Reader g(*top.table("grid", true), file, "grid");
  const toml::table* shape = g.table("shape", true);
  c.parameter = g.string("parameter");
  if (c.parameter != "beta" && c.parameter != "n") g.fail("parameter", "expected \"beta\" or \"n\", got \"" + c.parameter + "\"");
  c.values = g.numbers("values");
  if (c.values.empty()) g.fail("values", "expected a non-empty array of numbers");
  c.partner_radius = g.number("partner_radius", false, c.partner_radius);
  if (!(c.partner_radius > 0.0) || !std::isfinite(c.partner_radius))
    g.fail("partner_radius", "expected a finite number > 0, got " + fmt17(c.partner_radius));
  g.finish();
  // The shape at each value, as text for the harness's shape parser (so a
  // scene and the grid accept the same text).
  for (double v : c.values) {
    toml::table t = *shape;
    t.insert_or_assign(c.parameter, v);
    t.is_inline(true);
    std::ostringstream st;
    st << t;
    c.shape_texts.push_back(st.str());
  }
  if (const toml::table* t = top.table("study", false)) {
    Reader s(*t, file, "study");
    c.directions = s.bounded_int("hausdorff_directions", false, c.directions, 1, kMaxSamples);
    c.oracle_check_poses = s.bounded_int("oracle_check_poses", false, c.oracle_check_poses, 1, kMaxSamples);
    c.recommend_error_below = s.number("recommend_error_below", false, c.recommend_error_below);
    if (!(c.recommend_error_below > 0.0 && c.recommend_error_below < 1.0))
      s.fail("recommend_error_below", "expected a number in (0, 1), the alpha* p99 relative error below which a value may be "
                                      "recommended (default 0.01), got " + fmt17(c.recommend_error_below));
    s.finish();
  }
}

}  // namespace

void read_smoothing_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file, "smoothing");
  // No [shapes]: the grid gives its one shape.
  read_grid(top, file, s.spec.emplace<GridSpec>());
  s.poses = 10000;
  s.warmup = 500;
  read_sweep_table(top, file, s, false);
}

}  // namespace idcol::harness
