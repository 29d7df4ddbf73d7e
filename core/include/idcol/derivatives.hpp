// Derivatives of the contact solution and of the contact kinematics and
// wrench built on it (Sec. "Analytical Derivatives of Contact Kinematics",
// Appendix "Derivatives of Contact Kinematics and Wrenches").
//
// Everything here reads a converged SolveResult and never re-solves: the
// sensitivity dz*/dxi reuses the LU factorisation of the KKT Jacobian that
// the solver stored in SolveResult::internal (eq:dz_dq, "reusing the
// factorization"). The solver keeps it only when asked to
// (SolverOptions::derivatives = true); conditioning(), solution_sensitivity(),
// alpha_gradient() and gap_gradient() throw std::invalid_argument for a
// converged result solved without it. The values of contact_kinematics() and
// contact_wrench() need no factorisation. Every function here (and in
// shape_derivatives.hpp) throws std::invalid_argument for a result with
// status Separated (SolverOptions::alpha_max), which holds only a lower bound
// on alpha*. Nothing allocates; every type is fixed-size.
//
// Twist convention (all of this file)
// -----------------------------------
// A pose g = (R, r) is perturbed on the right by a *body-frame* twist
// xi = (w, v) in R^6, angular part first:
//     g(eps) = g * exp(eps xi^),   xi = (g^{-1} dg)^vee,
// so to first order R -> R (I + w~) and r -> r + R v. This is the ordering
// of eq:y_partials_q, y_q = [ y~, -(1/alpha) I ] J, whose first block
// multiplies the angular part. A user with generalised coordinates q and a
// geometric Jacobian J (6 x n, same ordering, (g^{-1} dg)^vee = J dq) gets
// d(.)/dq = d(.)/dxi * J (see map_through_jacobian).
//
// For the relative pose g = X_12 = X_W1^{-1} X_W2, body twists xi1 of X_W1
// and xi2 of X_W2 move g by (derived from g(eps) = exp(-eps xi1) g exp(eps xi2))
//     dxi = -Ad_{g^{-1}} xi1 + xi2,
// see relative_twist_jacobians().
//
// Cost: only what is asked for is computed.
//   - alpha, x, the witness points, gap and normal values: SolveResult and
//     contact_kinematics(), no linear solve;
//   - alpha_gradient() / gap_gradient(): one transposed 6x6 triangular solve;
//   - solution_sensitivity(): one 6-column triangular solve (the full T_c);
//   - contact_kinematics_derivatives(), contact_wrench_derivatives(): read a
//     SolutionSensitivity, no further solve.
#pragma once

#include <string>
#include <vector>

#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol {

using Row6 = Eigen::Matrix<double, 1, 6>;
using Mat36 = Eigen::Matrix<double, 3, 6>;
using Mat3x12 = Eigen::Matrix<double, 3, 12>;
using Row12 = Eigen::Matrix<double, 1, 12>;
using Mat6x12 = Eigen::Matrix<double, 6, 12>;

/// v~ with v~ u = v x u.
inline Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

/// The adjoint of X = (R, p) acting on twists ordered (w, v):
///   Ad_X = [[R, 0], [p~ R, R]].
Mat6 adjoint(const Pose& X);

/// The SE(3) exponential of a twist xi = (w, v) (same ordering as above).
Pose se3_exp(const Vec6& xi);

/// How far the derivatives can be trusted at a solution.
///
/// `pivot_ratio` = min|U_ii| / max|U_ii| of the LU factor of the (row- and
/// column-scaled) KKT Jacobian, a cheap inverse-condition estimate. Where it
/// is tiny J_c is nearly singular, the implicit function theorem is close to
/// failing, and dz*/dxi (and everything derived from it) may be inaccurate or
/// huge. `sensitivity` = max |T_c| over the rows of x and alpha, made
/// dimensionless by the pair length L (x / L, v columns times L); it is
/// filled by solution_sensitivity() only (-1 otherwise). A huge value means
/// z* changes over a tiny pose neighbourhood (e.g. nearly parallel flat
/// faces, where x* slides thousands of L per radian): the derivative is
/// exact but its linearisation holds only over that neighbourhood, and finite
/// differences at ordinary steps disagree with it. `reliable` is false when
/// the solve did not converge, the pivot ratio is below kReliablePivotRatio,
/// the sensitivity (when known) exceeds kReliableSensitivity or is not
/// finite, or alpha / max(1, L) or the surrogate scale k = |r| / (f_S L) is
/// below kMinReliableScale (|r| near the subnormal range, or body sizes near the
/// double range): derivatives carry 1/alpha and 1/k and may then overflow;
/// or alpha is below kMinReliableAlpha (nearly concentric bodies, see there).
struct Conditioning {
  double pivot_ratio = 0.0;
  double sensitivity = -1.0;
  bool reliable = false;
};

