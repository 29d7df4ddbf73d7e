// A sweep's own sections of its scene file ([run], [baselines], [reference],
// [derivatives]): their types, read by read_sweep_scene (sweep_scene.cpp)
// into the scene's KindSpec as a SweepSpec, and written back by
// scene_to_toml. Its [shapes] and [sweep] are every kind's (scene/scene.hpp).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.hpp"

namespace idcol::harness {

/// What a run records. Convergence counts by status are always kept.
struct RecordSpec {
  bool timing = false;      // per-solve time (timer overhead subtracted), histograms
  bool iterations = false;  // iteration mean, max, histogram
  bool residuals = false;   // final residual max and percentiles
  bool failures = false;    // a failure record (with the iteration trace) per failed solve
  bool per_pose = false;    // one CSV row per solve
  bool derivatives = false;  // IFT vs finite differences on a subsample ([derivatives])
  bool baselines = false;    // agreement with FCL / libccd / the exact oracles ([baselines])
  bool checks = false;       // every converged answer through checks.hpp (surfaces, normals, oracle), outside the timed region
};

/// [baselines]: which competitors run on which pairs. Every method named must
/// serve every pair named (checked at load time). The agreement pass runs
/// cold iDCOL, the oracle and each boolean on every pose of the shard; with
/// record "timing" it then times every method on the first timing_poses poses
/// of the shard (the same poses for every method).
struct BaselineSpec {
  /// Any of "fcl_collide", "fcl_distance", "ccd_gjk", "ccd_mpr", "oracle".
  std::vector<std::string> methods;
  std::vector<std::pair<int, int>> pairs;  // indices into shapes
  std::uint64_t timing_poses = 1000;
  /// Relative width added on both sides of the smoothing bracket when a
  /// disagreement is classified (the booleans' and oracles' tolerances; see
  /// the README's "Baseline agreement" section).
  double band_tolerance = 1e-6;
  /// Normals are compared only where |alpha* - 1| <= near_contact.
  double near_contact = 1e-2;
  bool has(const std::string& m) const;
  bool covers(int i1, int i2) const;
};

/// [reference]: published figures to print beside this run's, as the
/// paper's Table 2 gives them (mean time per query, us, on the authors'
/// machine): figures[method]["<body1>-<body2>"], a method being a timed
/// method of the agreement pass (idcol_cold, idcol_warm or one of
/// [baselines] methods) and the pair one of [baselines] pairs.
struct ReferenceSpec {
  std::string source;  // where the figures come from (printed with them)
  std::map<std::string, std::map<std::string, double>> mean_us;
  bool empty() const { return mean_us.empty(); }
};

/// [derivatives]: check_derivatives on poses k with k % every == 0.
struct DerivativeSpec {
  std::uint64_t every = 100;
  std::vector<std::pair<int, int>> pairs;
  double h = 1e-5, tolerance = 1e-5;  // DerivativeCheckOptions
  bool covers(int i1, int i2) const;
};

/// A sweep's [run] and the tables it asks for.
struct SweepSpec {
  bool all_pairs = false;
  std::vector<std::pair<int, int>> pairs;  // indices into shapes, resolved
  std::vector<Pass> passes;
  /// [run] timed_path = "batch": the timed passes go through solve_batch on
  /// one thread (blocks of poses timed as a whole) instead of the loop of
  /// solve() (each solve timed on its own, "loop", the default).
  bool timed_batch = false;
  RecordSpec record;
  BaselineSpec baselines;
  ReferenceSpec reference;
  DerivativeSpec derivatives;
};

/// The name and sections of a sweep's scene (SweepStudyKind::read_scene),
/// read after its description and [solver].
void read_sweep_scene(Reader& top, const std::string& file, Scene& s);
/// The run.record items a RecordSpec asks for, in the scene's order.
std::vector<std::string> record_names(const RecordSpec& r);
/// A TOML text that parses back to the same sweep scene (numbers at 17 digits).
std::string scene_to_toml(const Scene& s);

}  // namespace idcol::harness
