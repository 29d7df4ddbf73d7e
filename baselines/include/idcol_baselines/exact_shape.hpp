// The exact geometry a baseline sees for an idcol shape.
//
// FCL, libccd and the oracles work on exact bodies, the independent geometry's
// own (geom::SphereDesc, geom::SuperellipsoidDesc, geom::PolyBody): a sphere
// or an ellipsoid (Superellipsoid with n = 1) is exact already; a SmoothPolytope is replaced
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

/// Exact convex polytope {y : a_i^T y <= b_i}, |a_i| = 1, b_i > 0, with its
/// vertices and its planar faces (vertex indices counter-clockwise seen from
/// outside), as FCL's Convex wants them: the independent geometry's
/// geom::PolyBody itself, with the smoothing parameters of the smooth body
/// it came from.
struct ExactPolytope : geom::PolyBody {
  double beta = 0.0;  // sharpness of the smooth body it came from
  double L = 1.0;     // its characteristic length
};

/// The exact bodies FCL, libccd and the exact oracles take, each one of the
/// independent geometry's: a sphere, an ellipsoid (a superellipsoid with
/// n = 1), or an exact polytope.
using ExactShape = std::variant<geom::SphereDesc, geom::SuperellipsoidDesc, ExactPolytope>;

/// Whether `s` is a sphere or an ellipsoid.
bool is_ellipsoid(const ExactShape& s);
/// The semi-axes of a sphere (R, R, R) or an ellipsoid (a, b, c), for FCL's
/// Ellipsoid, libccd's support function and Perram-Wertheim. Throws
/// std::invalid_argument for a polytope.
Vec3 ellipsoid_axes(const ExactShape& s);

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
