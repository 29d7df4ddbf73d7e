// A time-of-impact study's own section of its scene file (toi_spec.hpp).
#include "studies/toi/toi_spec.hpp"

#include "scene/scene_toml.hpp"

namespace idcol::harness {

void read_toi_scene(Reader& top, const std::string& file, Scene& s) {
  s.name = read_scene_name(top, file);
  read_shapes(top, file, s, true);
  ToiSpec& t = s.spec.emplace<ToiSpec>();
  Reader r(*top.table("toi", true), file, "toi");
  read_pair_list(s, r, "pairs", "", true, "expected an array of [name, name] arrays", t.pairs);
  if (t.pairs.empty()) r.fail("pairs", "expected an array of [name, name] arrays");
  t.motions = r.count("motions", true, t.motions, false);
  if (r.get("models", false, "an array of strings")) t.models = r.strings("models", true);
  if (t.models.empty()) r.fail("models", "expected some of \"translation\", \"screw\"");
  for (std::size_t i = 0; i < t.models.size(); ++i) {
    if (t.models[i] != "translation" && t.models[i] != "screw")
      r.fail("models", "expected \"translation\" or \"screw\", got \"" + t.models[i] + "\"");
    for (std::size_t j = 0; j < i; ++j)
      if (t.models[i] == t.models[j]) r.fail("models", "\"" + t.models[i] + "\" given twice");
  }
  t.seed = r.count("seed", false, t.seed, true);
  if (t.seed > (1u << 20)) r.fail("seed", "expected an integer in [0, 1048576], got " + std::to_string(t.seed));
  if (t.motions > (1u << 20)) r.fail("motions", "expected at most 1048576, got " + std::to_string(t.motions));
  t.oracle_samples = r.bounded_int("oracle_samples", false, t.oracle_samples, 10, 1000000);
  auto in_range = [&](const char* key, double& v, double lo, double hi) {
    v = r.number(key, false, v);
    if (!(v >= lo && v <= hi)) r.fail(key, "expected a number in [" + fmt17(lo) + ", " + fmt17(hi) + "], got " + fmt17(v));
  };
  in_range("graze", t.graze, 0.0, 0.5);
  in_range("spread", t.spread, 0.0, 10.0);
  in_range("offset", t.offset, 0.0, 10.0);
  in_range("turn_min", t.turn_min, 0.0, 3.14159);
  in_range("turn_max", t.turn_max, t.turn_min, 3.14159);
  in_range("end_inside", t.end_inside, 0.0, 1.0);
  if (r.get("fcl", false, "an array of strings")) t.fcl = r.strings("fcl", true);
  for (const std::string& m : t.fcl)
    if (m != "naive" && m != "conservative_advancement")
      r.fail("fcl", "expected \"naive\" or \"conservative_advancement\", got \"" + m + "\"");
  t.fcl_naive_steps = r.bounded_int("fcl_naive_steps", false, t.fcl_naive_steps, 2, 100000);
  r.finish();
}

}  // namespace idcol::harness
