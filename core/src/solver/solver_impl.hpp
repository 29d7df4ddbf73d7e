// The solver, templated on the shape pair. Included by core/src/solver/solver.cpp,
// which instantiates it for every pair behind the variant front end; the
// harness and the benchmarks call that same front end.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>


#include "cold_resume.hpp"
#include "idcol/detail/formulas/ellipsoid_contact.hpp"
#include "idcol/detail/formulas/newton_run.hpp"
#include "idcol/detail/formulas/support.hpp"
#include "exact_polytope_start.hpp"
#include "lm_system.hpp"
#include "idcol/lu6.hpp"
#include "idcol/kkt.hpp"
#include "idcol/options.hpp"
#include "idcol/result.hpp"

namespace idcol::detail {

using Vec4 = Eigen::Matrix<double, 4, 1>;
using Mat4 = Eigen::Matrix<double, 4, 4>;

enum class RunStatus { Converged, IterationLimit, LineSearchFailed, NumericalFailure, SpuriousRoot };

inline SolveStatus to_status(RunStatus s) {
  switch (s) {
    case RunStatus::Converged: return SolveStatus::Converged;
    case RunStatus::IterationLimit: return SolveStatus::IterationLimit;
    case RunStatus::LineSearchFailed: return SolveStatus::LineSearchFailed;
    case RunStatus::NumericalFailure: return SolveStatus::NumericalFailure;
    case RunStatus::SpuriousRoot: return SolveStatus::SpuriousRoot;
  }
  return SolveStatus::NumericalFailure;
}

/// Trust region of s = log(alpha_S) (eq:surrogate_bounds, widened by the margin).
struct SBounds {
  double lo, hi;
};

/// a clamped to [e^lo, e^hi] into `clamped`, and its log: the bits of
/// std::log(std::clamp(a, std::exp(lo), std::exp(hi))), with the two exp
/// calls (about 100 instructions a cold solve) made only where log a is
/// within rounding of a bound or beyond it. Strictly inside, the clamp
/// keeps a, whose log is then the same; the margin of 1e-12 relative is far
/// above the few ulps by which exp and log may round.
inline double clamped_log(double a, const SBounds& B, double& clamped) {
  const double s = std::log(a);
  const double m = 1e-12 * (1.0 + std::abs(s));
  if (s > B.lo + m && s < B.hi - m) {
    clamped = a;
    return s;
  }
  clamped = std::clamp(a, std::exp(B.lo), std::exp(B.hi));
  return std::log(clamped);
}

/// formulas::genuine_root within the certified bounds of s: the contact,
/// not a spurious root.
inline bool genuine_root(const Vec6& z, const SBounds& B) { return formulas::genuine_root<ScalarNum>(z, B.lo, B.hi); }

/// The relative margin within which limit_step forms a bound's division:
/// outside it the bound cannot bind (formulas::limit_step).
constexpr double kLimitBand = 1e-3;

/// Distance from the frame origin to the boundary along the unit vector u,
/// clamped to the certified radii: exact for homogeneous shapes (1/psi(u)),
/// two monotone Newton steps from the outer radius for the LogSumExp ones.
/// With `normal`, also the gradient of phi at the last point evaluated: the
/// normal at the boundary point for homogeneous shapes (their gradient is
/// constant along rays), near it for the others.
template <class S>
inline double radial_extent(const S& s, const Vec3& u, double sharp, const Radii& rad, Vec3* normal = nullptr) {
  ShapeEval e;
  if constexpr (S::kHomogeneous) {
    s.eval(u, sharp, e);
    if (normal) *normal = e.grad;
    return formulas::homogeneous_extent<ScalarNum>(e.phi, rad.inner, rad.outer);
  } else {
    double n[3];
    const double rho = formulas::newton_extent<ScalarNum>(u, rad.inner, rad.outer, n, [&](const double (&y)[3], double& phi, double (&g)[3]) {
      if constexpr (std::is_same_v<S, SmoothPolytope>)
        s.eval_phi_grad(Vec3(y[0], y[1], y[2]), sharp, e);  // no Hessian needed: a third of a polytope evaluation saved
      else
        s.eval(Vec3(y[0], y[1], y[2]), sharp, e);
      phi = e.phi;
      for (int k = 0; k < 3; ++k) g[k] = e.grad[k];
    });
    if (normal) *normal = Vec3(n[0], n[1], n[2]);
    return rho;
  }
}

/// A boundary point p on the ray from the frame origin along the unit u, and
/// the outer normal n there (not normalised), for support_guess. The smooth
/// body's (radial_extent) for every family but the polytope, whose exact
/// face is taken instead: the face through which the ray leaves P, from m
/// dot products instead of two LogSumExp evaluations (a guess needs no
/// more: the smooth boundary at beta = 5 instead left the smoothing study's
/// cold steps unchanged, and cost two evaluations per polytope).
template <class S>
inline void boundary_on_ray(const S& s, const Vec3& u, double sharp, const Radii& rad, Vec3& p, Vec3& n) {
  if constexpr (std::is_same_v<S, SmoothPolytope>) {
    double pp[3], nn[3];
    if (formulas::polytope_exit_face<ScalarNum>(
            s.num_halfspaces(), [&](int i, int k) { return s.normal(i)[k]; }, [&](int i) { return s.offset(i); }, u, pp, nn)) {
      p = Vec3(pp[0], pp[1], pp[2]);
      n = Vec3(nn[0], nn[1], nn[2]);
      return;
    }
  }
  p = radial_extent(s, u, sharp, rad, &n) * u;
}

/// The matrix M of a body that is an ellipsoid at the given sharpness,
/// {y : y^T M^-1 y <= 1} in its own frame: a sphere, or a superellipsoid
/// evaluated at n = 1. False for every other body.
template <class S>
inline bool ellipsoid_matrix(const S& s, double sharp, Mat3& M) {
  Vec3 ax;
  if (!ellipsoid_axes(s, sharp, ax)) return false;
  M = ax.cwiseProduct(ax).asDiagonal();
  return true;
}

/// alpha* and the witness point of two ellipsoids in closed form up to one
/// scalar (Perram and Wertheim's contact function): with body 1 at the
/// origin (matrix M1) and body 2 at r (matrix M2, in body 1's frame),
///   F(l) = l (1 - l) r^T C(l)^-1 r,   C(l) = (1 - l) M1 + l M2,
/// has one maximum on (0, 1); alpha*^2 = max F, and the scaled bodies touch
/// at x = (1 - l*) M1 C(l*)^-1 r. l* is the root of F' = (1 - 2l) r.u -
/// l (1 - l) u.D u (u = C^-1 r, D = M2 - M1), found by Newton steps kept
/// inside a bracket that F'(0) > 0 > F'(1) starts. Returns false if the
/// iteration does not settle (the caller keeps its other first guess).
/// ellipsoid_contact_from starts the iteration at a given l in (0, 1) (a
/// warm start: the last contact's l, which KKT stationarity gives as
/// lambda1 / (lambda1 + lambda2), since M1^-1 x = (1 - l) u and
/// M2^-1 (r - x) = l u). Written once for the loop and the batch lanes
/// (formulas/ellipsoid_contact.hpp).
inline bool ellipsoid_contact_from(const Mat3& M1, const Mat3& M2, const Vec3& r, double l, double& alpha, Vec3& x) {
  const double ra[3] = {r[0], r[1], r[2]};
  double xa[3];
  bool bad = false;
  if (!formulas::ellipsoid_contact_from<ScalarNum>(M1, M2, ra, l, alpha, xa, bad)) return false;
  x = Vec3(xa[0], xa[1], xa[2]);
  return true;
}

inline bool ellipsoid_contact(const Mat3& M1, const Mat3& M2, const Vec3& r, double& alpha, Vec3& x) {
  const double ra[3] = {r[0], r[1], r[2]};
  return ellipsoid_contact_from(M1, M2, r, formulas::ellipsoid_contact_start<ScalarNum>(M1, M2, ra), alpha, x);
}

/// A homogeneous shape blended with a sphere of radius rho:
///   psi_t(y) = (1 - t) |y| / rho + t psi(y),   phi_t = psi_t - 1.
/// A convex combination of gauges is a gauge, so every stage is a convex
/// body; t = 0 is a sphere (where the cold guess is exact) and t = 1 the
/// shape itself. Used by the rounding continuation for bodies that are far
/// from round (1000:1 ellipsoids), where no sharpness parameter helps.
template <class S>
struct Rounded {
  static_assert(S::kHomogeneous, "rounding needs a homogeneous gauge");
  static constexpr bool kHomogeneous = true;
  const S* s;
  double rho;
  double t;
  void eval(const Vec3& y, double sharp, ShapeEval& e) const {
    s->eval(y, sharp, e);
    const double ny = y.norm();
    e.phi = (1.0 - t) * (ny / rho - 1.0) + t * e.phi;
    e.grad *= t;
    e.hess *= t;
    if (ny > 0.0) {
      const Vec3 u = y / ny;
      e.grad += ((1.0 - t) / rho) * u;
      e.hess += ((1.0 - t) / (rho * ny)) * (Mat3::Identity() - u * u.transpose());
    }
  }
  /// From |y|/r_out <= psi(y) <= |y|/r_in.
  Radii radii(double sharp) const {
    const Radii r = s->radii(sharp);
    return {1.0 / ((1.0 - t) / rho + t / r.inner), 1.0 / ((1.0 - t) / rho + t / r.outer)};
  }
};

template <class S1, class S2>
class PairSolver {
 public:
  PairSolver(const S1& s1, const S2& s2, const SolverOptions& o, TraceSink* trace = nullptr) : s1_(s1), s2_(s2), o_(o), trace_(trace) {}

  /// The next solve's first Newton run resumes at r (solve_pair_resumed).
  void resume_at(const ColdResume* r) { resume_ = r; }

