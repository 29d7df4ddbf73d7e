// Support-function oracle: a certified two-sided bracket on alpha*, the
// smallest common scaling (each body about its own origin) at which two
// convex bodies touch. Built on geometry.hpp only; nothing of core.
//
// Body 1 at the identity, body 2 at X_12 = (R, r). Scaled by alpha, body 1 is
// alpha K1 and body 2 is r + alpha R K2. A plane with unit normal u separates
// them iff alpha (h1(u) + h2(-R^T u)) <= u.r, so
//     alpha* = sup_{|u| = 1} (u.r) / (h1(u) + h2(-R^T u))        (1)
// and every u gives a lower bound. Any point x gives an upper bound,
//     alpha* <= max(g1(x), g2(R^T (x - r))),                      (2)
// since x then lies in both scaled bodies (g the gauges).
//
// Lower bound: (1) over the outer bodies, maximised by a deterministic
// Fibonacci covering of the sphere (the direction of r added) and a pattern
// search on the sphere from the best covering point. The ratio in (1) is
// quasi-concave on {u.r > 0} (its superlevel sets are convex cones), so the
// search has no spurious local maxima to fall into; it can still stop short
// on a ridge of a polytope's support, which widens the bracket but never
// breaks it.
// Upper bound: (2) over the inner bodies, minimised over x by a pattern
// search from the support witnesses of the best u.
//
// For sphere, superellipsoid and superelliptic cylinder the outer and inner
// bodies are the body itself, so [lo, hi] brackets the exact alpha*. For the
// smooth LogSumExp families (polytope, truncated cone) the support function
// has no closed form: the outer body is the exact polytope / frustum (which
// holds the smooth body), the inner one the closed-form body held by it (see
// geometry.hpp, inner_body), and [lo, hi] is the smoothing bracket of the
// smooth body's alpha*; `exact` is then false.
//
// Both bounds are widened by kRoundingMargin (relative) for floating point.
#pragma once

#include <string>

#include "idcol_baselines/geometry.hpp"

namespace idcol::baselines {

/// A certified bracket lo <= alpha* <= hi.
struct AlphaBracket {
  bool ok = false;
  double lo = 0.0, hi = 0.0;
  /// True when lo and hi both refer to the bodies themselves (no smoothing gap).
  bool exact = false;
  geom::Vec u = geom::Vec::Zero();  // the best separating direction found (body-1 frame)
  geom::Vec x = geom::Vec::Zero();  // the common point giving hi (body-1 frame)
  int evaluations = 0;              // support + gauge evaluations
  std::string error;                // why !ok
  double mid() const { return 0.5 * (lo + hi); }
  double rel_width() const { return hi / lo - 1.0; }
};

struct SupportOracleOptions {
  int covering = 400;          // Fibonacci points on the sphere
  double angle_tol = 1e-12;    // pattern search stops below this step (radians)
  int max_evaluations = 20000; // per bound
};

inline constexpr double kRoundingMargin = 1e-13;

/// The oracle for one pair: validates both descriptions and builds their
/// exact bodies (polytope vertices) once; bracket() is const and thread-safe.
class SupportOracle {
 public:
  /// Throws std::invalid_argument naming the body and the field.
  SupportOracle(const geom::Desc& body1, const geom::Desc& body2, SupportOracleOptions options = {});
  AlphaBracket bracket(const geom::Pose& X_12) const;
  bool exact() const { return exact_; }

 private:
  geom::Convex out1_, out2_, in1_, in2_;
  bool inner_ok_ = true, exact_ = true;
  SupportOracleOptions opt_;
};

/// The one-call entry point: alpha* of body1 (identity) and body2 at X_12.
AlphaBracket support_bracket(const geom::Desc& body1, const geom::Desc& body2, const geom::Pose& X_12);

}  // namespace idcol::baselines
