// Bullet 3.24 adapter (Debian's libbullet-dev, its double-precision build
// BulletCollision-float64 / LinearMath-float64): Bullet's GJK/EPA on the
// exact bodies, through its two entry points,
//  - btGjkPairDetector::getClosestPoints (btVoronoiSimplexSolver for GJK,
//    btGjkEpaPenetrationDepthSolver for the penetration), what Bullet's
//    convex-convex collision algorithm calls;
//  - btGjkEpaSolver2::SignedDistance (its GJK Distance, then its EPA
//    Penetration without margins where GJK finds the origin inside).
//
// Shapes: an exact polytope is a btConvexHullShape of its vertices; a sphere
// or an ellipsoid is a btConvexInternalShape of our own whose support map is
// the ellipsoid's closed form (bullet_adapter.cpp). Both with collision
// margin 0, so every answer is about the exact body: Bullet's default
// margin (0.04, added around a shrunken core) would make each body a
// rounded one 0.04 larger. The alternatives for the ellipsoid that Bullet
// offers itself (a btMultiSphereShape of one unit sphere with local scaling
// (a, b, c), or the hull of points on the surface) are kept as options for
// the accuracy comparison in baselines/README.md; the competitor rows use the
// exact support.
//
// Conventions of the answers (answer.hpp): body 1 at the identity, body 2 at
// X_12, normal from body 1 toward body 2, p2_1 - p1_1 = signed_distance *
// normal_1. Bullet's own are the reverse ("normal on B", pointing from body
// 2 toward body 1); the adapter turns them around.
//
// Known behaviour of Bullet 3.24 here (measured in test_bullet.cpp, figures
// in baselines/README.md):
//  - apart, btGjkEpaSolver2's distance is right to 1e-9; btGjkPairDetector's
//    GJK stops early on smooth bodies (a degenerate simplex), off by up to
//    1e-4;
//  - overlapping a smooth body, EPA at margin 0 returns on some poses (up to
//    a quarter, two ellipsoids) a depth well below the true one along a
//    wrong normal, reported as a penetration like any other;
//  - near touching, btGjkEpaSolver2::SignedDistance can return false (its
//    two GJK runs disagree): failed;
//  - Debian's build has no assertions, so nothing aborts; a non-finite pose
//    or answer comes back as failed.
#pragma once

#include <memory>

#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/exact_shape.hpp"

namespace idcol::baselines {

/// How an ellipsoid (or sphere) becomes a Bullet shape.
enum class BulletEllipsoid {
  ExactSupport,  // our btConvexInternalShape: support E^2 d / |E d|, the exact body
  ScaledSphere,  // btMultiSphereShape, one unit sphere, local scaling (a, b, c)
  SurfaceHull,   // btConvexHullShape of hull_points points on the surface (inside the body)
};

struct BulletOptions {
  BulletEllipsoid ellipsoid = BulletEllipsoid::ExactSupport;
  int hull_points = 1000;  // SurfaceHull: Fibonacci points on the surface
};

/// "double" or "single": what the linked Bullet computes in, probed at run
/// time through a library call (a hull's support point must come back with
/// all 53 bits); "double" is the only one this adapter is built for.
const char* bullet_precision();

/// The Bullet shapes of one pair, built once; queries are const and
/// allocation-free apart from Bullet's own stack use.
class BulletPair {
 public:
  BulletPair(const ExactShape& body1, const ExactShape& body2, BulletOptions options = {});
  ~BulletPair();
  BulletPair(BulletPair&&) noexcept;
  BulletPair& operator=(BulletPair&&) noexcept;

  /// btGjkPairDetector::getClosestPoints: signed distance (negative: EPA's
  /// depth), normal and both points. intersect = signed_distance <= 0.
  BaselineAnswer pair_detector(const Pose& X_12) const;
  /// btGjkEpaSolver2::SignedDistance: the same fields from Bullet's other
  /// GJK/EPA. failed where it returns false: near touching contact its
  /// distance GJK and its penetration GJK can both find nothing (status
  /// Separated, or GJK_Failed, "probably just touching"), and EPA_Failed.
  BaselineAnswer gjk_epa2(const Pose& X_12) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace idcol::baselines