  // Long: the solver's ladder of strategies (warm, cold starts, continuation,
  // rounding, the barrier) in the order it tries them, each rung reading what
  // the last one left; the batch lanes repeat its first rungs in this order.
  SolveResult solve(const Pose& X, WarmStart* warm) {
    SolveResult res;
    if (check_pose(X) != PoseCheck::Ok) {
      res.status = SolveStatus::InvalidInput;
      return res;
    }
    const double rmax = X.p.cwiseAbs().maxCoeff();
    if (rmax == 0.0) {
      res.status = SolveStatus::Concentric;
      return res;
    }
    const Radii r1 = s1_.radii(), r2 = s2_.radii();
    // Outside the safe band of sizes the whole problem is solved in units of
    // a power of two (solve_rescaled): alpha* does not depend on the unit.
    // Only a pair whose bodies are both out of the band on the same side is
    // rescaled: a unit that suits a body of 1e233 beside one of 8 suits
    // neither, and such a pair is solved in the caller's units as before.
    if (!(r1.outer + r2.outer >= kMinLength && r1.outer + r2.outer <= kMaxLength) && !rescaled_ &&
        (r1.outer + r2.outer < kMinLength || std::min(r1.outer, r2.outer) > kMaxLength)) {
      res = solve_rescaled(X, warm, r1, r2);  // into res: every return returns res, which keeps it constructed in place
      return res;
    }
    const Vec3 rs = X.p / rmax;
    const double rn = rmax * rs.norm();
    const Vec3 rhat = rs.normalized();
    if (o_.alpha_max < std::numeric_limits<double>::infinity()) {
      const double lower = alpha_lower_bound(rn, rhat, X.R);
      if (lower > o_.alpha_max) {
        res.status = SolveStatus::Separated;
        res.alpha = lower;
        if (warm) warm->history = 0;  // the predictor's sequence is broken; the last contact stays the warm start
        return res;
      }
    }

    const double fS = o_.surrogate_factor;
    set_problem(X, rhat, r1, r2);
    const double k = rn / (fS * P_.L);

    RunStatus st = RunStatus::IterationLimit;
    bool done = false;
    const bool warm_ok = warm && warm->valid && warm->length == P_.L;
    // Two ellipsoids: the closed form started from the last contact's l
    // costs less than one Newton step from the last contact (whose line
    // search alone evaluates the residual twice), and lands on the root.
    const bool ellipsoid_warm = warm_ok && has_ellipsoid_form();
    int pred_order = 0;  // the warm predictor's order for this query (0: none)
    bool predictor_missed = false;  // tried, and Newton did not finish from it
    Vec6 z_pred = Vec6::Zero();
    if (ellipsoid_warm) {
      res.warm_started = true;
      run_kind_ = "warm";
      const double l1 = warm->z[4], l2 = warm->z[5];
      seed_l_ = l1 / (l1 + l2);
    }
    if (warm_ok && !ellipsoid_warm) {
      res.warm_started = true;
      run_kind_ = "warm";
      // The predictor: the last solutions extrapolated to this query
      // (SolverOptions::warm_predictor_order), then the last solution itself.
      // Extrapolate only a sequence that moves steadily: when the last two
      // answers are more than kPredictorMaxStep apart (in s = log alpha or
      // in xi, units of the pair length) the poses jump, and the last answer
      // is the better start (the stress suite's warm passes: 15-30% fewer
      // iterations than extrapolating the jumps).
      const Vec6 last_step = warm->z - warm->z_prev[0];
      const bool steady = warm->history > 0 && std::abs(last_step[3]) <= kPredictorMaxStep &&
                          last_step.template head<3>().norm() <= kPredictorMaxStep;
      pred_order = steady ? std::min(o_.warm_predictor_order, warm->history) : 0;
      if (pred_order > 0)
        z_pred = pred_order == 1 ? Vec6(2.0 * warm->z - warm->z_prev[0]) : Vec6(3.0 * (warm->z - warm->z_prev[0]) + warm->z_prev[1]);
      // Extrapolate only where it worked: where, on the last query, the
      // prediction fell well within the last answer's distance to the new
      // one (kPredictorGain; WarmStart::extrapolate, judged whether or not
      // it was tried). A random walk's steps are short but point anywhere:
      // extrapolating them missed by more than a step, and cost two Newton
      // steps a query, more than a cold start.
      const bool predict = pred_order > 0 && warm->extrapolate;
      for (int attempt = predict ? 0 : 1; attempt < 2 && !done; ++attempt) {
        Vec6 z0 = attempt == 0 ? z_pred : warm->z;
        z0[4] = std::max(z0[4], 1e-12);
        z0[5] = std::max(z0[5], 1e-12);
        // A predicted point that Newton does not finish in kPredictorSteps
        // steps (it converges in 1-2 when the motion is steady) is dropped
        // at once: the last solution is the safer start, and the worst warm
        // solve then costs at most kPredictorSteps more than without it.
        iter_cap_ = attempt == 0 ? kPredictorSteps : 0;
        st = newton(bounds(r1, r2), z0, false, res.iterations);
        iter_cap_ = 0;
        done = st == RunStatus::Converged;
        if (attempt == 0) predictor_missed = !done;
      }
      if (!done) res.warm_start_fell_back = true;
    }
    // The cold strategy: the ray guess, then the other cold starts, then
    // (two homogeneous bodies) the rounding continuation, then continuation
    // in beta or n. Except that when the ray guess of two homogeneous bodies
    // ends stalled at a stationary point of ||F|| that is not a root (n = 8
    // bodies face to face: their Hessian vanishes at the face centres, so
    // J_c is singular there), rounding goes before the restarts, which
    // mostly stall at the same point: on 10^5 poses of the paper's sweep,
    // SE-SE's 4.6% of such poses took 45 iterations by restarts and 25 by
    // rounding, at a quarter of the time. A ray guess that fails otherwise
    // (1000:1 plates reach the iteration limit) is better served by restarts.
    constexpr bool kCanRound = S1::kHomogeneous && S2::kHomogeneous;
    bool round_done = false;
    auto round = [&] {
      if constexpr (kCanRound) {
        if (!done && !round_done && o_.rounding_continuation) {
          round_done = res.used_continuation = true;
          st = rounding(res, false);
          if (st != RunStatus::Converged) st = rounding(res, true);
          done = st == RunStatus::Converged;
        }
      }
    };
    // Whether the cold strategies may run: always, but after a warm start
    // that failed only if the options allow it (the ellipsoids' warm start
    // is the closed form, the first cold strategy itself).
    const bool may_go_cold = !res.warm_started || o_.warm_fallback_to_cold || ellipsoid_warm;
    if (!done && may_go_cold) {
      stall_exit_ = kCanRound && o_.rounding_continuation;
      stalled_ = false;
      st = cold(r1, r2, res, 0, 1);
      stall_exit_ = false;
      done = st == RunStatus::Converged;
      if (ellipsoid_warm && !done) res.warm_start_fell_back = true;
      if (stalled_) round();
      if (!done) {
        st = cold(r1, r2, res, 1, cold_attempts());
        done = st == RunStatus::Converged;
      }
    }
    round();
    if (!done && o_.continuation && (s1_.has_sharpness() || s2_.has_sharpness())) {
      res.used_continuation = true;
      st = continuation(res);
      done = st == RunStatus::Converged;
    }
    if (!done && o_.barrier && may_go_cold) {
      res.used_barrier = true;
      st = barrier(res);
      // A sharp pair whose root the barrier cannot centre on in doubles
      // (a beta = 10^4 body 10^5 times smaller than its partner): solve the
      // smoothest continuation stage by the barrier instead, and sharpen.
      if (st != RunStatus::Converged && o_.continuation && (s1_.has_sharpness() || s2_.has_sharpness()))
        st = continuation(res, true);
      // The same pair once more with the two log terms weighted by the
      // multipliers (barrier()'s weighted form): when the bodies' sizes
      // differ by 10^5 or more, so do the multipliers, and the unweighted
      // barrier centres the small body 10^5 times deeper than the large one.
      // Not when a run already stands at the rounding floor (a candidate
      // below kFloorCeiling): those stalls are rounding, not the barrier's
      // depth, and the weighted barrier ends at the same floor (a sharp
      // cone's rim beside a sphere: 230 more steps for the same answer).
      if (st != RunStatus::Converged && !(floor_res_ <= kFloorCeiling)) {
        st = barrier(res, true);
        if (st != RunStatus::Converged && o_.continuation && (s1_.has_sharpness() || s2_.has_sharpness()))
          st = continuation(res, true, true);
      }
      done = st == RunStatus::Converged;
    }
    // The last fallback: the same pair with the bodies named the other way
    // round (b2, b1 at X^-1). alpha* and the contact do not depend on the
    // order, but every strategy's path does (cold guesses, which body's
    // multiplier the barrier weights first), and a pose that defeats one
    // order can fall to the other: a 0.2 m beta = 10^4 cone against a
    // 962 x 871970 x 3118 box failed every strategy here and converged
    // swapped. Its answer, mapped back, is polished by Newton in this order,
    // so the result (and the factorisation behind the derivatives) is this
    // order's own root. Not when a run stands at the rounding floor (its
    // candidate is accepted below, as before).
    if (!done && !swapped_ && !(floor_res_ <= kFloorCeiling) && may_go_cold) {
      PairSolver<S2, S1> other(s2_, s1_, o_, nullptr);
      other.swapped_ = true;
      other.rescaled_ = rescaled_;
      const SolveResult rs = other.solve(X.inverse(), nullptr);
      res.iterations += rs.iterations;
      if (rs.converged()) {
        Vec6 z0;
        z0.template head<3>() = (X.R * rs.x_1 + X.p) / (k * P_.L) - P_.c1;
        z0[3] = std::log(rs.alpha / k);
        z0[4] = rs.lambda2 / k;
        z0[5] = rs.lambda1 / k;
        run_kind_ = "swapped";
        st = newton(bounds(r1, r2), z0, false, res.iterations);
        done = st == RunStatus::Converged;
      }
    }
    if (!done && (floor_res_ <= kFloorCeiling || sharp_floor_res_ <= kSharpFloorCeiling)) {
      kkt_residual(P_, floor_res_ <= kFloorCeiling ? floor_z_ : sharp_floor_z_, *pt_);
      st = RunStatus::Converged;
      done = true;
    }
    res.status = to_status(st);
    fill(res, k, done);
    // Scaling back from surrogate coordinates (x k) can leave the double
    // range when the sizes and |r| span it (a body of size 1e308 against a
    // subnormal k): a multiplier underflows to 0 or alpha overflows. Such an
    // answer breaks Converged's invariants, so it is not reported as one
    // (found by fuzz_solve; the iteration itself is unchanged).
    // The same holds when alpha, a multiplier or the witness point x (its
    // largest coordinate) is subnormal: it keeps fewer than 53 bits, so
    // alpha* = 1e-314 would be reported with a relative error of 1e-6. (One
    // coordinate far below the others may be subnormal: x keeps its relative
    // precision.)
    // And a root at which a LogSumExp body's Hessian is not finite is no
    // answer: the residual test cannot be trusted where its curvature
    // overflows (a polytope whose rounding length L is 1e-155 of its size:
    // beta / L^2 is out of range, and the residual was fooled into a wrong
    // Converged). An overflow leaves an infinite or NaN diagonal entry, so the
    // traces tell.
    if constexpr (!(S1::kHomogeneous && S2::kHomogeneous)) {
      if (done && !std::isfinite(res.internal.e1.hess.trace() + res.internal.e2.hess.trace())) {
        res.status = SolveStatus::NumericalFailure;
        done = false;
      }
    }
    const double xmax = res.x_1.cwiseAbs().maxCoeff();
    if (done && !(std::isnormal(res.alpha) && res.alpha > 0.0 && (xmax == 0.0 || std::isnormal(xmax)) && res.x_1.allFinite() &&
                  std::isnormal(res.lambda1) && res.lambda1 > 0.0 && std::isnormal(res.lambda2) && res.lambda2 > 0.0)) {
      res.status = SolveStatus::NumericalFailure;
      done = false;
    }
    if (warm) {
      if (done) {
        // The history continues only through warm-started solves of the
        // same surrogate problem (the same length scale).
        if (ellipsoid_warm) {
          // no predictor for the closed form: its history is never read
        } else if (warm_ok && !res.warm_start_fell_back) {
          if (pred_order > 0)  // squared distances: kPredictorGain^2, no square roots
            warm->extrapolate = !predictor_missed && (pt_->z - z_pred).template head<4>().squaredNorm() <
                                                         kPredictorGain * kPredictorGain * (pt_->z - warm->z).template head<4>().squaredNorm();
          warm->z_prev[1] = warm->z_prev[0];
          warm->z_prev[0] = warm->z;
          warm->history = std::min(warm->history + 1, 2);
        } else {
          warm->history = 0;
        }
        warm->valid = true;
        warm->z = pt_->z;
        warm->length = P_.L;
      } else {
        warm->valid = false;
        warm->history = 0;
      }
    }
    return res;
  }

