// Time of impact: the first time along a rigid motion at which two bodies
// touch, certified never to step past a contact, with its derivatives with
// respect to the motion's end poses.
//
// Motion
// ------
// Body 2 moves relative to body 1 from X0 = X0_12 at t = 0 to X1 = X1_12 at
// t = 1 along the screw motion
//     X(t) = X0 exp(t xi^),   xi = (w, v) = log(X0^{-1} X1),
// a constant body twist (angular part first, as in derivatives.hpp): the
// origin of body 2 moves at the constant speed |v| and turns at the constant
// rate |w|. When both ends have the same rotation (R0 == R1, compared entry by
// entry) the motion is evaluated as X(t) = (R0, p0 + t (p1 - p0)) exactly.
//
// Certification (why no contact is missed)
// ----------------------------------------
// alpha*(R, r) of eq:DCOL is the gauge of the convex set K(R) = B1 - R B2 at
// r: r = alpha (y1 - R y2) with y_i in B_i, and x* = alpha y1. K(R) holds the
// ball of radius rho = r1_in + r2_in (the certified inner radii of
// Sec. "Scaling Reparameterization and Bounds"), so
//   (a) the gauge is 1/rho-Lipschitz in r, and convex in r;
//   (b) turning body 2 by an angle theta moves each of its points by at most
//       theta r2_out, so alpha*(R', r) >= alpha*(R, r) / (1 + theta r2_out / rho).
// From an evaluated time t_k (alpha_k = alpha*(t_k) > 1), with s = t - t_k,
// the tangent line l(s) = r_k + s dr/dt(t_k) and |r(t) - l(s)| <= A s^2 / 2
// (A = |w x v| bounds |d^2 r/dt^2| on a screw),
//   alpha*(t) >= [alpha_k + s g_v - A s^2 / (2 rho)] / (1 + s |w| r2_out / rho),
// where g_v = d alpha*/d r . dr/dt at t_k is the translational part of the
// derivative d alpha*/d xi (eq:dz_dq; convexity (a) makes the tangent a lower
// bound along the line, and without a trusted derivative g_v = -|v| / rho).
// The next time evaluated is the first s where this bound reaches 1 (a root
// of a quadratic), so alpha* > 1 on the whole step: no contact is skipped.
// For a pure translation (w = 0, A = 0) the step is exactly Newton's step on
// alpha*(t) - 1 from the left, which converges to the first root from below
// and never overshoots; if g_v >= 0 there, alpha* cannot fall any more and
// the motion is certified free. Rotation adds the first-order term
// |w| r2_out / rho, and the method then also tries Newton steps
// t_k + (alpha_k - 1) / (-d alpha*/dt) as probes (doubled after a probe that
// falls short): a probe with alpha* <= 1 closes a bracket [t_lo, t_hi]
// (alpha*(t_lo) > 1 certified on [0, t_lo], alpha*(t_hi) <= 1), which the
// certified steps from t_lo then shrink to t_tolerance; the answer is the
// root in the bracket found by regula falsi. Probes never certify anything.
// The evaluated alpha_k and g_v are lowered by margins before they enter the
// bound (kToiAlphaMargin, kToiSlopeMargin below), which cover the errors of a
// solve at the solver's tolerance.
//
// Derivatives
// -----------
// With t* the root of alpha*(X(t; X0, X1)) = 1, the implicit function theorem
// (eq:IFT) gives dt*/d eta = -(d alpha*/d xi . dxi/d eta) / (d alpha*/dt) for
// body twists eta0, eta1 applied on the right of the end poses,
// X0 -> X0 exp(eta0^), X1 -> X1 exp(eta1^) (the convention of derivatives.hpp).
#pragma once

#include <string>

#include "idcol/derivatives.hpp"
#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol {

/// The certificate's margins. A solve stops when the KKT residual is below
/// SolverOptions::tolerance (tol), so alpha_k and g_v are known only to
/// within errors proportional to it; the bound uses
///   alpha_k (1 - kToiAlphaMargin tol)   in place of alpha_k, and
///   g_v - kToiSlopeMargin |g_v| - (kToiSlopeFloor + kToiSlopeTolFactor tol) (|v| / rho)
/// in place of g_v (|v| / rho bounds |d alpha*/dt| from the translation).
/// Measured against closed forms (core/src/toi/tests/test_toi_certificate.cpp, two
/// aligned copies of superellipsoids and superelliptic cylinders up to 100:1,
/// cold and warm, solver tolerances 1e-10 to 1e-4): alpha_k overestimates
/// alpha* by at most 0.25 of its margin; the error of d alpha*/dr, which a
/// motion nearly tangent to the level set of alpha* meets in full, grows with
/// tol: up to 18 tol / rho in the test, 33 tol / rho over 2000 poses per body
/// (a 100:1 plate at tol 1e-8), and 2.7e-9 / rho at the default tolerance (a
/// 50:1 disc), above kToiSlopeFloor alone; kToiSlopeTolFactor is three times
/// the largest. Where the solve's derivative is not reliable (conditioning())
/// the bound uses g_v = -|v| / rho instead, which holds without any derivative.
inline constexpr double kToiAlphaMargin = 4.0;
inline constexpr double kToiSlopeMargin = 1e-6;
inline constexpr double kToiSlopeFloor = 1e-9;
inline constexpr double kToiSlopeTolFactor = 100.0;

