// FCL 0.7 adapter: fcl::collide (boolean, optionally MPR contact) and
// fcl::distance (signed distance with nearest points), both with the libccd
// GJK solver (GST_LIBCCD) at tight tolerances. Shapes: fcl::Sphered,
// fcl::Ellipsoidd, and fcl::Convexd built from the exact polytope's vertices
// and planar faces.
//
// Known behaviour of FCL 0.7 here (and why the defaults are what they are):
//  - at the default gjk_tolerance 1e-6 collide misses shallow ellipsoid
//    penetrations, hence 1e-12;
//  - GST_INDEP gives wrong booleans and aborts when signed distance is asked,
//    so it is not offered;
//  - collide's depth and normal come from MPR, not the minimum depth;
//  - signed distance in penetration runs EPA, which may throw near touching
//    contact, and in Debian's build (assertions on) may also abort() on a
//    failed `isOutsidePolytopeFace` assertion: both are caught (the abort by
//    a SIGABRT trap armed only around the call) and reported as threw = true.
#pragma once

#include <memory>

#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/exact_shape.hpp"

namespace idcol::baselines {

struct FclOptions {
  double gjk_tolerance = 1e-12;       // CollisionRequest::gjk_tolerance (FCL default 1e-6)
  /// DistanceRequest::distance_tolerance (FCL default 1e-6). FCL uses it for
  /// GJK and EPA alike; at 1e-10 its EPA aborts on 98 of 100 ellipsoid pairs
  /// at alpha* = 0.8 (measured), at 1e-8 on none, hence 1e-8.
  double distance_tolerance = 1e-8;
};

/// fcl::continuousCollide's answer on one motion of body 2 from X0 to X1
/// (body 1 at rest at the identity).
struct FclContinuousAnswer {
  bool supported = true;  // false: FCL has no such query for this pair (it returned -1)
  bool hit = false;       // ContinuousCollisionResult::is_collide
  double t = 1.0;         // time_of_contact (FCL reports 1 when there is none)
};
/// FCL's continuous collision solvers compared here.
enum class FclContinuousMethod {
  Naive,                    // CCDC_NAIVE: fcl::collide at `steps` evenly spaced poses
  ConservativeAdvancement,  // CCDC_CONSERVATIVE_ADVANCEMENT, its distance-based steps
};

/// The FCL geometry of one pair, built once; queries are const.
class FclPair {
 public:
  FclPair(const ExactShape& body1, const ExactShape& body2, FclOptions options = {});
  ~FclPair();
  FclPair(FclPair&&) noexcept;
  FclPair& operator=(FclPair&&) noexcept;

  /// fcl::collide boolean; with_contact also asks for FCL's (MPR) contact.
  BaselineAnswer collide(const Pose& X_12, bool with_contact = false) const;
  /// Just the boolean (no answer struct), for bisection and timing.
  bool intersects(const Pose& X_12) const;
  /// fcl::distance with enable_signed_distance and enable_nearest_points.
  BaselineAnswer distance(const Pose& X_12) const;
  /// fcl::continuousCollide (GST_LIBCCD) from X0 to X1 along FCL's screw
  /// motion (CCDM_SCREW), or its translation (CCDM_TRANS) where `screw` is
  /// false; naive sampling tests `steps` poses.
  FclContinuousAnswer continuous(const Pose& X0, const Pose& X1, FclContinuousMethod method, bool screw,
                                 int steps = 100) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace idcol::baselines