  /// Whether solve(X) returns Separated before any iteration: a valid pose,
  /// solved unscaled, whose certified lower bound on alpha* (`lower`)
  /// exceeds alpha_max (the same sums as solve()). The batch lanes solve the
  /// others as solve() does.
  bool separated_at_start(const Pose& X, double& lower) const {
    if (!(o_.alpha_max < std::numeric_limits<double>::infinity()) || check_pose(X) != PoseCheck::Ok) return false;
    const double rmax = X.p.cwiseAbs().maxCoeff();
    const Radii r1 = s1_.radii(), r2 = s2_.radii();
    if (rmax == 0.0 || !(r1.outer + r2.outer >= kMinLength && r1.outer + r2.outer <= kMaxLength)) return false;
    const Vec3 rs = X.p / rmax;
    const double rn = rmax * rs.norm();
    lower = alpha_lower_bound(rn, rs.normalized(), X.R);
    return lower > o_.alpha_max;
  }

  /// The SolveResult that solve(X) returns when its answer is the converged
  /// point z, reached in `iterations` Newton steps, that the batch lanes
  /// found (solve_finished): the problem set up as solve() sets it, z
  /// evaluated as every iterate is (kkt_residual), and fill()'s result,
  /// with the factorisation behind the derivatives when they are on. Only
  /// for what the lanes answer: a valid pose inside the band of lengths
  /// solved unscaled, alpha_max infinite, a converged z.
  SolveResult finish_at(const Pose& X, const Vec6& z, int iterations) {
    SolveResult res;
    const double rmax = X.p.cwiseAbs().maxCoeff();
    const Vec3 rs = X.p / rmax;
    const double rn = rmax * rs.norm();
    set_problem(X, rs.normalized(), s1_.radii(), s2_.radii());
    const double k = rn / (o_.surrogate_factor * P_.L);
    kkt_residual(P_, z, *pt_);
    res.status = SolveStatus::Converged;
    res.iterations = iterations;
    fill(res, k, true);
    return res;
  }

  /// One Newton run on the surrogate problem of the pose X (kkt.hpp) from
  /// z0 exactly as given: no clamping of the multipliers, no projection of
  /// s. For tests of the run's acceptance rule (genuine_root), which no
  /// start that solve() makes can reach with a root that is not the contact.
  RunStatus newton_run_from(const Pose& X, const Vec6& z0, int& iters) {
    const Radii r1 = s1_.radii(), r2 = s2_.radii();
    set_problem(X, X.p.normalized(), r1, r2);
    return newton(bounds(r1, r2), z0, false, iters);
  }

 private:
  /// The band of pair lengths L = r1_out + r2_out solved as given. Inside
  /// it every quantity the iteration forms (squared lengths, Hessians of
  /// 1000:1 bodies, 1 / L^2) stays far inside the double range; outside it
  /// (bodies of 1e-155, whose squared lengths underflow, or of 1e160) the
  /// problem is rescaled.
  /// (Its top is lower: pairs of size 1e13 .. 1e18 solved as given drifted
  /// from the unit answer by up to 2e-11 in alpha, within the tolerance but
  /// not scale-free; from 1e-19 to 1e12 none moved by 1e-12.)
  static constexpr double kMinLength = 0x1p-64;  // 5.4e-20
  static constexpr double kMaxLength = 0x1p32;   // 4.3e9

  /// The solve in units of 2^e, e the mean of ilogb(r1_out) and
  /// ilogb(r2_out) (a unit between the two sizes, so that neither body's
  /// lengths leave the range when they are 10^200 apart): every length
  /// (both shapes, r) is multiplied by the exact power of two f = 2^-e, so
  /// the problem solved is bit for bit the unit-sized problem that the
  /// scaled one represents, and alpha*, the multipliers and the surrogate
  /// unknowns (the warm start) are the same in either unit. Lengths of the
  /// result (x, and the internal witness points, r, L and shape derivatives
  /// kept for the derivative code) are scaled back. The copies of the shapes
  /// are made here, once per solve, only out of the band (a polytope's
  /// allocates). A problem whose rescaled |r| or body sizes leave the normal
  /// doubles (sizes or distances spanning more than the double range) has no
  /// representable answer, and ends NumericalFailure.
  [[gnu::noinline]] SolveResult solve_rescaled(const Pose& X, WarmStart* warm, const Radii& r1, const Radii& r2) {
    auto failure = [warm] {
      SolveResult res;
      res.status = SolveStatus::NumericalFailure;
      if (warm) warm->reset();
      return res;
    };
    // A body whose outer radius overflowed (or is 0 or NaN) has no unit:
    // ilogb would give INT_MAX or INT_MIN, and their sum overflows.
    if (!(std::isfinite(r1.outer) && std::isfinite(r2.outer) && r1.outer > 0.0 && r2.outer > 0.0)) return failure();
    const int e = (std::ilogb(r1.outer) + std::ilogb(r2.outer)) / 2;
    const double f = std::ldexp(1.0, -e), g = std::ldexp(1.0, e);
    Pose Xs{X.R, X.p * f};
    const double pmax = Xs.p.cwiseAbs().maxCoeff();
    if (!std::isnormal(pmax) || !std::isnormal(r1.inner * f) || !std::isnormal(r2.inner * f)) return failure();
    const S1 t1 = s1_.scaled(f);
    const S2 t2 = s2_.scaled(f);
    PairSolver<S1, S2> inner(t1, t2, o_, trace_);
    inner.swapped_ = swapped_;
    inner.rescaled_ = true;  // two bodies 10^200 apart in size stay out of the band: solve them as they now are
    SolveResult res = inner.solve(Xs, warm);
    res.x_1 *= g;
    if (res.status != SolveStatus::Converged) return res;
    SolveResult::Internal& in = res.internal;
    in.length *= g;
    in.row_scale.template segment<3>(2) *= g;
    in.r = X.p;
    in.y1 *= g;
    in.y2 *= g;
    for (ShapeEval* ev : {&in.e1, &in.e2}) {
      ev->grad *= f;
      ev->hess *= f;  // twice: f^2 alone may overflow
      ev->hess *= f;
    }
    const double xmax = res.x_1.cwiseAbs().maxCoeff();
    if (!res.x_1.allFinite() || !(xmax == 0.0 || std::isnormal(xmax))) {
      res.status = SolveStatus::NumericalFailure;
      if (warm) warm->reset();
    }
    return res;
  }

  /// A certified lower bound on alpha* for SolverOptions::alpha_max
  /// (formulas::alpha_lower_bound says why it holds; the batch lanes'
  /// screen of the rows Separated at once runs the same source).
  double alpha_lower_bound(double rn, const Vec3& rhat, const Mat3& R) const {
    return formulas::alpha_lower_bound<ScalarNum>(
        rn, rhat, R, [&](const Vec3& u) { return s1_.support(u); },
        [&](const double(&w)[3]) { return s2_.support(Vec3(w[0], w[1], w[2])); });
  }

  SBounds bounds(const Radii& r1, const Radii& r2) const {
    const double fL = o_.surrogate_factor * P_.L;
    return {std::log(fL / (r1.outer + r2.outer)) - o_.bound_margin, std::log(fL / (r1.inner + r2.inner)) + o_.bound_margin};
  }

