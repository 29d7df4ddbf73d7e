// The outcome of one contact query.
#pragma once

#include "idcol/lu6.hpp"
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol {

/// Why a solve stopped. Only `Converged` (and `Concentric`, whose answer is
/// exact by definition) carry a genuine answer.
enum class SolveStatus {
  /// The KKT conditions of the *target* shapes (never a smoother
  /// continuation stage) hold to SolverOptions::tolerance in relative terms
  /// (kkt_relative_residual), with lambda1 > 0, lambda2 > 0 and alpha inside
  /// the certified bounds; or, when no strategy reaches the tolerance, to
  /// the rounding floor of doubles at the answer (kkt_rounding_floor, at most
  /// 1e-8; up to 1e-6 where both witness points lie on their surfaces to the
  /// tolerance), as residual_norm then shows.
  Converged,
  /// r = 0 exactly: both bodies contain the common origin at every scale, so
  /// alpha* = 0 and x* = 0. The normal and multipliers are undefined (set to
  /// 0); no derivatives are available.
  Concentric,
  /// Every run used SolverOptions::max_iterations Newton steps without
  /// meeting the tolerance.
  IterationLimit,
  /// Armijo backtracking failed and no LM trial decreased ||F||, or
  /// SolverOptions::lm_stall_limit consecutive LM steps each cut ||F|| by
  /// less than lm_min_progress (a stationary point of ||F|| that is not a
  /// root).
  LineSearchFailed,
  /// The residual or Jacobian became non-finite, or a root was found but
  /// the answer scaled back from surrogate coordinates is not representable
  /// (alpha, x or a multiplier overflows, or a multiplier underflows to 0:
  /// body sizes and |r| spanning the whole double range).
  NumericalFailure,
  /// A KKT root was found but it has lambda_i <= 0 or alpha outside the
  /// certified bounds: a spurious root, rejected, and every retry ended the
  /// same way.
  SpuriousRoot,
  /// The pose has a NaN/Inf entry, a non-orthonormal rotation or det R = -1.
  InvalidInput,
  /// SolverOptions::alpha_max is finite and a certified lower bound on
  /// alpha* (support functions along the line of centres) exceeds it, so
  /// alpha* > alpha_max: the bodies stay apart even when both are scaled by
  /// alpha_max. No Newton step was taken. SolveResult::alpha holds the
  /// bound (alpha_max < alpha <= alpha*); x and the multipliers are 0 and
  /// the derivative functions throw on such a result.
  Separated,
};

/// Every SolveStatus in declaration order: the one list that per-status
/// counts and tables iterate. A value added to the enum is added here too
/// (test_solver checks this list against to_string, which names every value).
inline constexpr SolveStatus kSolveStatuses[] = {
    SolveStatus::Converged,        SolveStatus::Concentric,   SolveStatus::IterationLimit, SolveStatus::LineSearchFailed,
    SolveStatus::NumericalFailure, SolveStatus::SpuriousRoot, SolveStatus::InvalidInput,   SolveStatus::Separated,
};
inline constexpr int kNumSolveStatuses = static_cast<int>(sizeof kSolveStatuses / sizeof kSolveStatuses[0]);

/// The status's snake_case name, as results files write it ("converged",
/// "iteration_limit", ...); "unknown" for a value outside the enum.
const char* to_string(SolveStatus s);

/// One Newton iteration, reported to a TraceSink (used by `replay`).
struct TraceRecord {
  int run = 0;            // which Newton run: 0 = first start, then restarts and continuation stages
  const char* run_kind = "";  // "warm", "cold", "restart", "continuation"
  double sharp1 = 0.0, sharp2 = 0.0;  // sharpness of the run (continuation stages differ)
  int iteration = 0;      // within the run
  Vec6 z = Vec6::Zero();  // surrogate unknowns (xi, s, lambda1, lambda2) before the step
  double residual = 0.0;  // ||F||_inf before the step
  const char* step = "";  // "newton", "chord" (the last Newton step's LU reused near the root), "lm", "failed", or the run's end: "converged", "spurious", ...
  double step_length = 0.0;
};

/// Receives every iteration of a solve. Only for diagnosis: a null sink
/// (the default) costs one branch per iteration.
class TraceSink {
 public:
  virtual ~TraceSink() = default;
  virtual void record(const TraceRecord& r) = 0;
};

/// Warm-start state of one contact pair, kept between queries by the caller
/// (see ContactPair). It lives in the solver's surrogate coordinates, which
/// do not depend on |r|.
struct WarmStart {
  bool valid = false;
  Vec6 z = Vec6::Zero();   // (xi, s_S, lambda1_S, lambda2_S); xi is measured from c1 (kkt.hpp)
  double length = 0.0;     // pair length scale it was made with
  /// The solutions of the queries before the last, newest first, for the
  /// predictor (SolverOptions::warm_predictor_order): `history` of them are
  /// valid (0..2), each from an unbroken run of successful warm-started
  /// queries with the same length scale.
  Vec6 z_prev[2] = {Vec6::Zero(), Vec6::Zero()};
  int history = 0;
  /// Whether, on the last query with a history, the predictor's point fell
  /// within a quarter of the last solution's distance to the answer (in xi
  /// and s), and Newton finished from it if it was tried: the next query
  /// extrapolates only if so.
  bool extrapolate = true;
  void reset() {
    valid = false;
    history = 0;
    extrapolate = true;
  }
};

/// Result of a contact query between body 1 and body 2 at relative pose
/// X_12 = (R, r).
///
/// Invariants when status == Converged (all vectors in body-1 coordinates):
///  - alpha > 0; alpha < 1 means penetration, alpha > 1 separation;
///  - p1 = x / alpha lies on body 1's surface: phi1(x / alpha) = 0;
///  - p2 = R^T (x - r) / alpha lies on body 2's surface (in body-2 coords);
///  - lambda1 grad_x phi1 + lambda2 grad_x phi2 = 0 with lambda1, lambda2 > 0,
///    so the outward normals of the two scaled bodies at x are opposite;
///  - gap d_D = (1 - 1/alpha) |r| (eq:gap) is > 0 iff alpha > 1.
struct SolveResult {
  SolveStatus status = SolveStatus::InvalidInput;
  double alpha = 0.0;       // alpha*, the minimal common scaling (Separated: a certified lower bound on it)
  Vec3 x_1 = Vec3::Zero();  // x*, the contact point of the scaled bodies, body-1 frame
  double lambda1 = 0.0;     // multipliers of the original (unscaled) problem
  double lambda2 = 0.0;
  int iterations = 0;       // Newton steps over every run: restarts and continuation stages included
  int restarts = 0;         // cold starts beyond the first
  bool used_continuation = false;
  bool used_barrier = false;         // the interior-point fallback ran (SolverOptions::barrier)
  bool warm_started = false;        // a warm start was attempted
  bool warm_start_fell_back = false;  // ... it failed and the cold strategy ran
  double residual_norm = 0.0;       // kkt_relative_residual at the returned point

  bool converged() const { return status == SolveStatus::Converged; }

  /// What the derivative code needs; filled when status == Converged. The
  /// factorisation `lu` only when SolverOptions::derivatives was set
  /// (`factorised`); the rest always.
  /// The Newton system is solved in surrogate coordinates
  ///   z_S = (xi, s_S, lambda1_S, lambda2_S), x = k L (xi + c1), alpha = k e^{s_S},
  ///   lambda_i = k lambda_i_S,
  /// with residual rows scaled by row_scale (see kkt.hpp). `lu` is the LU
  /// factorisation of that Jacobian at the returned solution;
  /// lu.pivot_ratio() = min|U_ii| / max|U_ii| flags a nearly singular J_c.
  struct Internal {
    bool factorised = false;  // lu holds the factorisation at the solution
    Lu6 lu;
    double k = 0.0;       // surrogate scale |r| / (f_S L)
    double length = 0.0;  // L = r1_out + r2_out
    Vec6 row_scale = Vec6::Ones();
    Mat3 R = Mat3::Identity();
    Vec3 r = Vec3::Zero();
    Vec3 y1 = Vec3::Zero();  // x/alpha in body 1
    Vec3 y2 = Vec3::Zero();  // R^T (x - r)/alpha in body 2
    ShapeEval e1, e2;        // phi, grad, hess of each body at y1, y2
  } internal;
};

}  // namespace idcol