/// Below this pivot ratio derivatives are flagged unreliable. Chosen from the
/// sweep in check_derivatives over the paper's shapes (see the report in
/// test_derivatives.cpp): every pose whose derivatives disagreed with finite
/// differences had a pivot ratio far below the bulk of the distribution.
inline constexpr double kReliablePivotRatio = 1e-9;
/// Above this dimensionless sensitivity derivatives are flagged (see
/// Conditioning); chosen from the same sweep.
inline constexpr double kReliableSensitivity = 1e3;
/// Below this alpha / max(1, L) or surrogate scale k derivatives are flagged:
/// they hold L/alpha and 1/k, leaving a margin of 1e18 below overflow.
inline constexpr double kMinReliableScale = 1e-290;
/// Below this alpha (bodies nearly concentric: |r| under 1e-8 of their size)
/// derivatives are flagged. The gap d = |r| - |r| / alpha and the witness
/// point on body 2 are differences of terms of size |r| / alpha, so their
/// derivatives are differences of terms of size 1/alpha: rounding leaves an
/// absolute error of about eps / alpha in them (0.999756 for an exact 1 at
/// |r| = 1e-12, 2 at 1e-16, -16384 at 1e-20). At alpha = 1e-8 that error is
/// 2e-8, below any finite-difference check; below it the error grows
/// without bound.
inline constexpr double kMinReliableAlpha = 1e-8;

Conditioning conditioning(const SolveResult& res);

/// dz*/dxi = T_c (eq:dz_dq with J = I), from J_c T_c = -G_c (eq:df_dq).
///
/// Rows: z = (x_1 (3, body-1 frame), alpha, lambda1, lambda2), the paper's
/// unknowns (the solver's s = log alpha is converted: d alpha = alpha ds).
/// Columns: the body twist xi = (w, v) of the relative pose X_12.
/// `valid` is false (and dz_dxi zero) unless res.status == Converged.
struct SolutionSensitivity {
  bool valid = false;
  Mat6 dz_dxi = Mat6::Zero();
  Conditioning cond;
  /// The rows of x_1 and alpha, the quantities most users need.
  Mat36 dx_dxi() const { return dz_dxi.topRows<3>(); }
  Row6 dalpha_dxi() const { return dz_dxi.row(3); }
};

SolutionSensitivity solution_sensitivity(const SolveResult& res);

/// d alpha*/dxi alone, by one adjoint (transposed) solve; zero unless
/// Converged. Cheaper than solution_sensitivity(res).dalpha_dxi().
Row6 alpha_gradient(const SolveResult& res);

/// d(.)/dq = d(.)/dxi J for a geometric Jacobian J (6 x n, fixed or dynamic
/// n; a fixed n never allocates) of the relative pose, (g^{-1} dg)^vee = J dq.
template <class Derived, class JDerived>
Eigen::Matrix<double, Derived::RowsAtCompileTime, JDerived::ColsAtCompileTime> map_through_jacobian(
    const Eigen::MatrixBase<Derived>& d_dxi, const Eigen::MatrixBase<JDerived>& J) {
  static_assert(Derived::ColsAtCompileTime == 6, "d/dxi has 6 columns");
  return d_dxi * J;
}

/// d xi / d xi1 = -Ad_{X_12^{-1}} and d xi / d xi2 = I, where xi1, xi2 are
/// body twists of the world poses X_W1, X_W2 and xi that of X_12 = X_W1^{-1} X_W2.
/// So dz*/dxi1 = T_c * dxi_dxi1 and dz*/dxi2 = T_c.
void relative_twist_jacobians(const Pose& X_12, Mat6& dxi_dxi1, Mat6& dxi_dxi2);

/// dz*/d(xi1, xi2): 6 x 12, columns (xi1 (w, v), xi2 (w, v)) for users who
/// hold the world poses. `X_12` must be the pose the result was solved at.
Mat6x12 world_pose_sensitivity(const SolutionSensitivity& s, const Pose& X_12);