  /// How many cold starts cold() has: 1 + max_restarts, at most 20.
  int cold_attempts() const {
    return 1 + std::min(o_.max_restarts, 1 + 2 * static_cast<int>(std::size(kFractions)));
  }
  /// A run that can go no further (line search failed, iteration limit,
  /// barrier out of stages) at the pair's own sharpness leaves a candidate
  /// answer if its residual is no more than the rounding floor
  /// (kkt_rounding_floor) and at most this: a floor estimate larger than
  /// 1e-8 means the point is no root, however rounded. The best candidate is
  /// returned as Converged only when every strategy has failed, so that each
  /// pose that some strategy solves to the tolerance still is.
  static constexpr double kFloorCeiling = 1e-8;
  /// A body whose surface curves over a length 10^8 times shorter than its
  /// distance from its frame origin (the beta = 10^4 tip of a needle cone,
  /// Rt = 4e-5 and 0.67 from its origin: a rounding radius of 2e-9) turns
  /// its normal by 7e-8 when the witness point moves by one unit in the last
  /// place, so the normals cannot be aligned to kFloorCeiling in doubles:
  /// the runs end at 1-2e-8, the order of the bodies deciding on which side
  /// of 1e-8. Such an end is a second-tier candidate when both witness
  /// points lie on their surfaces to the tolerance (the conditions that fix
  /// alpha* to first order) and only the normals' alignment and the
  /// stationarity in alpha stand above kFloorCeiling, within their rounding
  /// floor. Misaligned normals leave alpha* wrong by the square of the
  /// misalignment only, and the witness point within the floor's kUlps
  /// units in the last place of |y|. Returned as Converged only when every
  /// strategy has failed and no first-tier candidate exists, so no other
  /// solve changes. The generator's widest range (a Rt = 1e-5 tip at 0.5
  /// from its origin, beta = 10^4) puts one unit in the last place at 1e-7.
  static constexpr double kSharpFloorCeiling = 1e-6;

  template <class Prob>
  void note_floor(const Prob& P, const SBounds& B, double res, const KktPoint& p) {
    if constexpr (std::is_same_v<Prob, KktProblem<S1, S2>>) {
      const Vec6& z = p.z;
      const bool first_tier = res <= kFloorCeiling;
      if (P.sharp1 != s1_.sharpness() || P.sharp2 != s2_.sharpness() || !(res < (first_tier ? floor_res_ : sharp_floor_res_)) ||
          !(res <= kSharpFloorCeiling) || !genuine_root(z, B) || !(res <= kkt_rounding_floor(p)))
        return;
      if (first_tier) {
        floor_res_ = res;
        floor_z_ = z;
      } else if (kkt_surface_residual(p) <= o_.tolerance) {
        sharp_floor_res_ = res;
        sharp_floor_z_ = z;
      }
    }
  }
  static constexpr double kFractions[] = {0.5, 0.15, 0.85, 0.3, 0.7, 0.05, 0.95, 0.4, 0.6};

  /// Cold starts first..last-1 at the current sharpness: the ray guess, then
  /// eq:guess, then s_0 perturbed across the trust region (Algorithm 1,
  /// "Perturb s") alternating with x_0 moved off the ray.
  RunStatus cold(const Radii& r1, const Radii& r2, SolveResult& res, int first, int last) {
    const SBounds B = bounds(r1, r2);
    // The radial extents along the line of centres, measured once, when a
    // start first needs them (two ellipsoids' first start does not).
    double rho1 = 0.0, rho2 = 0.0;
    auto extents = [&] {
      if (rho1 > 0.0) return;
      rho1 = radial_extent(s1_, rhat_, P_.sharp1, r1);
      rho2 = radial_extent(s2_, Vec3(-(P_.R.transpose() * rhat_)), P_.sharp2, r2);
    };
    RunStatus st = RunStatus::IterationLimit;
    // A run from the support guess that fails is followed by the ray guess
    // before the other starts, so that the ray guess it replaced still gets
    // its turn. A run that stalls (homogeneous pairs, SolverOptions::
    // lm_stall_limit: flat faces again, 1.5% of SE-SEC poses on the paper's
    // sweep) is followed first by the other two points that support_guess
    // ranked, each ending at a stall as cheaply; only a stall of the ray run
    // hands over to rounding. Of 20,000 SE-SEC poses, 309 went on to
    // rounding from the first point and none now; the most steps a solve
    // took went from 22 to 12. (Trying those points after any failure
    // instead cost the random-body cut's hardest poses, which fail every
    // start, 60-150 more steps each.)
    int next0 = 0;  // slot 0's next start: 0 the first guess, 1..spares_ the other support points, then the ray
    for (int a = first; a < last; ++a) {
      Vec6 z0;
      double alpha0 = 0.0;  // every start sets it but the ellipsoid guess, which sets z0[3] itself
      const int sub = a == 0 ? next0 : 0;
      bool more = false;  // slot 0 has another start after this one
      if (a == 0 && sub == 0 && ellipsoid_guess(B, z0)) {
        // xi and s of the contact itself, up to rounding.
      } else if (a == 0 && sub == 0 && o_.support_guess && support_guess(B, r1, r2)) {
        z0 = pt_->z;  // evaluated there, with its multipliers (start_evaluated_)
        more = true;
      } else if (a == 0 && sub >= 1 && sub <= spares_) {
        z0 = spare_[sub - 1];
        more = true;
      } else if (a == 0) {
        extents();
        // The scaled bodies touch along r_hat at x = alpha rho1 r_hat when
        // alpha (rho1 + rho2) = |r_S|: exact for two spheres.
        alpha0 = std::clamp(o_.surrogate_factor * P_.L / (rho1 + rho2), std::exp(B.lo), std::exp(B.hi));
        z0.template head<3>() = (alpha0 * rho1 / P_.L) * rhat_ - P_.c1;
      } else if (a == 1) {
        // eq:guess: x on body 1's outer sphere, s at the middle of its bounds.
        alpha0 = std::exp(0.5 * (B.lo + B.hi));
        z0.template head<3>() = (r1.outer / P_.L) * rhat_ - P_.c1;
      } else if (a % 2 == 0) {
        // s_0 perturbed across the trust region, x on the ray.
        extents();
        alpha0 = std::exp(B.lo + kFractions[(a - 2) / 2] * (B.hi - B.lo));
        z0.template head<3>() = (alpha0 * rho1 / P_.L) * rhat_ - P_.c1;
      } else {
        // x_0 moved off the ray, towards the axis of body 1 nearest to it:
        // elongated bodies often touch far from the line of centres.
        const int axis = ((a - 3) / 2) % 3;
        Vec3 u = Vec3::Zero();
        u[axis] = rhat_[axis] >= 0.0 ? 1.0 : -1.0;
        const double rho = radial_extent(s1_, u, P_.sharp1, r1);
        alpha0 = std::exp(B.lo + kFractions[(a - 3) / 2] * (B.hi - B.lo));
        z0.template head<3>() = (alpha0 * rho / P_.L) * u - P_.c1;
      }
      if (alpha0 > 0.0) z0[3] = std::log(alpha0);
      if (!start_evaluated_) z0[4] = z0[5] = 0.0;  // set from eq:guess in newton()
      if (a > 0 || sub > 0) ++res.restarts;
      if (!in_continuation_) run_kind_ = a == 0 && sub == 0 ? "cold" : "restart";
      st = newton(B, z0, true, res.iterations);
      if (st == RunStatus::Converged) return st;
      if (more) {  // the same slot, from the next start
        next0 = stall_exit_ && stalled_ ? sub + 1 : spares_ + 1;
        stalled_ = false;
        --a;
      }
    }
    return st;
  }

  /// The first cold guess of two ellipsoids at the current sharpness
  /// (ellipsoid_contact on the surrogate problem, r_S = L (c1 + c2)): the
  /// root itself up to rounding, so Newton only confirms it. False for any
  /// other pair (two spheres included), or if the guess is not usable (the
  /// ray guess follows).
  bool ellipsoid_guess(const SBounds& B, Vec6& z0) {
    // Two spheres: the ray guess is exact to the last bit, this only to
    // rounding (which can cost a step).
    if constexpr (std::is_same_v<S1, Sphere> && std::is_same_v<S2, Sphere>) return false;
    Mat3 M1, M2;
    if (!ellipsoid_matrix(s1_, P_.sharp1, M1) || !ellipsoid_matrix(s2_, P_.sharp2, M2)) return false;
    double alpha = 0.0;
    Vec3 x;
    const double l0 = seed_l_;
    seed_l_ = -1.0;  // the warm seed serves the first guess only, not continuation stages
    const Mat3 M2r = P_.R * M2 * P_.R.transpose();
    const Vec3 rS = P_.L * (P_.c1 + P_.c2);
    if (!(l0 > 0.0 && l0 < 1.0 ? ellipsoid_contact_from(M1, M2r, rS, l0, alpha, x) : ellipsoid_contact(M1, M2r, rS, alpha, x)))
      return false;
    // s = ln alpha by formulas::log_positive, as the closed-form lanes take
    // it (one vector for W rows, where the library's log is a call a row);
    // alpha <= 0 or NaN fails here as its NaN logarithm would.
    if (!(alpha > 0.0)) return false;
    const double s = formulas::log_positive<ScalarNum>(alpha);
    if (!(s >= B.lo && s <= B.hi)) return false;
    z0.template head<3>() = x / P_.L - P_.c1;
    z0[3] = s;
    return true;
  }

  /// Both bodies are ellipsoids at their own sharpness (ellipsoid_guess
  /// applies), two spheres excepted.
  bool has_ellipsoid_form() const {
    if constexpr (std::is_same_v<S1, Sphere> && std::is_same_v<S2, Sphere>) {
      return false;
    } else {
      Mat3 M;
      return ellipsoid_matrix(s1_, s1_.sharpness(), M) && ellipsoid_matrix(s2_, s2_.sharpness(), M);
    }
  }

