#include "idcol/toi.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "idcol/solver.hpp"

namespace idcol {

const char* to_string(ToiStatus s) {
  switch (s) {
    case ToiStatus::Impact: return "impact";
    case ToiStatus::NoImpact: return "no_impact";
    case ToiStatus::InitiallyInContact: return "initially_in_contact";
    case ToiStatus::NumericalFailure: return "numerical_failure";
    case ToiStatus::IterationLimit: return "iteration_limit";
    case ToiStatus::InvalidInput: return "invalid_input";
  }
  return "unknown";
}

namespace {

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(17) << x;
  return os.str();
}

[[noreturn]] void bad(const std::string& what) { throw std::invalid_argument("time_of_impact: " + what); }

void check_pose_arg(const Pose& X, const char* name) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!std::isfinite(X.R(i, j)))
        bad(std::string(name) + ".R(" + std::to_string(i) + "," + std::to_string(j) + ") = " + num(X.R(i, j)) +
            " is not finite");
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(X.p[i]))
      bad(std::string(name) + ".p[" + std::to_string(i) + "] = " + num(X.p[i]) + " is not finite");
  const PoseCheck c = check_pose(X);
  if (c != PoseCheck::Ok) bad(std::string(name) + ": " + to_string(c));
}

/// Gauss-Legendre rule with 8 nodes on [0, 1]: exact for polynomials of
/// degree 15; for the trigonometric integrands of J_r below (angles up to pi)
/// the error is below 1e-14 relative.
constexpr double kGlNode[8] = {0.0198550717512319, 0.1016667612931866, 0.2372337950418355, 0.4082826787521751,
                               0.5917173212478249, 0.7627662049581645, 0.8983332387068134, 0.9801449282487681};
constexpr double kGlWeight[8] = {0.0506142681451881, 0.1111905172266872, 0.1568533229389436, 0.1813418916891810,
                                 0.1813418916891810, 0.1568533229389436, 0.1111905172266872, 0.0506142681451881};

/// The right Jacobian of SE(3): exp(xi + d) = exp(xi) exp(J_r(xi) d + O(d^2)),
/// J_r(xi) = integral_0^1 Ad_{exp(-s xi)} ds.
Mat6 se3_right_jacobian(const Vec6& xi) {
  Mat6 J = Mat6::Zero();
  for (int k = 0; k < 8; ++k) J += kGlWeight[k] * adjoint(se3_exp(-kGlNode[k] * xi));
  return J;
}

/// The screw motion of the header, with the bounds the certified step needs.
struct Motion {
  Pose X0, X1;
  Vec6 xi = Vec6::Zero();  // constant body twist (w, v)
  bool translation = false;
  double speed = 0.0;  // |dr/dt| = |v|
  double omega = 0.0;  // |w|
  double accel = 0.0;  // |d^2 r/dt^2| = |w x v|

  Pose at(double t) const {
    if (translation) return Pose{X0.R, X0.p + t * (X1.p - X0.p)};
    return X0 * se3_exp(t * xi);
  }
};

/// One evaluation of alpha*(t).
struct Eval {
  bool ok = false;
  double t = 0.0;
  double alpha = 0.0;
  bool reliable = false;  // derivative trusted
  double g = 0.0;         // d alpha*/dt
  double g_hat = 0.0;     // d alpha*/dt / S (see time_of_impact)
  double g_v = 0.0;       // the translational part of g_hat
  SolveResult res;
  Pose X;
};

}  // namespace

Vec6 se3_log(const Pose& X) {
  const Eigen::AngleAxisd aa(X.R);
  const Vec3 w = aa.angle() * aa.axis();
  const double th2 = w.squaredNorm(), th = std::sqrt(th2);
  const Mat3 W = skew(w);
  double b, c;  // (1-cos th)/th^2, (th - sin th)/th^3, as in se3_exp
  if (th < 1e-4) {
    b = 0.5 - th2 / 24.0;
    c = 1.0 / 6.0 - th2 / 120.0;
  } else {
    b = (1.0 - std::cos(th)) / th2;
    c = (th - std::sin(th)) / (th2 * th);
  }
  const Mat3 V = Mat3::Identity() + b * W + c * W * W;
  Vec6 xi;
  xi.head<3>() = w;
  xi.tail<3>() = V.partialPivLu().solve(X.p);
  return xi;
}

Pose screw_interpolate(const Pose& X0, const Pose& X1, double t) {
  if (X0.R == X1.R) return Pose{X0.R, X0.p + t * (X1.p - X0.p)};
  return X0 * se3_exp(t * se3_log(X0.inverse() * X1));
}