/// Contact kinematics at a converged solution, body-1 frame (eq:witness,
/// eq:gap, eq:unit_normal). Invariants (r = X_12.p, all in body-1 frame):
///  - p1_1 = x_1 / alpha lies on body 1 (phi1(p1_1) = 0);
///  - p2_1 = (1 - 1/alpha) r + x_1 / alpha lies on body 2 (eq:witness);
///  - p2_1 - p1_1 = gap * r / |r|, gap = (1 - 1/alpha)|r| (eq:gap),
///    gap > 0 separated, gap < 0 penetrating;
///  - nhat_1 = grad phi1(p1_1) / |grad phi1(p1_1)| is body 1's outward unit
///    normal at the contact of the scaled bodies (eq:unit_normal at x*; the
///    normal of phi1(x/alpha) at x* equals that of phi1 at x*/alpha). Body 2's
///    outward normal there is -nhat_1.
/// `valid` is false unless res.status == Converged.
/// `representable` is false when p1, p2 or the gap exceeds the double range:
/// bodies whose extents along r sum beyond ~1.8e308 (gap = |r| - that sum).
/// Those entries are then Inf and must not be used.
struct ContactKinematics {
  bool valid = false;
  bool representable = true;
  double alpha = 0.0;
  Vec3 x_1 = Vec3::Zero();
  Vec3 p1_1 = Vec3::Zero();
  Vec3 p2_1 = Vec3::Zero();
  Vec3 nhat_1 = Vec3::Zero();
  double gap = 0.0;
};

ContactKinematics contact_kinematics(const SolveResult& res);

/// Derivatives of ContactKinematics w.r.t. the relative twist xi.
struct ContactKinematicsDerivatives {
  bool valid = false;
  Mat36 dp1_1_dxi = Mat36::Zero();
  Mat36 dp2_1_dxi = Mat36::Zero();
  Mat36 dnhat_1_dxi = Mat36::Zero();
  Row6 dgap_dxi = Row6::Zero();  // eq:ddD_dq
  Conditioning cond;
};

ContactKinematicsDerivatives contact_kinematics_derivatives(const SolveResult& res, const SolutionSensitivity& s);

/// d gap / dxi alone (eq:ddD_dq), from alpha_gradient(): one adjoint solve,
/// no full sensitivity and nothing of the wrench.
Row6 gap_gradient(const SolveResult& res);

/// The same quantities in world coordinates for bodies at X_W1 and X_W2
/// (X_12 = X_W1^{-1} X_W2 being the pose solved at):
///   p1_W = X_W1 p1_1, p2_W = X_W1 p2_1, nhat_W = R_W1 nhat_1, gap unchanged.
/// Derivatives are 12 columns: (xi1 (w, v), xi2 (w, v)), body twists of X_W1
/// and X_W2. They are filled only when `d` is given and valid.
struct ContactKinematicsWorld {
  bool valid = false;
  Vec3 p1_W = Vec3::Zero();
  Vec3 p2_W = Vec3::Zero();
  Vec3 nhat_W = Vec3::Zero();
  double gap = 0.0;
  bool has_derivatives = false;
  Mat3x12 dp1_W = Mat3x12::Zero();
  Mat3x12 dp2_W = Mat3x12::Zero();
  Mat3x12 dnhat_W = Mat3x12::Zero();
  Row12 dgap = Row12::Zero();
};

ContactKinematicsWorld contact_kinematics_world(const ContactKinematics& c, const ContactKinematicsDerivatives* d,
                                                const Pose& X_W1, const Pose& X_12);

/// Hertz penalty law f_n = stiffness * delta^exponent, delta = -gap > 0
/// (eq:contactmodel); f_n = 0 when separated. exponent >= 1; with exponent 1
/// the derivative jumps at delta = 0 (we return the one-sided value 0 there).
struct HertzModel {
  double stiffness = 1.0;
  double exponent = 1.5;
  /// Throws std::invalid_argument naming the field if stiffness <= 0 or
  /// exponent < 1 or either is non-finite.
  void validate() const;
};