  /// The first cold guess of every other pair: the contact on a separating
  /// plane, from the support functions. Each body's boundary point on the
  /// line of centres, p_i, with its outer normal n_i, offers a plane
  /// direction u: for u = n1, h1(u) = u.p1, and the scaled bodies can touch
  /// across a plane normal to u no sooner than at
  ///   alpha(u) = u.r_S / (h1(u) + h2(-R^T u)),
  /// which is alpha* itself when u is the contact normal. (It is a lower
  /// bound where both supports are exact or bounded from above: the
  /// superquadrics' and the exact polytope's are; the cone's boundary point
  /// comes from two Newton steps and its normal from the last of them, so
  /// there it is a guess only. Nothing relies on the bound.) The u with
  /// the larger alpha(u) is kept; the contact lies on that plane, at the
  /// support point of one scaled body, of the other, or between them, and
  /// the three are ranked by ||F|| with the multipliers of eq:guess.
  ///
  /// Where the ray guess starts both bodies on flat faces (n = 8 bodies and
  /// cones face to face), J is singular there and Newton stalls; the support
  /// points reach the rim or edge where the bodies touch. Measured on the
  /// paper's sweep (20,000 poses per pair, support_guess off -> on), mean
  /// Newton steps per cold solve: SE-SE 8.88 -> 5.66 (929 rounding
  /// continuations -> 0), TC-SE 8.57 -> 5.41 (max 151 -> 15), Poly-Poly
  /// 6.26 -> 5.36. Leaves the best start evaluated in pt_
  /// (start_evaluated_) and the other two in spare_, best first; false if
  /// no plane direction faces the other body (the ray guess follows).
  /// Long: the exact start, the plane and the three candidates are one
  /// choice, in the order the cold lanes take it (newton_lanes_cold.hpp), on
  /// the same formulas (formulas::support_plane, support_starts, kkt_merit,
  /// rank_starts).
  bool support_guess(const SBounds& B, const Radii& r1, const Radii& r2) {
    // Two spheres: the ray guess is their contact, for one evaluation.
    if constexpr (std::is_same_v<S1, Sphere> && std::is_same_v<S2, Sphere>) return false;
    const Vec3 rS = P_.L * (P_.c1 + P_.c2);
    // Two polytopes, or a polytope and an ellipsoid: the exact bodies'
    // contact (exact_start: a small linear program, or a few active-set
    // steps against the ellipsoid, moved to the smooth contact to first
    // order where an edge or a vertex of a sharp polytope touches it, a
    // third of the way for two polytopes) instead of the three points
    // below, with no spares (polytopes never end a run at a stall).
    // Measured on 2,000 poses of the paper's sweep, Newton steps (chord
    // steps included) per cold solve from the three points and from the
    // exact start: Poly-Poly 5.37, 4.48; Poly-Ellip 4.55, 3.44. Where it
    // gives no start, the three points follow.
    if constexpr (kHasExactStart<S1, S2>) {
      double alpha = 0.0;
      Vec3 x;
      if (exact_start(s1_, s2_, P_.sharp1, P_.sharp2, P_.R, rS, alpha, x)) {
        Vec6 z;
        z.template head<3>() = x / P_.L - P_.c1;
        double clamped;
        z[3] = clamped_log(alpha, B, clamped);
        z[4] = z[5] = 0.0;
        kkt_residual(P_, z, *pt_);
        init_lambda(P_, *pt_);
        spares_ = 0;
        start_evaluated_ = std::isfinite(pt_->F.squaredNorm());
        if (start_evaluated_) return true;
      }
    }
    const Vec3 d2 = -(P_.R.transpose() * rhat_);
    Vec3 p1, n1, p2, n2;
    boundary_on_ray(s1_, rhat_, P_.sharp1, r1, p1, n1);
    boundary_on_ray(s2_, d2, P_.sharp2, r2, p2, n2);
    // The best plane that the two normals offer and its points
    // (formulas::support_plane, which the cold lanes run too), and the three
    // starts on it (formulas::support_starts).
    double best, q1[3], q2[3];
    bool none = false;
    auto support = [](const auto& s, double sharp) {
      return [&s, sharp](const double (&u)[3], double (&a)[3]) {
        const Vec3 q = s.support_point(Vec3(u[0], u[1], u[2]), sharp);
        a[0] = q[0], a[1] = q[1], a[2] = q[2];
      };
    };
    formulas::support_plane<ScalarNum>(P_.R, rS, p1, n1, p2, n2, support(s1_, P_.sharp1), support(s2_, P_.sharp2), best,
                                       q1, q2, none);
    if (!(best > 0.0) || !std::isfinite(best)) return false;
    double alpha;
    const double s = clamped_log(best, B, alpha);
    double xa[3][3];
    formulas::support_starts<ScalarNum>(P_.R, rS, alpha, q1, q2, xa);
    const Vec3 xs[3] = {Vec3(xa[0][0], xa[0][1], xa[0][2]), Vec3(xa[1][0], xa[1][1], xa[1][2]),
                        Vec3(xa[2][0], xa[2][1], xa[2][2])};
    // Each start evaluated (kkt_residual, init_lambda), the first two in pt_
    // and trial_, the third in a local, and ranked by merit
    // (formulas::rank_starts, which the cold lanes run too).
    KktPoint third;
    KktPoint* at[3] = {pt_, trial_, &third};
    double merit[3];
    for (int c = 0; c < 3; ++c) {
      Vec6 z;
      z.template head<3>() = xs[c] / P_.L - P_.c1;
      z[3] = s;
      z[4] = z[5] = 0.0;
      kkt_residual(P_, z, *at[c]);
      init_lambda(P_, *at[c]);
      merit[c] = formulas::kkt_merit<ScalarNum>(at[c]->F.data());
    }
    const formulas::StartRanking<ScalarNum> rank = formulas::rank_starts<ScalarNum>(merit);
    spares_ = 0;
    for (const int c : rank.spare)
      if (std::isfinite(merit[c])) spare_[spares_++] = at[c]->z;  // the finite ones, a prefix
    if (rank.best == 1) std::swap(pt_, trial_);
    else if (rank.best == 2) *pt_ = third;
    start_evaluated_ = std::isfinite(merit[rank.best]);
    return start_evaluated_;
  }

  /// Continuation in beta or n (Sec. "Continuation strategy"): solve a
  /// smoother pair cold, then sharpen geometrically, warm-starting each stage
  /// from the previous one. The last stage is the target pair itself.
  /// With barrier_start, the first stage is solved by barrier() rather
  /// than by the cold starts.
  RunStatus continuation(SolveResult& res, bool barrier_start = false, bool weighted = false) {
    run_kind_ = "continuation";
    const double t1 = s1_.sharpness(), t2 = s2_.sharpness();
    const double st1 = s1_.has_sharpness() ? s1_.continuation_start() : t1;
    const double st2 = s2_.has_sharpness() ? s2_.continuation_start() : t2;
    const double lr = std::log(o_.continuation_ratio);
    // The stage count in doubles, capped before the cast (a ratio near 1 or
    // a sharpness of 1e300 would overflow int): the stages then grow by
    // more than the ratio, never by more stages than kMaxContinuationStages.
    double Nd = 1.0;
    if (s1_.has_sharpness()) Nd = std::max(Nd, std::ceil(std::log(t1 / st1) / lr - 1e-9));
    if (s2_.has_sharpness()) Nd = std::max(Nd, std::ceil(std::log(t2 / st2) / lr - 1e-9));
    const int N = Nd < SolverOptions::kMaxContinuationStages ? static_cast<int>(Nd) : SolverOptions::kMaxContinuationStages;
    RunStatus st = RunStatus::IterationLimit;
    // In the last fallback (after the weighted barrier), a stage that
    // Newton does not finish from the previous one is split: the step in log
    // sharpness is halved and retried from the last converged stage, at most
    // kMaxStageSplits times in all. A box against a cone, both at
    // beta = 10^4 and ~200:1, fails the ratio-2 stage 625 -> 1250 and
    // finishes through its halves. The earlier continuations keep their
    // fixed stages: their failures go on to the next fallback, which solves
    // them sooner (splitting there cost a sphere-cone pose 70 iterations).
    int splits = weighted ? kMaxStageSplits : 0;
    double f_done = 0.0, f = 0.0;  // the last converged stage, the one tried
    bool first = true;             // no stage has converged yet
    Vec6 z_done = Vec6::Zero();
    while (f_done < 1.0) {
      P_.sharp1 = stage_at(st1, t1, f, N);
      P_.sharp2 = stage_at(st2, t2, f, N);
      const Radii r1 = s1_.radii(P_.sharp1), r2 = s2_.radii(P_.sharp2);
      if (first && barrier_start) {
        st = barrier(res, weighted);
        run_kind_ = "continuation";
      } else if (first) {
        in_continuation_ = true;
        st = cold(r1, r2, res, 0, cold_attempts());
        in_continuation_ = false;
      } else {
        st = newton(bounds(r1, r2), z_done, false, res.iterations);
      }
      if (st == RunStatus::Converged) {
        f_done = f;
        z_done = pt_->z;
        first = false;
        // The next grid point j / N (exactly j / N when no stage was split).
        f = std::min(1.0, (std::floor(f_done * N + 1e-9) + 1.0) / N);
        continue;
      }
      if (first || splits <= 0) break;
      const double mid = 0.5 * (f_done + f);
      if (stage_at(st1, t1, mid, N) == stage_at(st1, t1, f_done, N) && stage_at(st2, t2, mid, N) == stage_at(st2, t2, f_done, N)) break;
      --splits;
      f = mid;
    }
    P_.sharp1 = t1;
    P_.sharp2 = t2;
    return st;
  }
  static constexpr int kMaxStageSplits = 8;

  /// Rounding continuation: both bodies start as spheres (where the cold
  /// guess is exact) and are blended into their true shapes; the last stage
  /// is the target pair.
  RunStatus rounding(SolveResult& res, bool outer) {
    run_kind_ = "rounding";
    // Spheres through the boundary points on the line of centres suit
    // needles; outer spheres (bodies that shrink onto the targets) suit
    // plates facing each other. The second is tried if the first fails.
    const double rho1 = outer ? s1_.radii().outer : radial_extent(s1_, rhat_, P_.sharp1, s1_.radii());
    const double rho2 = outer ? s2_.radii().outer : radial_extent(s2_, Vec3(-(P_.R.transpose() * rhat_)), P_.sharp2, s2_.radii());
    Rounded<S1> q1{&s1_, rho1, 0.0};
    Rounded<S2> q2{&s2_, rho2, 0.0};
    KktProblem<Rounded<S1>, Rounded<S2>> Q{&q1, &q2, P_.R, P_.c1, P_.c2, P_.L, P_.sharp1, P_.sharp2, 1.0, 1.0};
    // Stage t = 0: two spheres, solved exactly by the ray guess.
    q1.t = q2.t = 0.0;
    const double alpha0 = o_.surrogate_factor * P_.L / (rho1 + rho2);
    Vec6 z;
    z.template head<3>() = (alpha0 * rho1 / P_.L) * rhat_ - P_.c1;
    z[3] = std::log(alpha0);
    z[4] = z[5] = 0.0;
    RunStatus st = newton(Q, bounds(q1.radii(P_.sharp1), q2.radii(P_.sharp2)), z, true, res.iterations);
    if (st != RunStatus::Converged) return st;
    // Then shrink the sphere's weight u = 1 - t geometrically, adapting the
    // ratio: a failed stage is retried from the last solution with a smaller
    // step. A 1000:1 body needs u down to ~1e-4 before its own shape dominates.
    double u = 1.0, ratio = 0.25;
    z = pt_->z;
    for (int stage = 0; stage < 60 && u > 1e-7; ++stage) {
      const double un = u * ratio;
      q1.t = q2.t = 1.0 - un;
      st = newton(Q, bounds(q1.radii(P_.sharp1), q2.radii(P_.sharp2)), z, false, res.iterations);
      if (st == RunStatus::Converged) {
        u = un;
        z = pt_->z;
        ratio = std::max(ratio * ratio, 1e-3);
      } else {
        ratio = std::sqrt(ratio);
        if (ratio > 0.95) return st;
      }
    }
    return newton(bounds(s1_.radii(), s2_.radii()), z, false, res.iterations);
  }

