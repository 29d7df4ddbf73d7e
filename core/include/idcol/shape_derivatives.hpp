// Derivatives of the contact solution, kinematics and wrench with respect to
// the shape parameters theta of body 1 or body 2 (shape_params.hpp gives the
// parameters of each family and their order).
//
// Like derivatives.hpp, everything here reads a converged SolveResult solved
// with SolverOptions::derivatives = true and never re-solves: eq:IFT with
// theta in place of the pose,
//   J_c dz*/dtheta = -dF/dtheta,
// through the stored factorisation exactly as solution_sensitivity() does
// for the pose (J_int = D_r J_c D_c^{-1}, see derivatives.cpp). At fixed
// z = (x, alpha, lambda1, lambda2), y1 = x/alpha and y2 do not depend on
// theta, so for a parameter of body 1 (eq:kkt_residual, unscaled rows)
//   dF/dtheta = (dphi1, 0, (lambda1/alpha) dg1, -(lambda1/alpha) y1^T dg1),
// and for body 2
//   dF/dtheta = (0, dphi2, (lambda2/alpha) R dg2, -(lambda2/alpha) y2^T dg2),
// with dphi_i = d phi_i / d theta and dg_i = d grad phi_i / d theta at y_i
// (eval_params). The pose is held fixed.
//
// Conventions are those of derivatives.hpp: rows z = (x_1 (body-1 frame),
// alpha, lambda1, lambda2); kinematics in body-1 coordinates; wrenches
// (moment, force) with F1_1 about body 1's origin and F2_2 about body 2's.
// Conditioning is that of the pose derivatives (pivot ratio, scale limits),
// with `sensitivity` = max |dz/dtheta| over the rows of x and alpha, made
// dimensionless by the pair length L (x / L; a column of a parameter with
// length power p times L^p, see param_length_powers()).
//
// Cost: one 6x6 triangular solve per parameter (eight run side by side)
// plus one eval_params() of the differentiated body; the results are
// dynamic-size (p = num_params columns) and allocate. World-frame values
// need no more: a body-1 point or direction moves with theta as R_W1 times
// its body-1 derivative.
#pragma once

#include <Eigen/Core>

#include "idcol/derivatives.hpp"
#include "idcol/result.hpp"
#include "idcol/shape_params.hpp"
#include "idcol/shapes.hpp"

namespace idcol {

using Mat6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using RowX = Eigen::Matrix<double, 1, Eigen::Dynamic>;

/// dz*/dtheta for the parameters of one body.
/// `valid` is false (and the matrices empty) unless res.status == Converged.
struct ShapeSensitivity {
  bool valid = false;
  int body = 0;           // 1 or 2
  Mat6X dz_dtheta;        // 6 x p: rows (x_1, alpha, lambda1, lambda2)
  /// d grad phi1 / d theta at y1 (3 x p): nonzero only for body 1, read by
  /// the normal's derivative.
  Mat3X dgrad1_dtheta;
  Conditioning cond;
  Mat3X dx_dtheta() const { return dz_dtheta.topRows<3>(); }
  RowX dalpha_dtheta() const { return dz_dtheta.row(3); }
};

/// `body1`, `body2` must be the shapes `res` was solved with: the
/// differentiated one is checked against the evaluation stored in res
/// (std::invalid_argument otherwise); the other enters only through the
/// stored factorisation and is not evaluated. `body` is 1 or 2
/// (std::invalid_argument naming the value otherwise). Throws
/// std::invalid_argument for a converged result without factorisation,
/// like solution_sensitivity().
ShapeSensitivity shape_sensitivity(const SolveResult& res, const Shape& body1, const Shape& body2, int body);

/// The sensitivity w.r.t. parameters q with theta = theta(q): every column
/// block multiplied on the right by dtheta_dq (p x n), e.g. the vertices of
/// a polytope through polytope_vertex_jacobian(). The kinematics and wrench
/// derivatives of the result are then w.r.t. q.
ShapeSensitivity chain_params(const ShapeSensitivity& s, const Eigen::MatrixXd& dtheta_dq);

/// Derivatives of ContactKinematics (eq:witness, eq:gap, eq:unit_normal)
/// w.r.t. theta, pose fixed:
///   d p1_1 = dx/alpha - y1 dalpha/alpha,
///   d p2_1 = dx/alpha + (r - x)/alpha dalpha/alpha,
///   d gap  = |r|/alpha^2 dalpha,
///   d nhat_1 = (I - n n^T)/|grad phi1| (H1 d y1 + d grad phi1/d theta).
struct ShapeKinematicsDerivatives {
  bool valid = false;
  Mat3X dp1_1;
  Mat3X dp2_1;
  Mat3X dnhat_1;
  RowX dgap;
  Conditioning cond;
};

ShapeKinematicsDerivatives shape_kinematics_derivatives(const SolveResult& res, const ShapeSensitivity& s);

/// Derivatives of ContactWrench w.r.t. theta, pose fixed (eq:dfc_dq,
/// eq:dFc1_dq with theta for q; F2_2 = -Ad_{X_12}^T F1_1 with X_12 fixed).
/// Zero (and valid) when the contact is not active; reported unreliable when
/// the wrench is not representable, as contact_wrench_derivatives() does.
struct ShapeWrenchDerivatives {
  bool valid = false;
  RowX df_n;
  Mat6X dF1_1;
  Mat6X dF2_2;
  Conditioning cond;
};

ShapeWrenchDerivatives shape_wrench_derivatives(const SolveResult& res, const ShapeSensitivity& s,
                                                const HertzModel& model);

// ---------------------------------------------------------------------------
// Verification against finite differences in theta, for sweeps.

struct ShapeDerivativeCheckOptions {
  /// Relative step of the central differences: theta_j +- h max(|theta_j|, s_j)
  /// with s_j = L for length parameters, 1 otherwise; Richardson-extrapolated
  /// over h and h/2 as in check_derivatives(). A one-sided second-order
  /// difference is used where theta_j - h would leave the valid range
  /// (n = 1). A disagreement must survive steps 10, 100 and 1000 times
  /// finer, as in check_derivatives().
  double h = 1e-5;
  /// Agreement when max |D_ift - D_fd| <= tolerance * max(1, max |D_fd|) on
  /// the dimensionless rows (x / L, alpha), columns times L^power.
  double tolerance = 1e-5;
  SolverOptions solver = [] {
    SolverOptions o;
    o.tolerance = 1e-13;
    return o;
  }();
};

/// The same counts as DerivativeCheckReport, for dz/dtheta of one body.
DerivativeCheckReport check_shape_derivatives(const Shape& body1, const Shape& body2, int body,
                                              const std::vector<Pose>& poses,
                                              const ShapeDerivativeCheckOptions& options = {});

}  // namespace idcol
