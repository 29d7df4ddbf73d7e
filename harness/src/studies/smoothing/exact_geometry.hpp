// The exact body each smooth family approximates, for the smoothing study
// (issue 6), with closed forms only: no iDCOL solver code.
//
//   smooth_polytope         -> the exact polytope P (its half-spaces)
//   smooth_truncated_cone   -> the exact frustum (axis y1, radius Rb at y1 = -a, Rt at y1 = b)
//   superellipsoid (a,b,c)  -> the box |y1| <= a, |y2| <= b, |y3| <= c (the n -> inf limit)
//   superelliptic_cylinder  -> the exact cylinder |y1| <= h, y2^2 + y3^2 <= R^2
//
// Every smooth body lies inside its exact body and both hold the frame origin
// strictly inside, so both are star-shaped about it and have radial functions
// rho(u) (distance from the origin to the surface along the unit vector u).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "idcol/shapes.hpp"

namespace idcol::smoothing {

class ExactBody {
 public:
  virtual ~ExactBody() = default;
  /// Radial function of the exact body: sup{t >= 0 : t u in body}, |u| = 1.
  virtual double radial(const Vec3& u) const = 0;
  /// For y inside the body: its distance to the boundary (>= 0).
  virtual double depth_inside(const Vec3& y) const = 0;
  /// Euclidean distance from y to the body (0 inside). Polytopes return -1:
  /// no closed form here (the study uses the baselines' oracle for them).
  virtual double distance(const Vec3& y) const = 0;
  virtual bool has_distance() const { return true; }
  /// Directions where the smooth body departs most from the exact one
  /// (vertices, rim circles), added to the dense direction sample.
  virtual std::vector<Vec3> special_directions() const = 0;
  /// Certified radii of the exact body about its frame origin.
  virtual double inner() const = 0;
  virtual double outer() const = 0;
  virtual std::string describe() const = 0;
};

/// The exact body of `s`. Throws std::invalid_argument for a sphere (nothing
/// is smoothed).
std::unique_ptr<ExactBody> exact_body(const Shape& s);

/// Smooth body's radial function by bisection on phi(t u) = 0 over
/// t in [0, t_hi] (phi(t u) is convex in t and negative at 0, so the root is
/// unique); t_hi must have phi(t_hi u) >= 0. 80 halvings: exact to rounding.
double smooth_radial(const Shape& s, const Vec3& u, double t_hi);

}  // namespace idcol::smoothing
