// Deterministic SE(3) pose generators. Pose k depends on k (and the pair's
// radii) alone, never on the poses before it, so a sweep can be split into
// shards or threads and pose k reproduced from its index.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol::harness {

enum class GeneratorKind {
  /// The paper's Lissajous-style sweep (see PoseGenerator::paper).
  Paper,
  /// Low-discrepancy uniform sweep (see PoseGenerator::uniform).
  Uniform,
};

const char* to_string(GeneratorKind g);
/// "paper" or "uniform"; throws std::invalid_argument otherwise.
GeneratorKind generator_from_string(const std::string& s);

/// Radial range of a pair: rmin = 0.1 min(inner radii), rmax = 2 max(outer radii).
struct RadialRange {
  double rmin = 0.0;
  double rmax = 0.0;
};
RadialRange radial_range(const Shape& body1, const Shape& body2);

class PoseGenerator {
 public:
  PoseGenerator(GeneratorKind kind, RadialRange range, double dt) : kind_(kind), range_(range), dt_(dt) {}

  /// X_12 for pose k.
  Pose operator()(std::uint64_t k) const { return kind_ == GeneratorKind::Paper ? paper(k) : uniform(k); }

  /// The paper's sweep at t = k dt:
  ///   radius = cbrt(rmin^3 + (rmax^3 - rmin^3) u),  u = (1 + sin(2 pi sqrt2 t)) / 2,
  ///   theta  = (pi/2) sin(2 pi sqrt3 t),  phi = 2 pi sqrt5 t,
  ///   p      = radius (cos th cos ph, cos th sin ph, sin th),
  ///   q      = normalise(sin 2pi sqrt7 t, cos 2pi sqrt11 t, sin 2pi sqrt13 t, cos 2pi sqrt17 t)  (w, x, y, z).
  Pose paper(std::uint64_t k) const;

  /// Uniform sweep from (u1..u6) = halton6(k): uniform_rotation(u1, u2, u3)
  /// (Haar on SO(3)), uniform_direction(u4, u5), and radius^3 = u6 of the way
  /// from rmin^3 to rmax^3 (uniform in the volume of the shell).
  Pose uniform(std::uint64_t k) const;

 private:
  GeneratorKind kind_;
  RadialRange range_;
  double dt_;
  /// cbrt(rmin^3 + (rmax^3 - rmin^3) u): the radius u of the way through the shell's volume.
  double radius(double u) const;
};

/// Radical inverse of n in base b (the Halton coordinate), in [0, 1).
double radical_inverse(std::uint64_t n, unsigned base);

/// The building blocks every uniform pose draws from (PoseGenerator::uniform
/// and the stress suite's shell and touching poses), each a pure function:
/// u1..u6 of pose k are point k + 1 of the Halton sequence in bases
/// (2, 3, 5, 7, 11, 13) (index 0 of every base is the corner 0).
std::array<double, 6> halton6(std::uint64_t k);
/// Shoemake's map: q = (sqrt(1-u1) sin 2pi u2, sqrt(1-u1) cos 2pi u2,
/// sqrt(u1) sin 2pi u3, sqrt(u1) cos 2pi u3) (x, y, z, w), uniform on SO(3).
Mat3 uniform_rotation(double u1, double u2, double u3);
/// z = 1 - 2 u4, azimuth 2 pi u5: uniform on the unit sphere.
Vec3 uniform_direction(double u4, double u5);

/// m Fibonacci points on the unit sphere (z_i = 1 - (2i + 1)/m, azimuth
/// i pi (3 - sqrt 5)): well spread and deterministic. Generated polytopes'
/// facets and vertices, and the smoothing study's direction sample.
std::vector<Vec3> fibonacci_sphere(int m);

// The stress suite's pose families (stress.hpp), each pose k from
// halton6(k) alone. L is the pair's length, outer radius 1 + outer radius 2.

/// "shell": uniform rotation and direction, |r| = L 10^u with u uniform in
/// [log10 rmin, log10 rmax]; r = 0 exactly (concentric) at every k with
/// k % zero_every == 0 (zero_every > 0).
Pose shell_pose(std::uint64_t k, double L, double rmin, double rmax, std::uint64_t zero_every);

/// How a "touching" pose turns the bodies against each other.
enum class TouchOrientation {
  Uniform,  // uniform rotation and direction
  Face,     // parallel faces: body 2 turned about the common normal z
  Edge,     // body 1's edge (y, z > 0) against body 2's edge (y, z < 0), crossed near 90 deg
  Vertex,   // body 2's (-,-,-) vertex down onto body 1's top face
};
/// "touching", before the suite scales r so that alpha* = 1 + eps: the
/// orientation family's rotation and a direction, with |r| = L.
Pose touching_pose(std::uint64_t k, TouchOrientation o, double L);

}  // namespace idcol::harness