enum class ToiStatus {
  /// alpha*(0) > 1 + alpha_tolerance, and alpha* reaches 1 at t in (0, 1]:
  /// either a solve there gave |alpha* - 1| <= alpha_tolerance, or t lies in a
  /// bracket [t_lo, t_hi] no wider than t_tolerance with alpha* > 1 certified
  /// on [0, t_lo] and alpha*(t_hi) <= 1 (t then is a root inside it).
  Impact,
  /// alpha* > 1 is certified on the whole of [0, 1].
  NoImpact,
  /// alpha*(0) <= 1 + alpha_tolerance: the bodies touch or overlap at t = 0.
  InitiallyInContact,
  /// A solve along the motion did not converge, or the certified step fell
  /// below the resolution of t in double (a motion some 1e15 times longer
  /// than the bodies' inner radii passing close by); ToiResult::t_free says
  /// how far the motion is certified free.
  NumericalFailure,
  /// ToiOptions::max_solves solves were spent without deciding (a motion that
  /// grazes while it turns); the motion is certified free up to t_free.
  IterationLimit,
  /// Never returned by time_of_impact, which throws std::invalid_argument
  /// for a pose or motion it refuses: the status with which a batch of
  /// queries (Python's time_of_impact_batch) marks such a row instead of
  /// abandoning the others.
  InvalidInput,
};

/// "impact", "no_impact", "initially_in_contact", "numerical_failure",
/// "iteration_limit", "invalid_input".
const char* to_string(ToiStatus s);

struct ToiOptions {
  /// The answer t is within this of the first time of contact (in units of
  /// the motion's duration, which is 1).
  double t_tolerance = 1e-10;
  /// The bodies count as touching when |alpha* - 1| <= alpha_tolerance: a
  /// relative gap of 1e-9 of |r|, just above the solver's accuracy. It also
  /// decides a grazing translation, where alpha* - 1 shrinks only linearly.
  double alpha_tolerance = 1e-9;
  /// Solves allowed for one query (each evaluation of alpha*(t) is one).
  /// Typical queries take 5 (translations) to 20; a contact brought about
  /// by the turn while alpha* barely dips below 1 advances only linearly
  /// (the turn's term |w| r2_out / rho dominates the step) and took up to
  /// 316 on 2500 random motions of every family pair, where 200 left 2
  /// undecided.
  int max_solves = 500;
  /// Compute dt*/d(X0, X1) on an Impact.
  bool derivatives = true;
  /// Options of every solve (its `derivatives` and `alpha_max` are set by
  /// time_of_impact itself).
  SolverOptions solver{};

  /// Throws std::invalid_argument naming the field and value.
  void validate() const;
};

struct ToiResult {
  ToiStatus status = ToiStatus::NumericalFailure;
  /// Impact: the time of first contact; InitiallyInContact: 0; otherwise 1
  /// (NoImpact) or t_free.
  double t = 0.0;
  /// The solve at X(t) (Impact, InitiallyInContact): witness points and
  /// normal through contact_kinematics(contact). Solved with derivatives.
  SolveResult contact;
  /// The relative pose X(t) at which `contact` was solved.
  Pose X_12;
  /// alpha* > 1 is certified on [0, t_free].
  double t_free = 0.0;
  /// d alpha*/dt at t (Impact); negative for an approaching contact.
  double alpha_rate = 0.0;
  /// dt*/d eta0 and dt*/d eta1 (body twists (w, v) on the right of X0 and
  /// X1); filled when has_derivatives: an Impact with ToiOptions::derivatives,
  /// whose contact solve is reliable (conditioning()) and approached,
  /// d alpha*/dt < 0. At a graze d alpha*/dt -> 0 and dt* is not
  /// differentiable: the entries grow without bound as alpha_rate -> 0.
  bool has_derivatives = false;
  Row6 dt_dX0 = Row6::Zero();
  Row6 dt_dX1 = Row6::Zero();
  /// Evaluations of alpha* (solves) and how many of them were probes that
  /// are not certified steps.
  int solves = 0;
  int probes = 0;
};

/// The first time of contact of body 2 moving relative to body 1 from X0_12
/// (t = 0) to X1_12 (t = 1) along the screw motion (see the top of this
/// file). Throws std::invalid_argument naming the pose and the entry for a
/// non-finite or non-rigid pose, for a motion whose displacement is not
/// representable, and for bad options.
ToiResult time_of_impact(const Shape& body1, const Shape& body2, const Pose& X0_12, const Pose& X1_12,
                         const ToiOptions& options = {});

/// The screw motion itself, for users and tests: X(t) = X0 exp(t log(X0^-1 X1))
/// (the exact linear form when R0 == R1).
Pose screw_interpolate(const Pose& X0, const Pose& X1, double t);

/// log of SE(3): the twist (w, v), |w| <= pi, with se3_exp(se3_log(X)) = X.
Vec6 se3_log(const Pose& X);

}  // namespace idcol
