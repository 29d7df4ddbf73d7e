// Scene files: TOML descriptions of what a study runs. What every kind of
// scene shares is here: the shapes (the catalogue of families), the pose
// sweep's [sweep] table, [solver], SceneError, and the Scene a file is read
// into. The sections only one kind has, their types and their reader, are
// that kind's, in its folder (studies/<kind>/<kind>_spec.hpp), and the
// Scene holds them as its KindSpec. A whole file is read by parse_scene
// (studies/study.hpp), which picks the kind from the sections the file has.
// See configs/*.toml and harness/README.md for the schema.
#pragma once

#include <any>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "idcol/families.hpp"
#include "idcol/options.hpp"
#include "idcol/shapes.hpp"
#include "gen/poses.hpp"

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

class Reader;  // scene_toml.hpp

/// The sections of a scene that only its kind has, as that kind's reader
/// leaves them: one value of the kind's own type (SweepSpec, StressSpec,
/// GridSpec, ToiSpec: studies/<kind>/<kind>_spec.hpp), which scene/ holds
/// without knowing it. as<T>() is that value; asked for as another type (a
/// kind's code given another kind's scene) it throws std::logic_error, never
/// reading one type as another.
class KindSpec {
 public:
  template <class T>
  T& emplace() {
    return value_.emplace<T>();
  }
  template <class T>
  T& as() {
    return checked(std::any_cast<T>(&value_));
  }
  template <class T>
  const T& as() const {
    return checked(std::any_cast<T>(&value_));
  }

 private:
  template <class T>
  static T& checked(T* v) {
    if (!v) throw std::logic_error("a scene's sections read as another kind's");
    return *v;
  }
  std::any value_;
};

struct Scene {
  std::string path;  // as given on the command line
  std::string text;  // the file's content, stored in every results file
  std::string name;
  std::string description;
  /// What the file describes: the name of its study kind (StudyKind::name),
  /// chosen by parse_scene from the sections the file has.
  std::string kind;
  std::vector<ShapeSpec> shapes;  // in file order (a smoothing grid has none)
  // The pose sweep ([sweep]): all of a sweep's; a smoothing grid reads poses,
  // dt and warmup from its optional [sweep].
  GeneratorKind generator = GeneratorKind::Paper;
  std::uint64_t poses = 0;
  double dt = 1e-4;
  /// Warm pass: the warm-start chain restarts (first pose solved without a
  /// warm start) every warm_chain poses, so that shards and threads split
  /// the sweep at chain boundaries and reproduce the unsharded run exactly.
  std::uint64_t warm_chain = 10000;
  /// Untimed solves (poses 0..warmup-1) before each timed pass.
  std::uint64_t warmup = 1000;
  SolverOptions solver;
  /// The kind's own sections ([run], [[case]], [grid], [toi], ...).
  KindSpec spec;
};

/// The text of a scene file of any kind; throws SceneError if it cannot be read.
std::string read_scene_file(const std::string& path);

/// One shape family as a scene writes it: its name, its parameters (key,
/// meaning, range and default: core's FamilyParam) and an example inline
/// table. The five families of core are core's own declarations
/// (idcol/families.hpp), read here, not repeated: the scene reader takes
/// their scalar keys, in their order, and builds the shape with
/// shape_with_params(prototype, ...) (idcol/shape_params.hpp), and
/// `idcol_harness shapes` prints them. The polytope (no prototype) and the
/// generated polytopes (box, facet_sphere, vertex_sphere, the harness's
/// own) have their own branches. This is the one catalogue of what a scene
/// may name.
struct FamilyDoc {
  std::string family;
  std::string summary;
  /// The body's frame as the solver uses it: its axis of symmetry, or what
  /// its parameters lie along.
  std::string axes;
  std::vector<idcol::FamilyParam> params;
  std::string example;
  std::optional<Shape> prototype;  // the example's shape
  /// A generated shape: not a family of core but a smooth_polytope the
  /// reader builds from these parameters (read_generated_shape).
  bool generated = false;
};
const std::vector<FamilyDoc>& scene_families();

/// Parses one shape from a TOML inline table, in exactly the form
/// idcol::describe prints. `file` and `field` name it in errors.
ShapeSpec parse_shape_inline(const std::string& inline_table, const std::string& file, const std::string& field);

}  // namespace idcol::harness
