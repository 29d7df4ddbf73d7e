// Random bodies of every family at random poses (issue 12): the generator
// behind the stress suite's kind = "random_bodies" (configs/random_bodies.toml)
// and build/harness/idcol_check_random_bodies. Pose k of a case is a pure
// function of (case, k): one stream of draws seeded from (seed, family1,
// family2, range, k), so any pose replays from its index, and threads or
// shards split a case anywhere.
//
// Bodies (s: a size, a1, a2: aspect ratios, each drawn afresh per body):
//   sphere          R = s
//   superellipsoid  (s, s a1, s a2), n in {1, 1.5, 2, 3, 4, 8, 16} (wide: 32, 64 instead of 8, 16)
//   cylinder        R = s, h = s a1, n as the superellipsoid
//   box             half-extents (s, s a1, s a2) as 6 half-spaces, beta in {5, 20, 100, 1000}
//                   (wide: 1e4 instead of 1000), L = the smallest half-extent (wide: the
//                   largest, with beta raised to 3 h_max log 6 / h_min where the smooth box
//                   would not hold its centre, at most 1e4)
//   polytope        hull of 6-25 random points on the ellipsoid (s, s a1, s a2) and its 6 axis
//                   points, beta as the box, L = 0.3 min axis (wide: L = the largest axis,
//                   beta raised to 3 L log m / b_min, m half-spaces, at most 1e4)
//   cone            Rb = s, Rt = s U(0.1, 1), a = s a1 / 2, b = a U(0.3, 1), beta as the box
//                   (wide: Rt = s 10^U(-2, 0), a = s 10^U(-1.5, 3) / 2, b = a 10^U(-1.5, 0):
//                   from nearly pointed to nearly a cylinder, from a disc to a needle, the
//                   origin from mid-axis to just below the top)
// with s log-uniform in [10^-0.5, 10^0.5] (wide: [1e-3, 1e3], so sizes of the two
// bodies differ by up to 10^6) and a1, a2 log-uniform in [1, 10] (wide: [1, 1000]).
// The box's three half-extents are independent (the smallest is s, the others
// s a1 and s a2 in any order once the uniform rotation turns it).
// Pose: a uniform rotation (Shoemake) and |r| = (inner1 + inner2) 10^U(-3, 3) along
// a uniform direction, so alpha* spans about 1e-3..1e3. The nearby pose, solved
// warm from the answer at the pose, has |r| x 1.01 and a further rotation of
// 0.02 rad about body 2's z axis.
#pragma once

#include <cstdint>
#include <string>

#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol::harness {

enum class BodyFamily { Sphere, Superellipsoid, Cylinder, Box, Polytope, Cone };
constexpr int kNumBodyFamilies = 6;
/// "sphere", "superellipsoid", "cylinder", "box", "polytope", "cone".
const char* to_string(BodyFamily f);
/// The inverse of to_string; throws std::invalid_argument naming the value and the choices.
BodyFamily body_family_from_string(const std::string& s);

/// The parameter ranges above: Normal, or Wide (the whole range the library accepts).
enum class BodyRange { Normal, Wide };
const char* to_string(BodyRange r);
BodyRange body_range_from_string(const std::string& s);

/// One ordered family pair and its seed: the generator's whole input but k.
struct RandomBodyCase {
  BodyFamily family1 = BodyFamily::Sphere, family2 = BodyFamily::Sphere;
  BodyRange range = BodyRange::Normal;
  std::uint64_t seed = 1;
};

/// Pose k of a case: the two bodies, X_12, and the nearby pose the warm
/// solve answers (warm-started from the answer at X_12).
struct RandomBodyPose {
  Shape body1, body2;
  Pose X_12, X_12_near;
};

/// A counter-based stream of draws (SplitMix64): the same draws on every
/// platform and standard library, unlike std::uniform_real_distribution.
class BodyDraws {
 public:
  explicit BodyDraws(std::uint64_t key) : state_(key) {}
  std::uint64_t next();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi);
  /// 10^U(lo, hi).
  double log_uniform(double lo_exp10, double hi_exp10);
  /// Standard normal (Box-Muller).
  double normal();
  /// Uniform in {0, ..., n - 1}.
  int index(int n);

 private:
  std::uint64_t state_;
};

/// One body of family f, drawn from the stream.
Shape random_body(BodyFamily f, BodyRange range, BodyDraws& g);

/// Pose k of case c (a pure function of c and k).
RandomBodyPose random_body_pose(const RandomBodyCase& c, std::uint64_t k);

}  // namespace idcol::harness
