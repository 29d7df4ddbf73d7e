// Shape parameters theta of each family and the mixed derivatives
// d phi / d theta and d (grad phi) / d theta at a point y of the shape's frame,
// for the shape-parameter sensitivities of shape_derivatives.hpp.
//
// Nothing here is on the solve path: the solver calls the families' eval()
// and never this file ("no cost when not asked"). eval_params() evaluates
// phi, grad phi and hess phi with the family's own eval() and then the
// parameter derivatives from the same bounded quantities that eval() uses
// (w = ybar / psi with |w_i| <= 1 for the superquadrics, weights of the
// smooth maximum with the maximum shifted out for the LogSumExp families),
// so they overflow no sooner than phi itself.
//
// Parameters, in this order (the "theta" of every function here):
//   a scalar family        its constructor's arguments, as families.hpp
//                          declares them: Sphere (R), Superellipsoid
//                          (a, b, c, n), SuperellipticCylinder (R, h, n),
//                          SmoothTruncatedCone (Rb, Rt, a, b, beta)
//   SmoothPolytope         (A_0x, A_0y, A_0z, b_0, ..., A_{m-1,z}, b_{m-1}, beta):
//                          4m + 1 entries; L is held fixed.
//
// The smooth polytope's parameters are the constructor's inputs (A_i, b_i),
// taken at the values the shape stores: unit rows a_i and the offsets b_i
// divided by the row norms. The constructor normalises each row, so phi
// depends on (A_i, b_i) only through (A_i, b_i) / |A_i| (homogeneous of
// degree 0): the derivative w.r.t. A_i has no component along a_i other than
// the one that moves the offset (d phi/dA_i = (I - a_i a_i^T) d/da_i
// - b_i a_i d/db_i with the unnormalised a_i, b_i of
// phi = smax_beta((a_i^T y - b_i) / L)), and a user whose rows had norms
// nu_i gets the derivatives w.r.t. his own (A_i, b_i) by dividing those
// columns by nu_i. Central differences that re-construct the polytope from
// perturbed (A_i, b_i) measure exactly these derivatives.
//
// At n = 1 the superquadrics' derivative in n is the right-sided one (n >= 1
// is required); the formula is the same.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol {

using VecX = Eigen::VectorXd;
using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

/// d phi / d theta and d grad phi / d theta at one point, p = num_params.
/// Sized by eval_params(); a caller that keeps one ShapeParamEval per shape
/// allocates only on its first use.
struct ShapeParamEval {
  VecX dphi;    // p
  Mat3X dgrad;  // 3 x p
};

/// Number of parameters of the shape (see the table above).
int num_params(const Shape& s);
/// Their names, e.g. "a", "n", "A3.y", "b3", "beta".
std::vector<std::string> param_names(const Shape& s);
/// Their current values, in the order above.
VecX shape_params(const Shape& s);
/// Which power of length each parameter carries (1 for R, a, b_i, ...; 0 for
/// n, beta and the unit rows of A), to make derivatives dimensionless.
VecX param_length_powers(const Shape& s);
/// A shape of the same family (and the same L for a polytope) with
/// parameters theta, through the family's constructor: it validates, and
/// throws std::invalid_argument naming the field and value as it does.
/// Throws std::invalid_argument if theta has the wrong size.
Shape shape_with_params(const Shape& like, const VecX& theta);

/// phi, grad phi, hess phi (exactly as Shape::eval) and their parameter
/// derivatives at y, at the shape's own sharpness. At the frame origin of a
/// homogeneous family (phi = -1, gradient undefined) the parameter
/// derivatives are returned as zero.
void eval_params(const Sphere& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d);
void eval_params(const Superellipsoid& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d);
void eval_params(const SuperellipticCylinder& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d);
void eval_params(const SmoothPolytope& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d);
void eval_params(const SmoothTruncatedCone& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d);
void eval_params(const Shape& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d);

/// For a polytope built by SmoothPolytope::from_vertices(vertices, beta, L):
/// d theta / d (v_0, ..., v_{k-1}, beta), a (4m + 1) x (3k + 1) matrix with
/// columns (v_0x, v_0y, v_0z, v_1x, ..., v_{k-1,z}, beta), where theta are the
/// polytope's parameters above. Multiply a derivative w.r.t. theta on the
/// right by it (e.g. chain_params() in shape_derivatives.hpp) to get the
/// derivative w.r.t. the vertices.
///
/// Each face is the plane through its three hull vertices v0, v1, v2
/// (counter-clockwise from outside): a = N/|N|, N = (v1 - v0) x (v2 - v0),
/// b = a^T v0. This is the derivative while the hull's combinatorics do not
/// change, which holds on a neighbourhood of the vertices only if every face
/// of the hull is a triangle: where four or more vertices are coplanar, almost
/// every perturbation splits the face into two nearly coplanar faces, whose
/// smooth maximum jumps by up to log(2)/beta. So this throws
/// std::invalid_argument naming the face if a face has more than three
/// vertices, and also if `polytope` does not have the hull's faces in the
/// hull's order (it was not built from these vertices). Points that are not
/// hull vertices get zero columns.
Eigen::MatrixXd polytope_vertex_jacobian(const std::vector<Vec3>& vertices, const SmoothPolytope& polytope);

}  // namespace idcol
