// The one bridge from core's shapes to the independent geometry: a narrow
// conversion that reads only public shape parameters (Sphere::R;
// Superellipsoid::a, b, c, n; SuperellipticCylinder::R, h, n;
// SmoothPolytope::normal(i), offset(i), beta, L; SmoothTruncatedCone::Rb, Rt,
// a, b, beta). Nothing of core's evaluation, vertices, hull, radii or solver
// is used: the oracles and geometry code never include core, and this file
// (with the FCL/libccd adapters' use of idcol::Pose) is where core meets
// baselines.
#pragma once

#include <string>

#include "idcol/shapes.hpp"
#include "idcol_baselines/exact_shape.hpp"
#include "idcol_baselines/geometry.hpp"

namespace idcol::baselines {

/// The independent description of `s` (parameters copied, validated again by
/// geom's own rules).
geom::Desc to_desc(const Shape& s);

/// Whether the FCL/libccd baselines can represent `s` exactly (sphere, n = 1
/// superellipsoid, or smooth polytope), and if not, why.
bool representable(const Shape& s, std::string* why = nullptr);

/// The exact geometry of `s` (polytope vertices and faces from geom). Throws
/// std::invalid_argument naming the family and its parameters if
/// !representable(s).
ExactShape to_exact(const Shape& s);

PairKind classify(const Shape& body1, const Shape& body2);

/// "superellipsoid(a=..., n=8) x smooth_polytope(...)": used in every error
/// message that names a pair.
std::string describe_pair(const Shape& body1, const Shape& body2);

}  // namespace idcol::baselines
