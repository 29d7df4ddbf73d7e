// What the dispatcher (batch_simd.cpp) hands the lane kernels
// (batch_simd_kernel.hpp): plain data only, so that the kernels, compiled
// for other instruction sets, include no header that defines an inline
// function.
#pragma once

#include "../solver/lm_system.hpp"  // the LM step's linear algebra, which the resumed cold lanes call
#include "idcol/detail/formulas/polytope_ellipsoid.hpp"  // templates and plain structs only
#include "idcol/detail/formulas/polytope_simplex.hpp"    // (the same)
#include "idcol/detail/formulas/shape_eval.hpp"          // (the same): ConeConsts

namespace idcol::detail {

/// The constants of one ellipsoid pair under one set of solver options.
struct EllipsoidLaneConsts {
  double M1[3], M2[3];      // the ellipsoid matrices diag(a^2, b^2, c^2) of body 1 and body 2
  double inv1[3], inv2[3];  // (1/a, 1/b, 1/c) of each body
  double L;                 // pair length r1_out + r2_out
  double fSL;               // surrogate_factor * L
  double c1f, c2f;          // surrogate_factor * r_i,out / L: c_i = c_if r_hat
  double lo, hi;            // the trust region of s = log alpha (PairSolver::bounds)
  double inv_sigma1, inv_sigma2;
  double accept;            // a lane is accepted with every relative residual term at most this
  double pose_tol2;         // squared Frobenius bound on R^T R - I accepted without the scalar check
  double rmax_lo, rmax_hi;  // lanes whose largest |r| coordinate lies outside go to the scalar solver
};

/// W poses (W = the kernel's lane count): R_in holds 9 rows of W (entry e of
/// R_12 row-major, lane i at [e W + i]), p_in 3 rows of W, l0_in W warm
/// starts of the closed form (l of the last contact, in (0, 1); anything
/// else: cold). Writes alpha* and x_1 (3 rows of W), the solution z
/// (6 rows of W: xi, s, lambda1, lambda2 in surrogate units, what a
/// WarmStart keeps), body 1's gradient at its witness point g1 (3 rows of
/// W: the solver's last evaluation, which SolveResult::internal.e1.grad
/// keeps and whose direction is the contact normal) and ok[i] = 1 where
/// lane i is the scalar solver's converged answer, else 0 (that pose must
/// be solved by the scalar solver).
typedef void (*EllipsoidLaneFn)(const EllipsoidLaneConsts&, const double* R_in, const double* p_in, const double* l0_in,
                                double* alpha, double* x, double* z, double* g1, int* ok);

void ellipsoid_lanes_sse2(const EllipsoidLaneConsts&, const double*, const double*, const double*, double*, double*, double*,
                          double*, int*);
void ellipsoid_lanes_avx2(const EllipsoidLaneConsts&, const double*, const double*, const double*, double*, double*, double*,
                          double*, int*);
void ellipsoid_lanes_avx512(const EllipsoidLaneConsts&, const double*, const double*, const double*, double*, double*,
                            double*, double*, int*);

/// The families the Newton lanes take, in the order of the kernels'
/// dispatch (eval_fn, newton_lanes_kernel.hpp).
enum class LaneFamily : int { Superellipsoid, Cylinder, Cone, Polytope, Sphere };

/// A smooth polytope in the lanes (newton_lanes_polytope.hpp): its face
/// block, as the scalar kernel reads it, and the kernel's constants.
struct LanePolytope {
  const double* faces;  // SmoothPolytope's face block (4 columns of m4 entries)
  int m4;               // entries per column
  double beta;          // its sharpness, at which the lanes evaluate it (its own)
  double L;             // the rounding length
  double k;             // beta / L, the kernel's k
  bool fused;           // the scalar face kernel fuses multiply-adds (then so do the lanes)
};

/// A shape the Newton lanes evaluate (newton_lanes_kernel.hpp), built from
/// the scalar shape by lane_shape (batch_simd.cpp).
struct LaneShape {
  LaneFamily family;
  double inv[3];    // superellipsoid: 1/a, 1/b, 1/c; sphere: 1/R
  double h, R;      // cylinder; sphere: R
  double n;         // superquadrics: the exponent, its own sharpness
  int n_int;        // n as an integer
  int sqrt_depth;   // k where 2n = 2^k (S^(1/2n) by k square roots), else -1 (std::pow)
  formulas::ConeConsts cone;  // cone: the constants its evaluation reads (SmoothTruncatedCone::consts)
  double cone_beta;           // cone: its sharpness, at which the lanes evaluate it (its own)
  LanePolytope poly;          // polytope
};

/// The constants of one pair under one set of solver options, for the
/// Newton lanes: PairSolver's, and the options its warm path reads.
struct NewtonLaneConsts {
  LaneShape s1, s2;
  int check_hessians;       // not both homogeneous: a root whose Hessians' traces are not finite is no answer (PairSolver::solve)
  double L, fSL, c1f, c2f;  // as EllipsoidLaneConsts
  double lo, hi;            // the trust region of s
  double inv_sigma1, inv_sigma2;
  double tol;               // SolverOptions::tolerance
  double band;              // a lane whose value lies this close (relative) to a threshold that decides its path goes to the scalar solver
  double pose_tol2, rmax_lo, rmax_hi;
  double max_step_s, max_step_x, tau_first, tau_restart, armijo_c, backtrack_factor;
  int max_backtracks, max_iterations, predictor_order, predictor_steps;
  double fast_pivot;        // PairSolver::kFastPivotFactor * min_pivot_ratio
  double chord_res;         // PairSolver::kChordResidual
  double predictor_max_step, predictor_gain2;
};

/// One row of W chains, structure of arrays (entry e of lane i at [e W + i]).
/// In: R (9 rows), p (3), the chains' WarmStarts (z: 6 rows; zp: z_prev[0]
/// then z_prev[1], 12 rows; history, extrapolate, valid). Out, for the lanes
/// with ok[i] = 1 (the scalar solver's converged answer): alpha*, x_1 (3),
/// g1 (3, body 1's gradient at its witness point), iterations, and the
/// WarmStart that PairSolver::solve leaves (z, zp, history, extrapolate).
/// Lanes with ok[i] = 0 leave their WarmStart untouched.
struct NewtonLaneIO {
  const double* R;
  const double* p;
  double* z;
  double* zp;
  int* history;
  int* extrapolate;
  const int* valid;
  double* alpha;
  double* x;
  double* g1;
  int* iters;
  int* ok;
};
typedef void (*NewtonLaneFn)(const NewtonLaneConsts&, const NewtonLaneIO&);
void newton_lanes_sse2(const NewtonLaneConsts&, const NewtonLaneIO&);
void newton_lanes_avx2(const NewtonLaneConsts&, const NewtonLaneIO&);
void newton_lanes_avx512(const NewtonLaneConsts&, const NewtonLaneIO&);

/// The derivatives of W converged rows, formed in lanes as the library's
/// functions form them from solve()'s result (PairSolver::finish_at's
/// point and factorisation, then formulas/derivatives.hpp). Structure of
/// arrays, entry e of lane i at [e W + i]. In: R (9 rows), p (3), z (6),
/// the contact law (stiffness, exponent). Out, kDerivRows rows: d alpha/d
/// xi (6), the kinematics' derivatives (gap 6, normal 18, p1 18, p2 18,
/// each row-major 3 x 6), f_n, F1 (6), F2 (6), d f_n (6), dF1 and dF2 (36
/// each, row-major), and whether the contact is active and representable
/// (1 or 0).
struct NewtonFinishIO {
  const double* R;
  const double* p;
  const double* z;
  double stiffness, exponent;
  double* out;
};
enum : int {
  kDerivAlpha = 0,
  kDerivGap = 6,
  kDerivNormal = 12,
  kDerivP1 = 30,
  kDerivP2 = 48,
  kDerivFn = 66,
  kDerivF1 = 67,
  kDerivF2 = 73,
  kDerivDFn = 79,
  kDerivDF1 = 85,
  kDerivDF2 = 121,
  kDerivActive = 157,
  kDerivRepresentable = 158,
  kDerivRows = 159
};
typedef void (*NewtonFinishFn)(const NewtonLaneConsts&, const NewtonFinishIO&);
void newton_finish_lanes_sse2(const NewtonLaneConsts&, const NewtonFinishIO&);
void newton_finish_lanes_avx2(const NewtonLaneConsts&, const NewtonFinishIO&);
void newton_finish_lanes_avx512(const NewtonLaneConsts&, const NewtonFinishIO&);

/// What the screen of the rows Separated at once reads of one body: its
/// support function's constants (formulas/support_bound.hpp).
struct SupportShape {
  LaneFamily family;
  double ax[3];                 // superellipsoid: the semi-axes
  double h, R, n;               // cylinder: half-height, radius; sphere: R; superquadrics: the exponent
  double Rb, Rt, a, b;          // cone: the exact frustum's radii and ends
  const double* verts;          // polytope: the exact polytope's vertices, x, y, z of each in turn
  int nv;                       // and how many
};

/// The constants of one pair for that screen: the two bodies, the pose
/// checks' margins (as NewtonLaneConsts) and SolverOptions::alpha_max.
struct SeparatedLaneConsts {
  SupportShape s1, s2;
  double pose_tol2, rmax_lo, rmax_hi;
  double alpha_max;
};

/// W poses (R_in 9 rows of W, p_in 3 rows, entry e of lane i at [e W + i])
/// screened as PairSolver::separated_at_start screens a pose: lower[i], the
/// certified bound on alpha* (formulas::alpha_lower_bound), and sep[i] = 1
/// where solve() answers lane i Separated at once with that bound as alpha,
/// 0 where it does not (it iterates), -1 where the lanes cannot tell (a
/// pose near check_pose's limits or not valid, or far from the pair's
/// scale): the scalar screen decides those.
typedef void (*SeparatedLaneFn)(const SeparatedLaneConsts&, const double* R_in, const double* p_in, double* lower, int* sep);
void separated_lanes_sse2(const SeparatedLaneConsts&, const double*, const double*, double*, int*);
void separated_lanes_avx2(const SeparatedLaneConsts&, const double*, const double*, double*, int*);
void separated_lanes_avx512(const SeparatedLaneConsts&, const double*, const double*, double*, int*);

/// What the cold Newton lanes (newton_lanes_cold.hpp) read of one body
/// beyond its LaneShape: its semi-axes (superellipsoid: a, b, c), its top
/// radius (smooth truncated cone: Rt, which support_point reads) and its
/// radii (Shape::radii(), which radial_extent clamps to and starts from).
struct NewtonColdShape {
  double ax[3];
  double Rt;
  double inner, outer;
  // Smooth polytope: the exact polytope's vertices (SmoothPolytope::vertices(),
  // x, y, z of each in turn; nv of them) and support_point's tolerance, 1e-9
  // of its outer radius.
  const double* verts = nullptr;
  int nv = 0;
  double vtol = 0.0;
};

/// The constants of one pair for the cold Newton lanes: the warm lanes'
/// (NewtonLaneConsts), each body's NewtonColdShape, e^lo and e^hi (the
/// support guess clamps alpha to them), and PairSolver's stall exit
/// (SolverOptions::lm_stall_limit; stall_ratio2 = (1 - lm_min_progress)^2).
struct NewtonColdConsts {
  NewtonLaneConsts base;
  NewtonColdShape b1, b2;
  double exp_lo, exp_hi;
  double stall_ratio2;
  int stall_limit;
  double min_pivot;  // SolverOptions::min_pivot_ratio (Lu6's test, where KktLu6's fast one fails)
  int max_iterations_extended;  // SolverOptions::max_iterations_extended and extension_residual: a run
  double extension_residual;    // close to a root at max_iterations goes on (PairSolver::newton_run)
  int lm_max_trials;            // SolverOptions::lm_max_trials and lm_initial_damping: the LM steps of
  double lm_damping;            // the resumed rows (newton_cold_lanes_*_resume)
  int exact_start;              // support_guess's exact start, in the lanes: 1 the two polytopes' dual simplex
                                // (simplex below), 2 a polytope and an ellipsoid's active-set method (ball
                                // below), 0 none
  /// exact_start == 1: what detail::exact_start hands exact_polytope_contact.
  struct Simplex {
    formulas::SimplexConsts k;
    const double* F[2];    // each body's face block [a_x | a_y | a_z | b]
    int n[2], m[2];        // its rows a column, and its faces
    double soft1, soft2;   // the vertex's move (0: none)
    double step;           // kExactStartPolytopeStep
    double unique;         // kExactStartUnique: a start only where the multipliers' ratio is above it
  } simplex;
  /// exact_start == 2: what detail::exact_start hands
  /// exact_polytope_ellipsoid_contact.
  struct Ball {
    formulas::BallConsts k;  // the polytope's outer radius, the tolerance, the step limit and its smoothing length
    const double* F;         // the polytope's face block
    int n, m;                // its rows a column, and its faces
    double ax[3];            // the ellipsoid's semi-axes
    int polytope_first;      // 1: body 1 is the polytope, 0: body 2
  } ball;
};

/// W cold rows, structure of arrays (entry e of lane i at [e W + i]). In:
/// R (9 rows), p (3). Out, for the lanes with ok[i] = 1 (the scalar
/// solver's converged answer from its first cold start): alpha*, x_1 (3),
/// g1 (3, body 1's gradient at its witness point) and iterations. For the
/// lanes with ok[i] = 0 that left the first run for an LM step (a failed
/// line search or no Newton direction: lm[i] = 1, else 0), where they left it (detail::ColdResume): the point lm_z (6
/// rows), the run's iteration lm_it, the Newton steps before it lm_iters,
/// the stall count lm_stalls and the chord flags lm_chord (bit 0 chord_ok,
/// bit 1 chord_tried). And for every lane, z (6 rows): its last point (the
/// converged z where ok[i] = 1, what a WarmStart keeps).
struct NewtonColdIO {
  const double* R;
  const double* p;
  double* alpha;
  double* x;
  double* g1;
  int* iters;
  int* ok;
  int* lm;
  double* lm_z;
  int* lm_it;
  int* lm_iters;
  int* lm_stalls;
  int* lm_chord;
  double* z;
};
typedef void (*NewtonColdFn)(const NewtonColdConsts&, const NewtonColdIO&);
void newton_cold_lanes_sse2(const NewtonColdConsts&, const NewtonColdIO&);
void newton_cold_lanes_avx2(const NewtonColdConsts&, const NewtonColdIO&);
void newton_cold_lanes_avx512(const NewtonColdConsts&, const NewtonColdIO&);
/// W rows that the cold lanes left at an LM step (lm[i] = 1), resumed
/// there: in, R and p and where each left (lm_z, lm_it, lm_iters,
/// lm_stalls, lm_chord); out, as the cold lanes, ok[i] = 1 for an answer,
/// and for every other lane, in lm_*, the last LM step of its first run,
/// where the scalar solver resumes it (detail::ColdResume).
void newton_cold_lanes_sse2_resume(const NewtonColdConsts&, const NewtonColdIO&);
void newton_cold_lanes_avx2_resume(const NewtonColdConsts&, const NewtonColdIO&);
void newton_cold_lanes_avx512_resume(const NewtonColdConsts&, const NewtonColdIO&);

}  // namespace idcol::detail