  /// The interior-point fallback, at the sharpness in P_ (the target pair, or
  /// the first stage of continuation()). The scaled bodies' feasible set
  ///   K_i = {(x, alpha) : alpha > 0, alpha phi_i(y_i(x, alpha)) <= 0}
  /// is the cone over body i (the perspective of a convex set), so alpha* is
  /// the minimum of the linear function alpha over the convex set K_1 n K_2
  /// (Sec. "Problem Formulation"). In the surrogate coordinates w = (xi, a),
  /// a = alpha_S, the constraint functions G_i(w) = a phi_i(y_i) are convex
  /// (perspectives of convex functions), with
  ///   grad G_i = (L grad_world phi_i, phi_i - y_i . grad phi_i),
  ///   hess G_i = (1/a) M_i^T hess phi_i M_i,   M_1 = [L I, -y1], M_2 = [L R^T, -y2].
  /// The log-barrier f_t(w) = t a - log(-G_1) - log(-G_2) is convex and finite
  /// exactly on the interior of K_1 n K_2, which holds the explicit point
  /// (xi = 0, a_0) below, so damped Newton with backtracking on f_t converges
  /// from there whatever the sharpness and the pose: no basin to miss. Its
  /// minimiser has a - alpha*_S <= 2/t, and mu_i = 1/(t (-G_i)) are the
  /// multipliers of the KKT system (lambda_i = a mu_i in eq:kkt_residual's
  /// scaling). t grows geometrically; from a relative gap of
  /// barrier_handover the KKT Newton iteration finishes the root (or the
  /// barrier goes on to the tolerance itself). Slower than Newton on the KKT
  /// system, so it runs only when every other start has failed.
  ///
  /// weighted: f_t(w) = t a - w_1 log(-G_1) - w_2 log(-G_2), w_1 + w_2 = 2,
  /// the weights set after each stage in proportion to the multipliers just
  /// estimated (the first stage has w_1 = w_2 = 1). The barrier stays convex
  /// with the same minimiser as t grows, mu_i = w_i / (t (-G_i)), and the
  /// depth of the centred point inside body i is -phi_i = w_i / (t lambda_i).
  /// Unweighted, a millimetre body beside one 10^5..10^8 times larger (the
  /// multipliers differ as much) is centred 10^5..10^8 times deeper than its
  /// partner: still 10 rounding widths inside its beta = 10^4 rim when the
  /// large body's depth reaches the rounding of phi_1, so neither the barrier
  /// nor the KKT Newton iteration from its point gets closer. Weighted, both
  /// depths are about the relative gap, and the handover comes with the
  /// small body's rim resolved. Only tried after the unweighted barrier and
  /// its continuation fail, so every pose those solve is solved as before.
  /// Long: the barrier's path (centring, the steps in its parameter, the
  /// handover to the KKT iteration) is one iteration over one state.
  RunStatus barrier(SolveResult& res, bool weighted = false) {
    run_kind_ = "barrier";
    bw1_ = bw2_ = 1.0;
    const Radii r1 = s1_.radii(P_.sharp1), r2 = s2_.radii(P_.sharp2);
    const SBounds B = bounds(r1, r2);
    const double fS = o_.surrogate_factor;
    // Strictly feasible: with xi = 0, |y_i| = fS r_i_out / a, inside the
    // certified inner ball of body i (where phi_i < 0) for a > fS r_out / r_in.
    Vec4 w(0.0, 0.0, 0.0, 2.0 * fS * std::max(r1.outer / r1.inner, r2.outer / r2.inner));
    BarrierPoint cur, trial;
    if (!barrier_eval(w, cur) || !(cur.G1 < 0.0 && cur.G2 < 0.0)) return RunStatus::NumericalFailure;
    double t = 1.0 / w[3];
    bool handed_over = false;
    double best_rr = std::numeric_limits<double>::infinity();  // the best stage point, for the rounding floor
    Vec6 best_z = Vec6::Zero();
    for (int outer = 0; outer < o_.barrier_max_stages; ++outer) {
      // Centre: damped Newton on f_t.
      for (int it = 0; it < o_.barrier_max_newton; ++it) {
        ++res.iterations;
        Vec4 g;
        Mat4 H;
        barrier_derivatives(cur, t, g, H);
        // The cone's side term r^2/R(y1)^2 is quasi-convex, not convex, so
        // f_t may curve down: clamp the eigenvalues of its Hessian from below
        // (a descent direction whatever the curvature).
        // Symmetric diagonal scaling first, so that the clamp acts on the
        // curvature that is real and not on the units of xi against a (a
        // small sharp body beside a large one spreads H's diagonal over
        // 15 orders of magnitude).
        Vec4 D;
        for (int i = 0; i < 4; ++i) {
          const double h = std::abs(H(i, i));
          D[i] = h > 0.0 && std::isfinite(h) ? 1.0 / std::sqrt(h) : 1.0;
        }
        const Mat4 Hs = D.asDiagonal() * H * D.asDiagonal();
        const Vec4 gs = D.cwiseProduct(g);
        Eigen::SelfAdjointEigenSolver<Mat4> eig(Hs);
        Vec4 lam = eig.eigenvalues();
        const double lmax = std::max(std::abs(lam[3]), 1e-300);
        for (int i = 0; i < 4; ++i) lam[i] = std::max(std::abs(lam[i]), 1e-14 * lmax);
        const Mat4& V = eig.eigenvectors();
        Vec4 d = -D.cwiseProduct(V * (V.transpose() * gs).cwiseQuotient(lam));
        if (!d.allFinite() || !(g.dot(d) < 0.0)) d = -D.cwiseProduct(gs) / lmax;
        const double dec = -g.dot(d);  // Newton decrement squared
        if (dec < 1e-12) break;
        // Stay inside: a > 0, and the step no larger than the scaled pair's size.
        double step = 1.0;
        const double nd = d.template head<3>().norm() / (o_.barrier_max_step_x * std::max(1.0, w[3]));
        if (nd > 1.0) step = 1.0 / nd;
        if (d[3] < 0.0) step = std::min(step, 0.9 * w[3] / -d[3]);
        bool ok = false;
        for (int bt = 0; bt < 60; ++bt, step *= 0.5) {
          const Vec4 wn = w + step * d;
          if (barrier_eval(wn, trial) && trial.G1 < 0.0 && trial.G2 < 0.0 &&
              barrier_change(cur, trial, t) <= -1e-4 * step * dec) {
            ok = true;
            break;
          }
        }
        if (!ok) break;  // no decrease representable: centred as far as doubles allow
        if (trace_) barrier_steps_ = it + 1;
        w = trial.w;
        std::swap(cur, trial);
      }
      const double gap = (bw1_ + bw2_) / t;
      // The barrier point as a KKT point: does it already meet the tolerance?
      Vec6 z;
      z.template head<3>() = w.template head<3>();
      z[3] = std::log(w[3]);
      z[4] = bw1_ * w[3] / (t * -cur.G1);
      z[5] = bw2_ * w[3] / (t * -cur.G2);
      kkt_residual(P_, z, *pt_);
      if (trace_) emit(P_, barrier_steps_, "barrier-stage", gap);
      const double rr = kkt_relative_residual(*pt_);
      if (!std::isfinite(rr)) return RunStatus::NumericalFailure;
      if (rr < best_rr) {
        best_rr = rr;
        best_z = z;
      }
      if (rr <= o_.tolerance) return z[3] >= B.lo && z[3] <= B.hi ? RunStatus::Converged : RunStatus::SpuriousRoot;
      if (!handed_over && gap <= o_.barrier_handover * w[3]) {
        handed_over = true;
        const Vec6 z0 = z;
        handover_ = true;
        const RunStatus st = newton(B, z0, false, res.iterations);
        handover_ = false;
        if (st == RunStatus::Converged) return st;
        run_kind_ = "barrier";
      }
      t *= o_.barrier_growth;
      if (weighted) {
        // Weights in proportion to the multipliers just estimated, so that
        // the next stage centres both bodies at the same depth -phi_i.
        const double l1 = z[4], l2 = z[5];
        if (l1 > 0.0 && l2 > 0.0 && std::isfinite(l1 + l2)) {
          bw1_ = std::max(2.0 * l1 / (l1 + l2), 1e-300);
          bw2_ = std::max(2.0 * l2 / (l1 + l2), 1e-300);
        }
      }
    }
    // Centring in doubles ends before the tolerance: the best stage point is
    // a candidate for the rounding floor.
    if (best_rr <= kSharpFloorCeiling) {
      kkt_residual(P_, best_z, *pt_);
      note_floor(P_, B, best_rr, *pt_);
    }
    return RunStatus::IterationLimit;
  }

  struct BarrierPoint {
    Vec4 w;
    Vec3 y1, y2;
    ShapeEval e1, e2;
    double G1 = 0.0, G2 = 0.0;
  };

  bool barrier_eval(const Vec4& w, BarrierPoint& b) const {
    b.w = w;
    const double a = w[3];
    if (!(a > 0.0)) return false;
    const double c = P_.L / a;
    const Vec3 xi = w.template head<3>();
    b.y1 = c * (xi + P_.c1);
    b.y2 = c * (P_.R.transpose() * (xi - P_.c2));
    s1_.eval(b.y1, P_.sharp1, b.e1);
    s2_.eval(b.y2, P_.sharp2, b.e2);
    b.G1 = a * b.e1.phi;
    b.G2 = a * b.e2.phi;
    return std::isfinite(b.G1) && std::isfinite(b.G2);
  }

  /// f_t(b) - f_t(a), formed from differences: at t ~ 1e12 the terms of f_t
  /// themselves differ by 12 orders of magnitude, and their rounding would
  /// swamp the decrease the line search looks for.
  double barrier_change(const BarrierPoint& a, const BarrierPoint& b, double t) const {
    return t * (b.w[3] - a.w[3]) - bw1_ * std::log(b.G1 / a.G1) - bw2_ * std::log(b.G2 / a.G2);
  }

