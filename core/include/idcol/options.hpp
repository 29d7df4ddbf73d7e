// Every tunable of the solver, in one place, each with its reason.
//
// A new option is a member here, with its reason and default, and one line
// in idcol/options_fields.hpp (its name, type and accepted values) at the
// same place of the order: validate(), the harness's scenes and results
// files and the Python module all read that list, and options.cpp does not
// compile while the two disagree.
#pragma once

#include <limits>

namespace idcol {

struct SolverOptions {
  /// Stop when every KKT condition holds to this relative error
  /// (kkt_relative_residual in kkt.hpp): the distance of each witness point
  /// to its surface relative to its distance from the frame origin, the
  /// misalignment of the two normals, and the stationarity in alpha. 1e-10
  /// leaves room above rounding (1e-14 to 1e-12 even for 1000:1 bodies) while
  /// giving alpha* to about 1e-10 relative.
  double tolerance = 1e-10;
  /// Newton iterations allowed in one run (one start point or one
  /// continuation stage). Converging runs take 4-15; a run still going after
  /// 25 is almost always in a bad basin, and a restart is cheaper.
  int max_iterations = 25;
  /// A run that reaches max_iterations with the relative residual already
  /// below extension_residual may continue, up to this many iterations in
  /// all, as long as each further block of 10 cuts the residual tenfold:
  /// near-parallel flat faces (two 1000:1 plates) make Newton converge
  /// slowly but surely there.
  int max_iterations_extended = 100;
  double extension_residual = 1e-3;
  /// Extra cold starts (perturbed s_0) after the first one fails.
  int max_restarts = 8;
  /// f_S >= 1 of the surrogate problem (Sec. "Surrogate Formulation"):
  /// the relative translation is rescaled to f_S (r1_out + r2_out) r_hat.
  /// 1 makes the outer spheres just touch, which keeps alpha_S near 1.
  double surrogate_factor = 1.0;
  /// Armijo sufficient-decrease constant on m = ||F||^2 / 2.
  double armijo_c = 1e-4;
  /// Backtracking factor and the number of halvings before the
  /// Levenberg-Marquardt fallback takes over.
  double backtrack_factor = 0.5;
  int max_backtracks = 20;
  /// Largest change of s = log(alpha) in one step: a factor e^1 in alpha.
  double max_step_s = 1.0;
  /// Largest change of the witness point in one step, relative to the pair
  /// length scale; stops a near-singular step from throwing x far away.
  double max_step_x = 0.5;
  /// Multipliers stay positive: a step may cut lambda_i by at most this
  /// fraction (interior-point style), so spurious roots with lambda < 0 are
  /// not approached from a positive start. Measured on the paper's sweep,
  /// 0.3 needs 10-35% fewer cold iterations than 0.95 (SE-SE: 10.3 vs 15.8).
  double lambda_fraction_to_boundary = 0.3;
  /// The same for restarts and continuation stages: after a failed first
  /// run, the cautious 0.95 rescues more of the hard cases (1000:1 bodies).
  double lambda_fraction_to_boundary_restart = 0.95;
  /// The Newton step is called ill-conditioned, and the damped least-squares
  /// (LM) step is used instead, when min|U_ii| / max|U_ii| of the LU factor
  /// drops below this.
  double min_pivot_ratio = 1e-13;
  /// LM damping mu starts at this fraction of max diag(J^T J) and grows
  /// tenfold per rejected trial, for at most lm_max_trials trials.
  double lm_initial_damping = 1e-6;
  int lm_max_trials = 8;
  /// The first cold run of two homogeneous bodies (sphere, superellipsoid,
  /// superelliptic cylinder) ends after this many consecutive accepted steps
  /// (LM steps, or Newton steps the line search cut short; at such a point
  /// the two alternate) that each cut ||F|| by less than the fraction
  /// lm_min_progress: it has reached a stationary point of ||F||^2 that is
  /// not a root (n = 8 bodies face to face), and the rounding continuation
  /// that follows solves those in ~25 iterations, where crawling on to
  /// max_iterations and the restarts took ~90, up to 236 (SE-SE on the
  /// paper's sweep). Every other run keeps
  /// its LM steps: for sharp polytope pairs they are what carries the slow
  /// runs to a root (the stress suite's box cases lost up to 30% of their
  /// solves under the rule). 0 disables the rule.
  int lm_stall_limit = 2;
  double lm_min_progress = 1e-3;
  /// The trust region of s is [log alpha_min, log alpha_max] from the
  /// certified radii, widened by this margin in log units so an answer on the
  /// bound itself (two spheres) stays reachable.
  double bound_margin = 1e-3;
  /// Continuation in beta or n when every cold start at the target shapes
  /// fails (Sec. "Continuation strategy"); sharpness grows geometrically by
  /// at most continuation_ratio per stage from each shape's smoothest stage.
  bool continuation = true;
  double continuation_ratio = 2.0;
  /// When every cold start fails on a pair of homogeneous bodies (sphere,
  /// superellipsoid, superelliptic cylinder), blend both from spheres into
  /// their true shapes in a few warm-started stages (detail::Rounded).
  bool rounding_continuation = true;
  /// The first cold start of a pair that is not two ellipsoids (or two
  /// spheres): the contact on a separating plane from the support functions
  /// (detail::PairSolver::support_guess; two polytopes, or a polytope and
  /// an ellipsoid: the exact bodies' contact, detail::exact_start, with no
  /// other points). If Newton stalls from it, the two
  /// other points it ranked follow; then, or after any other failure, the
  /// ray guess. Off: the ray guess alone, as before it existed (for
  /// comparisons).
  bool support_guess = true;
  /// When every start and continuation has failed, minimise alpha over the
  /// two scaled bodies by a log-barrier interior-point method on the convex
  /// perspective formulation (detail::PairSolver::barrier): it needs no
  /// basin, so it converges from a constructed feasible point whatever the
  /// sharpness (sharp boxes face to face, beta h/L = 10^4). The barrier
  /// weight t grows by barrier_growth per stage, at most barrier_max_stages
  /// stages of at most barrier_max_newton damped Newton steps each; the
  /// xi-part of a step is at most barrier_max_step_x times max(1, alpha_S)
  /// (units of the pair length): the scaled bodies, and the region the
  /// barrier crosses, grow with alpha_S, which starts at 2 f_S r_out / r_in
  /// (2800 for a 1000:1 box needle). Once the duality gap 2/t is below barrier_handover * alpha_S,
  /// the KKT Newton iteration is tried from the barrier point (with the
  /// barrier's multipliers), for up to barrier_max_newton iterations: near
  /// the root of a small beta = 10^4 body beside a large one Newton is
  /// linear for a while before it is quadratic. If it fails the barrier goes
  /// on to the tolerance. If the barrier fails at the pair's own sharpness,
  /// it solves the first stage of the continuation in beta or n instead. If
  /// that fails too, and no run stands at the rounding floor, both are tried
  /// once more with the two log terms weighted by the multipliers
  /// (re-estimated after each stage), which centres both bodies at the same
  /// depth: a millimetre beta = 10^4 body beside one 10^5..10^8 times larger
  /// has multipliers 10^5..10^8 apart, and the unweighted barrier holds it
  /// too deep inside its rim to finish.
  bool barrier = true;
  double barrier_growth = 16.0;
  int barrier_max_stages = 16;
  int barrier_max_newton = 60;
  double barrier_max_step_x = 1.0;
  double barrier_handover = 1e-7;
  /// A failed warm start falls back to the cold strategy, so a warm start
  /// never makes a pose fail that a cold start solves.
  bool warm_fallback_to_cold = true;
  /// A warm start extrapolates the last solutions of the pair (kept in
  /// WarmStart) to the new query, a polynomial predictor in the query index:
  /// 0 starts from the last solution itself, 1 extrapolates the last two
  /// linearly, 2 the last three quadratically. For a pose that moves
  /// smoothly at a steady rate (a simulation's fixed time step) the predicted
  /// point is O(dt^(order+1)) from the new root instead of O(dt): on the
  /// paper's sweep (dt = 1e-4) order 2 cuts warm Newton steps from 2.1-3.1
  /// to 1.0-1.5 per query. If Newton does not finish from the predicted
  /// point within two steps, the last solution itself is tried before the
  /// cold strategy, so a jump in the pose costs at most two steps, never a
  /// solve. The predictor is tried only while it works: after a query whose
  /// predicted point missed (Newton did not finish from it, or it fell
  /// farther than a quarter of the last solution's distance to the answer)
  /// the next query starts from the last solution, as on a random walk.
  int warm_predictor_order = 2;
  /// Factorise the KKT Jacobian at the solution and keep it in
  /// SolveResult::internal, where every derivative of derivatives.hpp reads
  /// it. It costs one Jacobian and one 6x6 LU per converged solve (about 15%
  /// of a warm solve of two ellipsoids), so it is off by default: a caller
  /// who wants alpha* alone pays nothing for derivatives. The derivative
  /// functions reject a converged result solved without it.
  bool derivatives = false;
  /// The certified early exit for "is alpha* at most alpha_max?" queries.
  /// Before any Newton step the solve forms a certified lower bound on
  /// alpha* from the support functions of the two bodies along the line of
  /// centres, |r| / (h1(r_hat) + h2(-R^T r_hat)) (each h_i is the body's
  /// support function, or an upper bound on it: the exact polytope or
  /// frustum around a LogSumExp body). If that bound exceeds alpha_max the
  /// solve stops there with SolveStatus::Separated and the bound in alpha:
  /// no x, no multipliers, no derivatives. Otherwise the solve is exactly
  /// the one without the option. +inf (the default) switches it off; a
  /// finite value must be > 0 (NaN is rejected).
  double alpha_max = std::numeric_limits<double>::infinity();

