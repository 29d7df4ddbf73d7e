// The exact geometry a baseline sees for an idcol shape.
//
// FCL, libccd and the oracles work on exact bodies: a sphere or an ellipsoid
// (Superellipsoid with n = 1) is exact already; a SmoothPolytope is replaced
// by the exact polytope P it smooths (its half-spaces and vertices). The
// smooth body lies inside P, so every baseline answer on a polytope is an
// answer about P, not about the body iDCOL sees (see smoothing_bracket in
// oracles.hpp for what that means for alpha*).
//
// Nothing of core is included here: the polytope's vertices and faces come
// from the independent geometry module (geom::exact_polytope). The
// conversion from core's idcol::Shape lives in core_adapter.hpp.
#pragma once

#include <array>
#include <string>
#include <variant>
#include <vector>

#include "idcol_baselines/geometry.hpp"

namespace idcol::baselines {

using Vec3 = geom::Vec;  // Eigen::Vector3d, the same type as core's idcol::Vec3
using Mat3 = geom::Mat;

/// Ellipsoid y^T diag(axes)^-2 y <= 1 in its own frame (a sphere has equal axes).
struct ExactEllipsoid {
  Vec3 axes = Vec3::Ones();
  bool is_sphere = false;
};

/// Exact convex polytope {y : a_i^T y <= b_i}, |a_i| = 1, b_i > 0, with its
/// vertices and its planar faces (vertex indices counter-clockwise seen from
/// outside), as FCL's Convex wants them: the independent geometry's
/// geom::PolyBody itself, with the smoothing parameters of the smooth body
/// it came from.
struct ExactPolytope : geom::PolyBody {
  double beta = 0.0;  // sharpness of the smooth body it came from
  double L = 1.0;     // its characteristic length
};

using ExactShape = std::variant<ExactEllipsoid, ExactPolytope>;

/// The pair classes the baselines know. Ellip covers spheres and exact
/// ellipsoids; Poly covers SmoothPolytope (as its exact polytope).
enum class PairKind { EllipEllip, EllipPoly, PolyEllip, PolyPoly, Unsupported };
const char* to_string(PairKind k);

/// The exact polytope of half-spaces a_i.y <= b_i (|a_i| = 1) of a smooth
/// polytope of sharpness beta and length L, vertices and faces from
/// geom::exact_polytope.
ExactPolytope exact_polytope_of(const geom::PolytopeDesc& p);

/// Certified bounds on alpha* for exact bodies at relative translation r:
/// |r| / (R1_out + R2_out) <= alpha* <= |r| / (R1_in + R2_in), with
/// ellipsoid radii min/max axis and polytope radii min b_i / max |vertex|.
std::array<double, 2> alpha_bounds(const ExactShape& s1, const ExactShape& s2, const Vec3& r);

}  // namespace idcol::baselines
