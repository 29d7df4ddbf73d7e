// libccd 2.1 adapter, called directly (not through FCL): ccdGJKIntersect,
// ccdMPRIntersect, ccdMPRPenetration, and (labelled unreliable on smooth
// shapes) ccdGJKPenetration, i.e. EPA. Support functions are our own, for the
// exact ellipsoid and the exact polytope (vertex scan), in body-1 coordinates.
//
// libccd's defaults are a 1e-4 MPR/EPA tolerance and an unlimited iteration
// count; here both are explicit. The Debian build is double precision
// (/usr/include/ccd/config.h defines CCD_DOUBLE; ccd_precision() reports it).
#pragma once

#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/exact_shape.hpp"

namespace idcol::baselines {

struct CcdOptions {
  unsigned long max_iterations = 1000;  // libccd default: (unsigned long)-1
  double mpr_tolerance = 1e-12;         // portal-convergence distance (default 1e-4)
  double epa_tolerance = 1e-10;         // EPA convergence (default 1e-4)
  double dist_tolerance = 1e-12;        // GJK distance progress (default 1e-6)
};

/// "double" or "single": the precision libccd was built with (sizeof ccd_real_t).
const char* ccd_precision();

/// The pair, held by value; queries are const and allocation-free except EPA.
class CcdPair {
 public:
  CcdPair(ExactShape body1, ExactShape body2, CcdOptions options = {});

  bool gjk_intersect(const Pose& X_12) const;
  bool mpr_intersect(const Pose& X_12) const;
  BaselineAnswer gjk(const Pose& X_12) const;
  BaselineAnswer mpr(const Pose& X_12) const;
  /// ccdMPRPenetration: depth along MPR's direction, pos the midpoint.
  BaselineAnswer mpr_penetration(const Pose& X_12) const;
  /// ccdGJKPenetration (EPA). Unreliable on smooth shapes.
  BaselineAnswer epa_penetration(const Pose& X_12) const;

  struct Body {
    const ExactShape* shape = nullptr;
    Mat3 R = Mat3::Identity();
    Vec3 p = Vec3::Zero();
  };

 private:
  ExactShape s1_, s2_;
  CcdOptions opt_;
};

}  // namespace idcol::baselines
