// A stress scene's own sections ([[case]] tables; stress.hpp describes the
// kinds of case): their types, read by read_stress_scene (stress_scene.cpp)
// into the scene's KindSpec as a StressSpec.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gen/poses.hpp"
#include "gen/random_bodies.hpp"
#include "referee/checks.hpp"
#include "scene/scene.hpp"

namespace idcol::harness {

/// One [[case]] of a stress scene (stress.hpp describes the kinds).
enum class StressKind { Shell, Touching, Explicit, RandomBodies };
const char* to_string(StressKind k);  // "shell", "touching", "explicit", "random_bodies"
const char* to_string(TouchOrientation o);  // "uniform", "face", "edge", "vertex"

struct StressCase {
  std::string name;
  int body1 = 0, body2 = 0;  // indices into Scene::shapes
  StressKind kind = StressKind::Shell;
  std::uint64_t poses = 0;
  std::vector<Pass> passes;
  std::uint64_t warm_chain = 1000;
  double rmin = 0.1, rmax = 2.0;  // shell, relative to L
  std::uint64_t zero_every = 0;   // shell
  TouchOrientation orientation = TouchOrientation::Uniform;
  std::vector<double> touch_eps{0.0, 1e-12, -1e-12};
  std::vector<Pose> explicit_poses;
  RandomBodyCase random;  // random_bodies
  OracleChoice oracle = OracleChoice::Auto;
  std::uint64_t oracle_every = 1;
  int derivative_samples = 64;
};

/// A stress scene's cases, in file order.
struct StressSpec {
  std::vector<StressCase> cases;
};

/// The name and sections of a stress scene (StressStudyKind::read_scene),
/// read after its description and [solver].
void read_stress_scene(Reader& top, const std::string& file, Scene& s);

}  // namespace idcol::harness