/// The contact wrench of eq:contact_wrench.
///
/// Sign conventions. Wrenches are ordered (moment, force), like twists
/// (w, v), so that the power is F . xi.
///  - F1_1: the wrench on body 1, in body-1 coordinates, moment about
///    body 1's origin. The force f_1 = -f_n nhat_1 acts at x_1 (the contact
///    point of the scaled bodies, as in the paper), pushing body 1 away from
///    body 2: F1_1 = (x_1 x f_1, f_1) = -[x~ nhat; nhat] f_n.
///  - F2_2: the equal and opposite reaction on body 2, in body-2 coordinates,
///    moment about body 2's origin: F2_2 = -Ad_{X_12}^T F1_1. (Ad^T is the
///    co-adjoint that carries a wrench from frame 1 to frame 2; it is the
///    paper's Ad_g^{-*}.) Equivalently f_2 = R^T f_n nhat_1, acting at
///    R^T (x_1 - r) in body-2 coordinates.
/// `active` is false (and everything zero) when delta <= 0 or not converged.
/// `representable` is false when the wrench exceeds the double range: f_n
/// overflows (a penetration beyond ~1e205 at stiffness 1, exponent 1.5) or a
/// moment does (|x_1| f_n or |r| f_n beyond ~1.8e308: bodies and poses near
/// the double range). Its entries are then Inf or NaN and must not be used,
/// and contact_wrench_derivatives() reports them unreliable.
struct ContactWrench {
  bool valid = false;
  bool active = false;
  bool representable = true;
  double f_n = 0.0;
  Vec6 F1_1 = Vec6::Zero();
  Vec6 F2_2 = Vec6::Zero();
};

ContactWrench contact_wrench(const SolveResult& res, const HertzModel& model);

/// d F / dxi for the relative twist (eq:dfc_dq, eq:dFc1_dq, eq:dFc2_dq);
/// the dF2_2 term -adbar*_{F2} J of eq:dFc2_dq comes from the rotation of
/// the co-adjoint with the pose.
struct ContactWrenchDerivatives {
  bool valid = false;
  Row6 df_n_dxi = Row6::Zero();
  Mat6 dF1_1_dxi = Mat6::Zero();
  Mat6 dF2_2_dxi = Mat6::Zero();
  Conditioning cond;
};

ContactWrenchDerivatives contact_wrench_derivatives(const SolveResult& res, const SolutionSensitivity& s,
                                                    const HertzModel& model);

// ---------------------------------------------------------------------------
// Verification against finite differences, for sweeps.

struct DerivativeCheckOptions {
  /// Step of the central differences along each twist direction (w in rad,
  /// v in units of the pair length L = r1_out + r2_out). Differences at h
  /// and h/2 are Richardson-extrapolated: truncation O(h^4) (plain central
  /// differences at 1e-5 showed O(h^2) errors of 7e-5 for the sharp shapes
  /// at deep penetration), rounding O(eps_solve / h) ~ 1e-8 with a solver
  /// tolerance of 1e-13; both far below `tolerance`.
  double h = 1e-5;
  /// Agreement when max|T_ift - T_fd| <= tolerance * max(1, max|T_fd|) on the
  /// dimensionless block (rows alpha and x_1/L, v columns times L).
  double tolerance = 1e-5;
  /// The solver's options for the base and the perturbed solves.
  SolverOptions solver = [] {
    SolverOptions o;
    o.tolerance = 1e-13;
    return o;
  }();
};

struct DerivativeCheckReport {
  int poses = 0;
  int converged = 0;        // base solves that converged
  int fd_failed = 0;        // ... of which a perturbed solve did not converge
  int agree = 0;            // IFT and FD agree within tolerance
  int disagree_flagged = 0;    // disagree, and Conditioning::reliable == false
  int disagree_unflagged = 0;  // disagree although reported reliable
  int flagged = 0;             // converged poses with reliable == false
  /// agree / (converged - fd_failed).
  double agreement() const;
  /// The worst relative error over poses not flagged, and its pose.
  double worst_error = 0.0;
  int worst_index = -1;
  Pose worst_pose;
  double worst_pivot_ratio = 0.0;
  /// The smallest pivot ratio and largest sensitivity among poses that agreed.
  double min_agreeing_pivot_ratio = 1.0;
  double max_agreeing_sensitivity = 0.0;
  /// One line per disagreeing pose: index, error, pivot ratio and the pose at
  /// 17 significant digits, ready to paste into a test.
  std::vector<std::string> failures;
};

/// For each pose, compare solution_sensitivity() (rows x_1 and alpha) with
/// central differences through the SE(3) exponential.
DerivativeCheckReport check_derivatives(const Shape& body1, const Shape& body2, const std::vector<Pose>& poses,
                                        const DerivativeCheckOptions& options = {});

namespace detail {
/// Throws std::invalid_argument naming `function` if res.status == Separated.
void reject_separated(const SolveResult& res, const char* function);
}  // namespace detail

}  // namespace idcol
