// Scene files: TOML descriptions of what a study runs. One reader takes
// every kind: a sweep (shapes, pairs, the pose sweep, the passes and what to
// record), a stress suite ([[case]] tables, stress.hpp) and a smoothing grid
// ([grid], smoothing.hpp). See configs/*.toml and
// harness/README.md for the schema.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "idcol/options.hpp"
#include "idcol/shapes.hpp"
#include "referee/checks.hpp"
#include "gen/poses.hpp"
#include "gen/random_bodies.hpp"

namespace idcol::harness {

/// A malformed scene. what() reads "<file>: <field>: <what was expected>".
class SceneError : public std::runtime_error {
 public:
  SceneError(const std::string& file, const std::string& field, const std::string& msg)
      : std::runtime_error(file + ": " + field + ": " + msg), file_(file), field_(field) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_, field_;
};

/// One named shape as the scene gives it: the parameters as written, and the
/// validated shape built from them.
struct ShapeSpec {
  std::string name;
  std::string family;
  std::vector<std::pair<std::string, double>> scalars;  // in the family's canonical order
  std::vector<Vec3> normals;                            // polytope, half-space form
  std::vector<double> offsets;
  std::vector<Vec3> vertices;                           // polytope, vertex form
  std::optional<Shape> shape;
};

enum class Pass { Cold, Warm };
const char* to_string(Pass p);

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

class Reader;  // scene_toml.hpp
struct Scene;

/// A kind of scene as its file shows it: the study it is for ("sweep",
/// "stress", "smoothing"), the table whose presence makes a file that kind
/// (nullptr: a file with none of the others'), and the reader of its
/// sections. The studies' table (studies/study.hpp) is keyed by the same name.
struct SceneKind {
  const char* name;
  const char* section;
  void (*read)(Reader& top, const std::string& file, Scene& s);
};
/// Every kind of scene, in the order their sections are looked for.
const std::vector<SceneKind>& scene_kinds();

struct Scene {
  std::string path;  // as given on the command line
  std::string text;  // the file's content, stored in every results file
  std::string name;
  std::string description;
  std::vector<ShapeSpec> shapes;  // in file order (a smoothing grid has none)
  // The sweep ([sweep], [run], [baselines], [derivatives]); a smoothing grid
  // reads poses, dt and warmup from its optional [sweep].
  bool all_pairs = false;
  std::vector<std::pair<int, int>> pairs;  // indices into shapes, resolved
  GeneratorKind generator = GeneratorKind::Paper;
  std::uint64_t poses = 0;
  double dt = 1e-4;
  /// Warm pass: the warm-start chain restarts (first pose solved without a
  /// warm start) every warm_chain poses, so that shards and threads split
  /// the sweep at chain boundaries and reproduce the unsharded run exactly.
  std::uint64_t warm_chain = 10000;
  /// Untimed solves (poses 0..warmup-1) before each timed pass.
  std::uint64_t warmup = 1000;
  /// [run] timed_path = "batch": the timed passes go through solve_batch on
  /// one thread (blocks of poses timed as a whole) instead of the loop of
  /// solve() (each solve timed on its own, "loop", the default).
  bool timed_batch = false;
  std::vector<Pass> passes;
  RecordSpec record;
  BaselineSpec baselines;
  ReferenceSpec reference;
  DerivativeSpec derivatives;
  SolverOptions solver;
  std::vector<StressCase> cases;  // [[case]]: given in, and only in, a stress scene
  std::optional<GridSpec> grid;   // [grid]: a smoothing grid
  std::optional<ToiSpec> toi;     // [toi]: a time-of-impact study
  /// What the file describes (scene_kinds()): chosen by which section it has.
  const SceneKind* kind = nullptr;
};

/// Parses a scene of any kind from TOML text (a [[case]] makes it a stress
/// scene, a [grid] a smoothing grid); `file` names it in error messages,
/// which read "<file>: <field>: <what was expected>".
Scene parse_scene(const std::string& text, const std::string& file);
/// Reads and parses a scene file.
Scene load_scene(const std::string& path);
/// The text of a scene file of any kind; throws SceneError if it cannot be read.
std::string read_scene_file(const std::string& path);
/// The run.record items a RecordSpec asks for, in the scene's order.
std::vector<std::string> record_names(const RecordSpec& r);
/// A TOML text that parses back to the same sweep scene (numbers at 17 digits).
std::string scene_to_toml(const Scene& s);
/// The name and sections of a scene of each kind (the `read` of its row of
/// scene_kinds()), read after its description and [solver].
void read_sweep_scene(Reader& top, const std::string& file, Scene& s);
void read_stress_scene(Reader& top, const std::string& file, Scene& s);
void read_smoothing_scene(Reader& top, const std::string& file, Scene& s);
void read_toi_scene(Reader& top, const std::string& file, Scene& s);

/// One shape family as a scene writes it: its name, its parameters (key,
/// meaning, constraint) and an example inline table. The scene reader takes
/// the scalar keys from here and builds the shape from them, in this order,
/// with shape_with_params(prototype, ...) (idcol/shape_params.hpp), and
/// `idcol_harness shapes` prints it. The polytope (no prototype) and the
/// generated polytopes (box, facet_sphere, vertex_sphere) have their own
/// branches. This is the one catalogue of what a scene may name.
struct FamilyParam {
  const char* key;
  const char* meaning;
};
struct FamilyDoc {
  const char* family;
  const char* summary;
  /// The body's frame as the solver uses it: its axis of symmetry, or what
  /// its parameters lie along.
  const char* axes;
  std::vector<FamilyParam> params;
  const char* example;
  std::optional<Shape> prototype;  // the example's shape
  /// A generated shape: not a family of core but a smooth_polytope the
  /// reader builds from these parameters (read_generated_shape).
  bool generated = false;
};
const std::vector<FamilyDoc>& shape_families();

/// Parses one shape from a TOML inline table, in exactly the form
/// idcol::describe prints. `file` and `field` name it in errors.
ShapeSpec parse_shape_inline(const std::string& inline_table, const std::string& file, const std::string& field);

}  // namespace idcol::harness
