// What one baseline says about one pose. The baselines themselves are the
// rows of the competitor table (registry.hpp).
#pragma once

#include <limits>
#include <string>

#include "idcol/types.hpp"

namespace idcol::baselines {

/// One baseline's answer at one pose. All vectors are in body-1 coordinates
/// (body 1 at the identity). Invariants where the fields are present:
///  - p2_1 - p1_1 = signed_distance * normal_1 (to the baseline's tolerance):
///    normal_1 is the unit vector from body 1 toward body 2 (moving body 2
///    along it separates the bodies), signed_distance > 0 is the gap and
///    < 0 minus the penetration depth;
///  - intersect == (signed_distance <= 0) for baselines that give both.
/// What "depth" means differs by baseline: FCL distance's negative value is
/// EPA's minimum translational depth; MPR's is a depth along MPR's own
/// direction, an upper bound on the minimum depth.
struct BaselineAnswer {
  bool intersect = false;
  bool has_distance = false;
  double signed_distance = std::numeric_limits<double>::quiet_NaN();
  bool has_normal = false;
  Vec3 normal_1 = Vec3::Zero();
  bool has_points = false;
  Vec3 p1_1 = Vec3::Zero();  // witness point on body 1
  Vec3 p2_1 = Vec3::Zero();  // witness point on body 2
  /// The optimal scaling alpha* of the exact bodies, for a method that
  /// solves for it (DCOL; intersect == alpha < 1), and its iteration count.
  bool has_alpha = false;
  double alpha = std::numeric_limits<double>::quiet_NaN();
  /// The method's own bound on |alpha - alpha*| (DCOL: twice its duality
  /// gap at exit, dcol.hpp's Result::gap); NaN where it states none.
  double alpha_bound = std::numeric_limits<double>::quiet_NaN();
  int iterations = -1;
  /// The library threw (FCL's EPA near touching contact) or returned an
  /// error code; `intersect` and the rest are then meaningless.
  bool failed = false;
  bool threw = false;
  std::string error;
};

}  // namespace idcol::baselines