  /// Work. Every count is bounded by validate(): the iteration counts
  /// (max_iterations, max_iterations_extended, barrier_max_newton,
  /// max_restarts, lm_stall_limit) by kMaxIterationCount, the trial counts
  /// (max_backtracks, lm_max_trials, barrier_max_stages) by kMaxTrialCount,
  /// and continuation_ratio from below by kMinContinuationRatio; the
  /// continuation has at most kMaxContinuationStages stages whatever the
  /// ratio and the sharpness. A solve makes a bounded number of Newton runs
  /// (at most 2 warm, 1 + min(max_restarts, 19) cold, 3 support-guess
  /// points, 2 roundings of at most 60 stages, 4 continuations of at most
  /// kMaxContinuationStages + 8 stages, 2 barriers of barrier_max_stages
  /// stages, then all of it once more in the swapped order), each of at most
  /// max(max_iterations_extended, barrier_max_newton) steps, and each step
  /// evaluates the shapes at most max_backtracks + lm_max_trials + 2 times.
  /// At the defaults a solve is a few dozen steps; at the bounds it is
  /// finite, never the 29 million steps that continuation_ratio = 1 + 1e-7
  /// once cost.
  static constexpr int kMaxIterationCount = 10000;
  static constexpr int kMaxTrialCount = 100;
  static constexpr double kMinContinuationRatio = 1.01;
  static constexpr int kMaxContinuationStages = 64;

  /// Throws std::invalid_argument naming the field and value if any option
  /// is out of range (non-finite, tolerance <= 0, f_S < 1, a count above its
  /// bound, ...).
  void validate() const;
};

}  // namespace idcol