void ToiOptions::validate() const {
  if (!(t_tolerance > 0.0 && t_tolerance < 1.0))
    throw std::invalid_argument("ToiOptions::t_tolerance must be in (0, 1), got " + num(t_tolerance));
  if (!(alpha_tolerance > 0.0 && alpha_tolerance < 0.5))
    throw std::invalid_argument("ToiOptions::alpha_tolerance must be in (0, 0.5), got " + num(alpha_tolerance));
  if (max_solves < 2) throw std::invalid_argument("ToiOptions::max_solves must be >= 2, got " + std::to_string(max_solves));
  solver.validate();
  if (!(alpha_tolerance > 8.0 * solver.tolerance))
    throw std::invalid_argument("ToiOptions::alpha_tolerance = " + num(alpha_tolerance) +
                                " must exceed 8 * solver.tolerance = " + num(8.0 * solver.tolerance) +
                                " (alpha* is known only to the solver's tolerance)");
}

// Long: the certified steps, the probes and the bracket's regula falsi are
// one loop whose state (the bracket, the last contact, the warm start, the
// solve count) every step reads and writes; toi.hpp describes it as one.
ToiResult time_of_impact(const Shape& body1, const Shape& body2, const Pose& X0_12, const Pose& X1_12,
                         const ToiOptions& options) {
  options.validate();
  check_pose_arg(X0_12, "X0_12");
  check_pose_arg(X1_12, "X1_12");

  Motion m;
  m.X0 = X0_12;
  m.X1 = X1_12;
  const Vec3 dp = X1_12.p - X0_12.p;
  if (!dp.allFinite())
    bad("the displacement X1_12.p - X0_12.p = (" + num(dp[0]) + ", " + num(dp[1]) + ", " + num(dp[2]) +
        ") leaves the double range");
  m.translation = X0_12.R == X1_12.R;
  if (m.translation) {
    m.xi.tail<3>() = X0_12.R.transpose() * dp;
  } else {
    m.xi = se3_log(X0_12.inverse() * X1_12);
  }
  if (!m.xi.allFinite())
    bad("the motion's twist log(X0_12^-1 X1_12) is not representable (poses near the double range)");
  m.speed = m.xi.tail<3>().stableNorm();
  m.omega = m.translation ? 0.0 : m.xi.head<3>().stableNorm();
  m.accel = m.translation ? 0.0 : m.xi.head<3>().cross(m.xi.tail<3>()).stableNorm();
  if (!std::isfinite(m.speed) || !std::isfinite(m.accel))
    bad("the motion's speed |v| = " + num(m.speed) + " or |w x v| = " + num(m.accel) + " is not finite");

  const Radii rad1 = radii(body1), rad2 = radii(body2);
  const double rho = rad1.inner + rad2.inner;  // K(R) = B1 - R B2 holds the ball of this radius
  const double r2_out = rad2.outer;
  // Rates are kept per unit of S = max(|v|, |w|) (time measured in units of
  // 1/S), so that a motion across the double range overflows none of them.
  const double S = std::max(m.speed, m.omega) > 0.0 ? std::max(m.speed, m.omega) : 1.0;
  const Vec6 xi_hat = m.xi / S;
  const double lip = (m.speed / S) / rho;             // |d alpha*/dt| from translation, at most
  const double turn = (m.omega / S) * r2_out / rho;   // first-order effect of the rotation, at most
  const double curve = ((m.accel / S) / S) / (2.0 * rho);  // second-order term of the curved path

  SolverOptions sopt = options.solver;
  sopt.derivatives = true;
  sopt.alpha_max = std::numeric_limits<double>::infinity();
  sopt.warm_predictor_order = 0;  // evaluations jump back and forth in t
  // alpha_k and g_v are known to the solver's tolerance: lower them by the
  // margins of the header (kToiAlphaMargin, kToiSlopeMargin).
  const double alpha_margin = kToiAlphaMargin * sopt.tolerance;
  const double slope_floor = (kToiSlopeFloor + kToiSlopeTolFactor * sopt.tolerance) * lip;

  ToiResult out;
  WarmStart warm;
  auto evaluate = [&](double t) {
    Eval e;
    e.t = t;
    e.X = m.at(t);
    e.res = solve(body1, body2, e.X, sopt, &warm);
    ++out.solves;
    if (e.res.status == SolveStatus::Concentric) {
      e.ok = true;
      e.alpha = 0.0;
      return e;
    }
    if (e.res.status != SolveStatus::Converged) return e;
    e.ok = true;
    e.alpha = e.res.alpha;
    const Row6 ga = alpha_gradient(e.res);
    e.g_hat = ga.dot(xi_hat.transpose());
    e.g_v = ga.tail<3>().dot(xi_hat.tail<3>().transpose());
    e.g = e.g_hat * S;
    e.reliable = conditioning(e.res).reliable && std::isfinite(e.g_hat) && std::isfinite(e.g_v);
    return e;
  };
  // The certified step of the header from an evaluation with alpha > 1:
  // the first s > 0 where c0 + c1 s - c2 s^2 = 0 (in units of 1/S); +inf if
  // never. If the discriminant overflows, the root is bounded below by that
  // of c0 - |c1| s - c2 s^2, which is at least min(c0 / (2|c1|), sqrt(c0 / (2 c2))).
  auto certified_step = [&](const Eval& e) {
    const double c0 = e.alpha * (1.0 - alpha_margin) - 1.0;
    if (!(c0 > 0.0)) return 0.0;
    double gv = -lip;
    if (e.reliable) gv = std::max(-lip, e.g_v - kToiSlopeMargin * std::abs(e.g_v) - slope_floor);
    const double c1 = gv - turn, c2 = curve;
    if (c2 == 0.0) return c1 >= 0.0 ? std::numeric_limits<double>::infinity() : (c0 / (-c1)) / S;
    const double D = std::sqrt(c1 * c1 + 4.0 * c2 * c0);
    if (!std::isfinite(D)) return std::min(c0 / (2.0 * std::abs(c1)), std::sqrt(c0 / (2.0 * c2))) / S;
    return (c1 >= 0.0 ? (c1 + D) / (2.0 * c2) : 2.0 * c0 / (D - c1)) / S;
  };
  auto finish = [&](ToiStatus st, const Eval& e) {
    out.status = st;
    out.t = e.t;
    out.contact = e.res;
    out.X_12 = e.X;
    out.alpha_rate = e.g;
    return out;
  };
  auto fail = [&](ToiStatus st, double t_free) {
    out.status = st;
    out.t = t_free;
    out.t_free = t_free;
    return out;
  };

  Eval lo = evaluate(0.0);
  if (!lo.ok) return fail(ToiStatus::NumericalFailure, 0.0);
  if (lo.alpha <= 1.0 + options.alpha_tolerance) {
    out.t_free = 0.0;
    return finish(ToiStatus::InitiallyInContact, lo);
  }
  bool have_hi = false;
  Eval hi;
  int probe_wait = 0;  // certified steps before the next Newton probe
  int probe_misses = 0;
  double probe_factor = 1.0;
  Eval hit;
  bool touched = false;

  while (true) {
    out.t_free = lo.t;
    if (lo.alpha - 1.0 <= options.alpha_tolerance) {  // touching (a graze, or the end of Newton from the left)
      hit = lo;
      touched = true;
      break;
    }
    if (have_hi && hi.t - lo.t <= options.t_tolerance) break;
    if (out.solves >= options.max_solves) return fail(ToiStatus::IterationLimit, lo.t);
    const double limit = have_hi ? hi.t : 1.0;
    const double s = certified_step(lo);
    const double t_next = lo.t + s;
    // a step below the resolution of t: the motion is too long for its bodies
    // (|p1 - p0| beyond ~1e15 times the bodies' inner radii, near a graze)
    if (!(t_next > lo.t)) return fail(ToiStatus::NumericalFailure, lo.t);
    if (!(t_next < limit)) {
      // alpha* > 1 on [lo.t, t_next) which covers [lo.t, limit)
      if (!have_hi) {
        if (t_next > 1.0) {
          out.t_free = 1.0;
          out.status = ToiStatus::NoImpact;
          out.t = 1.0;
          return out;
        }
        Eval e1 = evaluate(1.0);  // t_next == 1 exactly
        if (!e1.ok) return fail(ToiStatus::NumericalFailure, lo.t);
        if (e1.alpha > 1.0 + options.alpha_tolerance) {
          out.t_free = 1.0;
          out.status = ToiStatus::NoImpact;
          out.t = 1.0;
          return out;
        }
        hi = e1;
        have_hi = true;
      }
      // the first root is hi.t itself
      out.t_free = hi.t;
      lo = hi;
      hit = hi;
      touched = true;
      break;
    }
    // Newton probes beyond the certified step close a bracket [lo, hi]. Where
    // alpha* is convex Newton from the left falls short of the root: after a
    // probe that stays above 1 the next one goes twice as far (up to 8 times
    // Newton's step); three misses in a row pause the probes for three steps.
    // Once a bracket stands, the certified steps from lo do the work; a probe
    // every fourth step still pulls hi in.
    // Only where the certified step falls well short of Newton's: for a
    // translation the two coincide and a probe would be a wasted solve.
    const double s_newton = lo.g_hat < 0.0 ? ((lo.alpha - 1.0) / (-lo.g_hat)) / S : 0.0;
    if (probe_wait == 0 && lo.reliable && s_newton > 2.0 * s) {
      if (have_hi) probe_wait = 3;
      const double t_n = lo.t + probe_factor * s_newton;
      if (t_n > t_next && t_n < limit) {
        Eval p = evaluate(t_n);
        ++out.probes;
        if (p.ok && p.alpha <= 1.0 + options.alpha_tolerance) {
          hi = p;
          have_hi = true;
          probe_factor = 1.0;
          probe_misses = 0;
        } else if (++probe_misses >= 3) {
          probe_wait = 3;
          probe_misses = 0;
          probe_factor = 1.0;
        } else {
          probe_factor = std::min(2.0 * probe_factor, 8.0);
        }
      }
    } else if (probe_wait > 0) {
      --probe_wait;
    }
    Eval e = evaluate(t_next);
    if (!e.ok) return fail(ToiStatus::NumericalFailure, lo.t);
    if (e.alpha <= 1.0 + options.alpha_tolerance) {
      // the bound reached 1 at t_next: alpha* > 1 before it
      out.t_free = t_next;
      if (e.alpha >= 1.0 - options.alpha_tolerance) {
        hit = e;
        touched = true;
        break;
      }
      hi = e;
      have_hi = true;
      break;
    }
    lo = e;
  }

  if (!touched) {
    // A root in the bracket [lo.t, hi.t] (alpha*(lo) > 1 >= alpha*(hi)), at most
    // t_tolerance after the first: regula falsi (Illinois) to |alpha* - 1| <= tol.
    Eval a = lo, b = hi;
    double fa = a.alpha - 1.0, fb = b.alpha - 1.0;
    int side = 0;
    hit = b;
    for (int it = 0; it < 60 && out.solves < options.max_solves + 60; ++it) {
      if (std::abs(fb) <= options.alpha_tolerance) {
        hit = b;
        break;
      }
      double t = (a.t * fb - b.t * fa) / (fb - fa);
      if (!(t > a.t && t < b.t)) t = 0.5 * (a.t + b.t);
      if (!(t > a.t && t < b.t)) break;  // no double between them
      Eval c = evaluate(t);
      if (!c.ok) break;
      const double fc = c.alpha - 1.0;
      if (fc > 0.0) {
        a = c;
        fa = fc;
        if (side == -1) fb *= 0.5;
        side = -1;
      } else {
        b = c;
        fb = fc;
        if (side == 1) fa *= 0.5;
        side = 1;
        hit = b;
      }
      if (std::abs(fc) <= options.alpha_tolerance) {
        hit = c;
        break;
      }
    }
  }
  finish(ToiStatus::Impact, hit);
  if (options.derivatives && hit.ok && hit.res.status == SolveStatus::Converged && hit.reliable &&
      hit.g_hat < 0.0) {
    // eq:IFT on alpha*(X(t; X0, X1)) = 1: dt/d eta = -(d alpha*/d xi . dxi_t/d eta) / (d alpha*/dt).
    const double t = hit.t;
    const Row6 ga = alpha_gradient(hit.res);
    const Mat6 Jt = se3_right_jacobian(t * m.xi);
    const Mat6 Jinv = se3_right_jacobian(m.xi).inverse();
    const Mat6 dxi1 = t * Jt * Jinv;  // body twist of X(t) per eta1
    const Mat6 dxi0 = adjoint(se3_exp(-t * m.xi)) - dxi1 * adjoint(se3_exp(-m.xi));
    out.dt_dX1 = -(ga * dxi1) / hit.g;
    out.dt_dX0 = -(ga * dxi0) / hit.g;
    if (!std::isfinite(hit.g)) out.dt_dX1 = out.dt_dX0 = Row6::Constant(std::nan(""));
    out.has_derivatives = out.dt_dX0.allFinite() && out.dt_dX1.allFinite();
  }
  return out;
}

}  // namespace idcol
