// A time-of-impact study's own section of its scene file ([toi]): its type,
// read by read_toi_scene (toi_scene.cpp) into the scene's KindSpec as a
// ToiSpec.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.hpp"

namespace idcol::harness {

/// [toi] of a time-of-impact study (studies/toi/toi.hpp): the pairs, how
/// many motions of each model, and what the oracle and FCL are asked.
struct ToiSpec {
  std::vector<std::pair<int, int>> pairs;  // indices into shapes
  std::uint64_t motions = 100;             // per pair and model
  std::vector<std::string> models{"translation", "screw"};  // "translation" (R1 = R0) and/or "screw"
  std::uint64_t seed = 1;                  // motion k of the scene draws Halton points 2 (seed M + k) and 2 (seed M + k) + 1
  int oracle_samples = 1000;               // bracket evaluations along each motion (baselines/toi_oracle.hpp)
  double graze = 1e-3;                     // |alpha* - 1| at the deepest sample below which no verdict is drawn
  /// Where each motion starts and ends, in units of L = outer radius 1 +
  /// outer radius 2: |p0| and |p1| in [1, 1 + spread] L (both ends apart),
  /// p1 on the far side shifted sideways by up to `offset` L (so that some
  /// motions pass by), and the screw's turn in [turn_min, turn_max] rad.
  double spread = 0.5, offset = 1.2, turn_min = 0.3, turn_max = 2.5;
  /// Fraction of motions whose end X1 is drawn inside L (the bodies may
  /// overlap at t = 1).
  double end_inside = 0.25;
  /// FCL's continuousCollide methods to run beside ("naive",
  /// "conservative_advancement"), where this build has FCL and the pair is
  /// one FCL represents; the naive method's number of poses.
  std::vector<std::string> fcl{"naive", "conservative_advancement"};
  int fcl_naive_steps = 100;
};

/// The name and sections of a time-of-impact study's scene
/// (ToiStudyKind::read_scene), read after its description and [solver].
void read_toi_scene(Reader& top, const std::string& file, Scene& s);

}  // namespace idcol::harness