  void barrier_derivatives(const BarrierPoint& b, double t, Vec4& g, Mat4& H) const {
    const double a = b.w[3], L = P_.L;
    g.setZero();
    g[3] = t;
    H.setZero();
    auto add = [&](double wt, double G, const Vec3& gw, double ga, const Mat4& HG) {
      Vec4 dG;
      dG.template head<3>() = gw;
      dG[3] = ga;
      const double iv = 1.0 / -G;
      g += (wt * iv) * dG;
      H += (wt * iv * iv) * dG * dG.transpose() + (wt * iv) * HG;
    };
    Eigen::Matrix<double, 3, 4> M1, M2;
    M1.template leftCols<3>() = L * Mat3::Identity();
    M1.col(3) = -b.y1;
    M2.template leftCols<3>() = L * P_.R.transpose();
    M2.col(3) = -b.y2;
    add(bw1_, b.G1, L * b.e1.grad, b.e1.phi - b.y1.dot(b.e1.grad), (M1.transpose() * b.e1.hess * M1) / a);
    add(bw2_, b.G2, L * (P_.R * b.e2.grad), b.e2.phi - b.y2.dot(b.e2.grad), (M2.transpose() * b.e2.hess * M2) / a);
  }

  /// The sharpness a fraction f of the way from start to target, geometric.
  /// On the grid f = j / N it is integral where both ends are (superellipsoid
  /// exponents, whose integral powers are cheaper); between grid points (a
  /// split stage) it is not, so that a split of n = 1 -> 2 is a real step.
  static double stage_at(double start, double target, double f, int N) {
    if (f >= 1.0 || start == target) return target;
    const double v = start * std::pow(target / start, f);
    const bool on_grid = std::abs(f * N - std::round(f * N)) < 1e-9;
    const bool integral = on_grid && start == std::floor(start) && target == std::floor(target);
    return integral ? std::max(start, std::round(v)) : v;
  }

  /// One safeguarded Newton run (Algorithm 1, inner loop). Leaves its last
  /// iterate in pt_.
  template <class Prob>
  void emit(const Prob& P, int it, const char* step, double t) {
    emit(P, it, step, t, *pt_);
  }
  template <class Prob>
  void emit(const Prob& P, int it, const char* step, double t, const KktPoint& p) {
    TraceRecord r;
    r.run = run_;
    r.run_kind = run_kind_;
    r.sharp1 = P.sharp1;
    r.sharp2 = P.sharp2;
    r.iteration = it;
    r.z = p.z;
    r.residual = kkt_relative_residual(p);
    r.step = step;
    r.step_length = t;
    trace_->record(r);
  }

  RunStatus newton(const SBounds& B, const Vec6& z0, bool init_multipliers, int& iters) {
    return newton(P_, B, z0, init_multipliers, iters);
  }

  /// The surrogate problem of the pose X (kkt.hpp): its data, the direction
  /// r_hat and r.
  void set_problem(const Pose& X, const Vec3& rhat, const Radii& r1, const Radii& r2) {
    const double fS = o_.surrogate_factor;
    P_.s1 = &s1_;
    P_.s2 = &s2_;
    P_.R = X.R;
    P_.L = r1.outer + r2.outer;
    P_.c1 = (fS * r1.outer / P_.L) * rhat;
    P_.c2 = (fS * r2.outer / P_.L) * rhat;
    P_.sharp1 = s1_.sharpness();
    P_.sharp2 = s2_.sharpness();
    P_.inv_sigma1 = 1.0 / s1_.phi_scale();
    P_.inv_sigma2 = 1.0 / s2_.phi_scale();
    rhat_ = rhat;
    r_ = X.p;
  }

  template <class Prob>
  RunStatus newton(const Prob& P, const SBounds& B, const Vec6& z0, bool init_multipliers, int& iters) {
    // The first run (warm, or the first cold start) is bold; later ones cautious.
    tau_ = run_ == 0 ? o_.lambda_fraction_to_boundary : o_.lambda_fraction_to_boundary_restart;
    const RunStatus st = newton_run(P, B, z0, init_multipliers, iters);
    ++run_;
    return st;
  }

  /// The scalar solver's run of formulas::newton_run (formulas/newton_run.hpp),
  /// the function the batch lanes run too: one problem, the points in pt_
  /// and trial_ (a candidate is the trial: kSharedCand), the Jacobian
  /// factorised in kkt_lu_'s storage (and formed again in J_ for the rare
  /// steps that need J itself), the options read where they are, the exits
  /// as a RunStatus, and the trace.
  template <class Prob>
  struct Run {
    using Point = KktPoint;
    using Vec = Vec6;
    using Mat = Mat6r;
    static constexpr bool kBands = false;
    static constexpr bool kPerLaneLimit = false;
    static constexpr bool kSharedCand = true;
    static constexpr bool kCheapEnds = false;

    PairSolver& s;
    const Prob& P;
    const SBounds& B;
    KktPoint* pt;
    KktPoint* trial;
    KktPoint* cand;
    RunStatus status = RunStatus::Converged;

    Run(PairSolver& solver, const Prob& p, const SBounds& b)
        : s(solver), P(p), B(b), pt(solver.pt_), trial(solver.trial_), cand(solver.trial_) {}
    const SolverOptions& o() const { return s.o_; }
    double tol() const { return o().tolerance; }
    static double chord_res() { return kChordResidual; }
    double ext_res() const { return o().extension_residual; }
    static double cut() { return 0.1; }  // each block of the extension cuts the residual tenfold
    double lo() const { return B.lo; }
    double hi() const { return B.hi; }
    int cap() const { return s.iter_cap_; }
    static bool cap_lanes() { return true; }
    int max_it() const { return s.handover_ ? std::max(o().max_iterations, o().barrier_max_newton) : o().max_iterations; }
    static bool extends() { return true; }
    int max_it_ext() const { return o().max_iterations_extended; }
    int max_backtracks() const { return o().max_backtracks; }
    double armijo_c() const { return o().armijo_c; }
    double backtrack_factor() const { return o().backtrack_factor; }
    int stall_limit() const { return s.stall_exit_ ? o().lm_stall_limit : 0; }
    double stall_ratio2() const {
      const double ratio = 1.0 - o().lm_min_progress;
      return ratio * ratio;
    }
    double fast_pivot() const { return kFastPivotFactor * o().min_pivot_ratio; }
    double min_pivot() const { return o().min_pivot_ratio; }
    static bool slow_lu() { return true; }

    void residual(const Vec6& z, KktPoint& p, bool&) const { kkt_residual(P, z, p); }
    static double relres(const KktPoint& p, bool&) { return kkt_relative_residual(p); }
    static double merit(const KktPoint& p) { return formulas::kkt_merit<ScalarNum>(p.F.data()); }
    static void sum(const Vec6& z, const Vec6& dz, Vec6& zt) { zt = z + dz; }
    static void axpy(const Vec6& z, double t, const Vec6& dz, Vec6& zt) { zt = z + t * dz; }
    static void negate(const Vec6& F, Vec6& mF) { mF = -F; }
    /// x - x is 0 for a finite x, else NaN (Eigen's allFinite, written out:
    /// where the unit's inlining budget ran out, allFinite was left a call).
    [[gnu::always_inline]] static bool all_finite(const Vec6& v) {
      return ((v[0] - v[0]) + (v[1] - v[1])) + ((v[2] - v[2]) + (v[3] - v[3])) + ((v[4] - v[4]) + (v[5] - v[5])) == 0.0;
    }
    static bool near(double, double) { return false; }
    /// Shrinks or projects a step so that s stays in its bounds, |ds| and
    /// the witness-point move stay under their limits and lambda stays
    /// positive; the largest admissible step length t in (0, 1] from p.
    [[gnu::always_inline]] double limit_step(const KktPoint& p, Vec6& dz) const {
      return formulas::limit_step<ScalarNum>(p.z, p.alpha, dz, B.lo, B.hi, s.o_.max_step_s, s.o_.max_step_x, s.tau_, kLimitBand);
    }
    void factor(const KktPoint& p) {
      kkt_jacobian(P, p, s.kkt_lu_.matrix());  // factorised in place
      s.jacobian_in_J_ = false;
      s.kkt_lu_.factor();
    }
    double fast_ratio() const { return s.kkt_lu_.pivot_ratio(); }
    void fast_solve(const Vec6& b, Vec6& x) const { x = s.kkt_lu_.solve(b); }
    const Mat6r& jacobian(const KktPoint& p) {
      s.jacobian_to_J(P, p);
      return s.J_;
    }
    static double& at(Mat6r& m, int i, int j) { return m(i, j); }
    static double at(const Mat6r& m, int i, int j) { return m(i, j); }
    double lu6(const Mat6r& A, const Vec6& b, Vec6& x) {
      const double ratio = s.lu_.compute(A);
      x = s.lu_.solve(b);
      return ratio;
    }
    static void take(bool m, const KktPoint& a, KktPoint& b) {
      if (m) b = a;
    }
    void converged(bool, int it, const KktPoint& p) {
      status = RunStatus::Converged;
      if (s.trace_) s.emit(P, it, "converged", 0.0, p);
    }
    void end(bool, formulas::RunEnd why, int it, double res, const KktPoint& p) {
      using formulas::RunEnd;
      const char* what = "line-search-failed";
      switch (why) {
        case RunEnd::NonFinite:
          status = RunStatus::NumericalFailure;
          what = "non-finite";
          break;
        case RunEnd::Spurious:
          status = RunStatus::SpuriousRoot;
          what = "spurious";
          break;
        case RunEnd::Capped:
          status = RunStatus::IterationLimit;
          what = "iteration-limit";
          break;
        case RunEnd::IterationLimit:
          s.note_floor(P, B, res, p);
          status = RunStatus::IterationLimit;
          what = "iteration-limit";
          break;
        case RunEnd::LineSearchFailed:
        case RunEnd::Unsure:  // (the lanes' only)
          s.note_floor(P, B, res, p);
          status = RunStatus::LineSearchFailed;
          break;
        case RunEnd::Stalled:
          s.stalled_ = true;
          status = RunStatus::LineSearchFailed;
          return;  // traced with its step (stepped)
      }
      if (s.trace_) s.emit(P, it, what, 0.0, p);
    }
    void stepped(bool, bool chorded, bool lm, int it, double t, bool stalled, const KktPoint& p) {
      if (!s.trace_) return;
      s.emit(P, it, stalled ? "lm-stalled" : chorded ? "chord" : lm ? "lm" : "newton", t, p);
    }
    /// The LM step (formulas::lm_trials): J^T J, g and the first damping at
    /// p, and each trial's step (lm_system.hpp, the code the lanes run lane
    /// by lane).
    static constexpr bool lm_in_run() { return true; }
    int lm_max_trials() const { return o().lm_max_trials; }
    [[gnu::noinline]] void lm_begin(bool, const KktPoint& p) {
      s.jacobian_to_J(P, p);
      lm_normal_equations(s.J_.data(), p.F.data(), o().lm_initial_damping, lm_JtJ.data(), lm_g.data(), &lm_mu);
    }
    [[gnu::noinline]] bool lm_direction(bool, Vec6& dz) {
      const bool ok = idcol::detail::lm_direction(lm_JtJ.data(), lm_g.data(), lm_mu, dz.data());
      lm_mu *= 10.0;
      return ok;
    }
    static void lm_record(bool, int, const formulas::RunCounters<ScalarNum>&, const KktPoint&) {}
    Mat6 lm_JtJ;  // the LM step's normal equations (lm_begin)
    Vec6 lm_g;
    double lm_mu = 0.0;
  };

  /// One Newton run (formulas::newton_run) from z0, evaluated here unless
  /// support_guess left it evaluated in pt_ with its multipliers, or from
  /// where the batch lanes left it (resume_run).
  template <class Prob>
  RunStatus newton_run(const Prob& P, const SBounds& B, const Vec6& z0, bool init_multipliers, int& iters) {
    if (start_evaluated_) {
      start_evaluated_ = false;  // pt_ holds z0 with its multipliers (support_guess)
    } else {
      kkt_residual(P, z0, *pt_);
      if (init_multipliers) init_lambda(P, *pt_);
    }
    formulas::RunCounters<ScalarNum> c;
    if (__builtin_expect(resume_ != nullptr, false)) resume_run(P, c, iters);
    c.iters = iters;
    Run<Prob> r(*this, P, B);
    formulas::newton_run<ScalarNum>(r, true, c);
    pt_ = r.pt;
    trial_ = r.trial;
    iters = static_cast<int>(c.iters);
    return r.status;
  }

  /// A run that the batch lanes made up to an LM step (ColdResume) goes on
  /// from there: a point after the start evaluated again (kkt_residual, the
  /// lanes' bits; the start itself is support_guess's, evaluated already),
  /// and the run's counters as the lanes left them, its first step the LM
  /// step. Out of line: inlined, it cost every solve a few dozen
  /// instructions.
  template <class Prob>
  [[gnu::noinline, gnu::cold]] void resume_run(const Prob& P, formulas::RunCounters<ScalarNum>& c, int& iters) {
    if (resume_->it > 0) kkt_residual(P, resume_->z, *pt_);
    c.it0 = resume_->it;
    iters = resume_->iterations;
    c.stalls = resume_->stalls;
    c.chord_ok = resume_->chord_ok;
    c.chord_tried = resume_->chord_tried;
    c.lm_first = true;  // the run's first step is the LM step the lanes left it at
    resume_ = nullptr;
  }

  /// J_ holds the Jacobian at p, the run's point (formed again where the Newton step formed
  /// it in kkt_lu_'s storage, which its factorisation overwrote): the same
  /// bits, for the steps that need J itself, which are rare.
  template <class Prob>
  [[gnu::noinline]] void jacobian_to_J(const Prob& P, const KktPoint& p) {
    if (jacobian_in_J_) return;
    kkt_jacobian(P, p, J_);
    jacobian_in_J_ = true;
  }


  /// Multipliers of eq:guess from the stationarity conditions:
  /// lambda1 = alpha / (r_S . phi1_x), lambda2 = -alpha / (r_S . phi2_x).
  template <class Prob>
  void init_lambda(const Prob& P, KktPoint& p) { formulas::kkt_init_lambda<ScalarNum>(P.L, P.c1, P.c2, p); }

  void fill(SolveResult& res, double k, bool done) {
    const KktPoint& p = *pt_;
    res.alpha = k * p.alpha;
    res.x_1 = (k * P_.L) * (p.z.template head<3>() + P_.c1);
    res.lambda1 = k * p.z[4];
    res.lambda2 = k * p.z[5];
    res.residual_norm = kkt_relative_residual(p);
    if (!done) return;
    SolveResult::Internal& in = res.internal;
    if (o_.derivatives) {
      kkt_jacobian(P_, p, J_);
      in.lu.compute(J_);
      in.factorised = true;
    }
    in.k = k;
    in.length = P_.L;
    in.row_scale << P_.inv_sigma1, P_.inv_sigma2, P_.L, P_.L, P_.L, 1.0;
    in.R = P_.R;
    in.r = r_;
    in.y1 = p.y1;
    in.y2 = p.y2;
    in.e1 = p.e1;
    in.e2 = p.e2;
  }

  template <class, class>
  friend class PairSolver;
  const S1& s1_;
  const S2& s2_;
  const SolverOptions& o_;
  TraceSink* trace_;
  bool rescaled_ = false;  // this solver solves the rescaled problem of another (solve_rescaled)
  bool swapped_ = false;  // this solver is the swapped-order fallback of another (which it must not call back)
  int run_ = 0;
  bool in_continuation_ = false;  // cold() runs the first stage of continuation()
  bool stall_exit_ = false;       // this run ends when LM stalls (SolverOptions::lm_stall_limit)
  bool stalled_ = false;          // ... and it did
  bool start_evaluated_ = false;  // pt_ holds the next run's start, evaluated (support_guess)
  const ColdResume* resume_ = nullptr;  // the first run resumes where the batch lanes left it (solve_cold_resumed)
  Vec6 spare_[2];                 // support_guess's other starts, best first ...
  int spares_ = 0;                // ... and how many
  double tau_ = 0.3;
  double floor_res_ = std::numeric_limits<double>::infinity();  // best candidate at the rounding floor (note_floor)
  Vec6 floor_z_ = Vec6::Zero();
  double sharp_floor_res_ = std::numeric_limits<double>::infinity();  // the second tier (kSharpFloorCeiling)
  Vec6 sharp_floor_z_ = Vec6::Zero();
  bool handover_ = false;  // the Newton run started from a barrier point (SolverOptions::barrier_max_newton)
  static constexpr int kPredictorSteps = 2;  // Newton steps allowed from the warm predictor's point
  /// The predictor is kept for the next query only if its point fell within
  /// this fraction of the last answer's distance to the new answer (and,
  /// if tried, Newton finished from it). Measured on 2,000-query motions of
  /// three pairs, warm steps in all: at 1 (merely nearer) a jittered steady
  /// motion alternated between a missed prediction and none; 0.25 is within
  /// 1% of no predictor on random walks and keeps its gain on steady ones;
  /// 0.1 gives up half the gain on jittered motion at steps of 0.001. After
  /// a warm start that fell back the history restarts, and a stale flag
  /// costs at most the next query's prediction.
  static constexpr double kPredictorGain = 0.25;
  static constexpr double kPredictorMaxStep = 0.05;  // last two answers this close: steady motion, extrapolate
  int iter_cap_ = 0;                         // > 0: the current run stops after this many steps
  double seed_l_ = -1.0;  // ellipsoid_guess's warm start in (0, 1), else none (ellipsoid_contact's l0)
  int barrier_steps_ = 0;  // Newton steps of the last barrier stage (trace only)
  double bw1_ = 1.0, bw2_ = 1.0;  // weights of the two log terms of barrier()
  const char* run_kind_ = "cold";
  KktProblem<S1, S2> P_{};
  Vec3 rhat_ = Vec3::Zero();
  Vec3 r_ = Vec3::Zero();
  KktPoint buf_[2]{};
  KktPoint* pt_ = &buf_[0];     // current iterate
  KktPoint* trial_ = &buf_[1];  // line-search trial, swapped in when accepted
  Mat6r J_;  // row-major: the LU copies it without a transpose. The Newton step forms J in kkt_lu_ instead ...
  bool jacobian_in_J_ = false;  // ... and this says whether J_ holds the Jacobian at pt_ (jacobian_to_J)
  KktLu6 kkt_lu_;  // the Newton step's LU, which skips J_'s zero block
  static constexpr double kFastPivotFactor = 1e5;  // kkt_lu_'s step is taken above this times min_pivot_ratio
  static constexpr double kChordResidual = 1e-7;  // chord steps below this relative residual (newton_run)
  Lu6 lu_;  // the safeguarded LU of ill-conditioned steps
};

template <class S1, class S2>
inline SolveResult solve_pair(const S1& s1, const S2& s2, const Pose& X, const SolverOptions& o, WarmStart* warm,
                              TraceSink* trace = nullptr) {
  PairSolver<S1, S2> solver(s1, s2, o, trace);
  return solver.solve(X, warm);
}

/// PairSolver::separated_at_start.
template <class S1, class S2>
inline bool pair_separated_at_start(const S1& s1, const S2& s2, const Pose& X, const SolverOptions& o, double& lower) {
  return PairSolver<S1, S2>(s1, s2, o, nullptr).separated_at_start(X, lower);
}

/// solve()'s result for a pose whose converged point z the batch lanes found
/// (PairSolver::finish_at).
template <class S1, class S2>
inline SolveResult solve_pair_finished(const S1& s1, const S2& s2, const Pose& X, const SolverOptions& o, const Vec6& z,
                                       int iterations) {
  PairSolver<S1, S2> solver(s1, s2, o, nullptr);
  return solver.finish_at(X, z, iterations);
}

/// The cold solve of a pose whose first Newton run the batch lanes made up
/// to an LM step (ColdResume), from there: the scalar solver's answer.
template <class S1, class S2>
inline SolveResult solve_pair_resumed(const S1& s1, const S2& s2, const Pose& X, const SolverOptions& o, const ColdResume& r) {
  PairSolver<S1, S2> solver(s1, s2, o, nullptr);
  solver.resume_at(&r);
  return solver.solve(X, nullptr);
}

}  // namespace idcol::detail
