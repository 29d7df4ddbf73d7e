// The SIMD batch path (internal to solve_batch): rows of one pair solved
// several at a time across vector lanes, the instruction set chosen at run
// time. Two ellipsoids: their closed form (batch_simd_kernel.hpp), cold W
// rows at a time, warm a row of W chains at a time. Two superquadrics with
// integer exponents (superellipsoids, superelliptic cylinders), smooth
// truncated cones, smooth polytopes, and a cone, a polytope or a sphere
// beside such a superquadric or beside each other (not a sphere beside an
// ellipsoid or a sphere): warm a row of W chains at a time by
// Newton steps (newton_lanes_kernel.hpp), cold W rows at a time through the
// first cold start, the support guess and one Newton run
// (newton_lanes_cold.hpp), and the rows whose run reaches an LM step W at a
// time again from there, with the LM steps and the other support-guess
// starts in lanes.
// Every row it answers is the scalar solver's
// answer; every row it cannot answer in lanes it hands back to the
// caller's scalar loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "idcol/batch.hpp"
#include "batch_simd_abi.hpp"
#include "../solver/cold_resume.hpp"
#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol::detail {

/// The instruction set the lanes use on this CPU: "avx512" (8 lanes),
/// "avx2" (4), "sse2" (2; any x86-64) or "none". The environment variable
/// IDCOL_SIMD (none, sse2, avx2, avx512) caps it, for tests and benchmarks.
const char* batch_simd_isa();
/// Lanes of batch_simd_isa() (1 for "none").
int batch_simd_lanes();

/// Rows answered in lanes by this thread so far (for tests and benchmarks).
std::size_t batch_simd_lane_rows();
/// Rows whose screen for Separated at once the lanes decided, by this
/// thread so far (separated_rows_lanes; for tests).
std::size_t batch_simd_screened_rows();
/// How many cold rows this thread's lanes have handed to the scalar solver
/// at an LM step of their first run, which the scalar solver resumed there
/// (ColdResume) rather than solving them again from the start.
std::size_t batch_simd_resumed_rows();
/// How many cold rows this thread's lanes have left at an LM step and then
/// answered themselves, resumed W at a time (newton_cold_lanes_*_resume).
std::size_t batch_simd_lane_resumed_rows();
/// For tests: whether the cold rows left at an LM step resume in lanes (on,
/// the default) or each on the scalar solver (off), for every thread.
void batch_simd_resume_in_lanes(bool on);
/// Kernel calls made for warm chains by this thread so far (each takes a
/// row of up to W chains; for tests and benchmarks).
std::size_t batch_simd_warm_calls();
/// For benchmarks: while `marks` is set (not null; sized to the poses of
/// the calls that follow), every row of this thread's solve_batch calls that
/// a kernel call declined, and that the scalar loop then solved, is marked 1
/// in it (rows that never reach the lanes, such as a pass's last row, or
/// its last rows fewer than W outside the cold Newton lanes, are not).
/// Other threads' rows are not marked.
void batch_simd_mark_declined(std::vector<std::uint8_t>* marks);

/// Whether solve_rows_simd takes rows of this pair under these options: two
/// ellipsoids (superellipsoids with n = 1, not spheres, semi-axes in
/// [1e-150, 1e150]) or two superquadrics with integer n (superellipsoids
/// and superelliptic cylinders), smooth truncated cones, smooth polytopes
/// or spheres, not a sphere beside an ellipsoid or a sphere (where the lanes can
/// repeat the polytope's face kernel: not SSE2's when it fuses), pair
/// length within the band the scalar solver solves unscaled, and a CPU
/// with lanes. A finite alpha_max: cold and per-row rows only (chains run
/// the loop), those not Separated at once (separated_bound).
bool batch_simd_covers(const Shape& body1, const Shape& body2, const SolverOptions& options);

/// Whether the lanes form the derivatives of each row of this pair they
/// answer (the Newton lanes, W rows at a time: LaneRow::derivatives), so
/// that derivatives cost no scalar rebuild of the row. The closed-form
/// ellipsoid lanes do not: their rows' results are rebuilt on one core
/// (solve_finished), and the derivatives formed from them.
bool batch_simd_finishes(const Shape& body1, const Shape& body2, const SolverOptions& options);

/// Row k's pose: from a Pose list, or from row-major R (9 a row) and p (3).
struct PoseRows {
  const Pose* list = nullptr;
  const double* R = nullptr;
  const double* p = nullptr;
};

/// The caller's scalar loop over rows [lo, hi) (the rows the lanes decline),
/// warm-started from `ws` where not null (the row's chain), as the loop would;
/// with `resume` (one cold row), from where the lanes left its first run
/// (solve_cold_resumed).
using ScalarRowsFn = void (*)(const void* ctx, std::size_t lo, std::size_t hi, WarmStart* ws, const ColdResume* resume);

/// solve() of a cold row whose first Newton run the lanes made up to an LM
/// step, resumed there (PairSolver::resume_at): the same SolveResult.
SolveResult solve_cold_resumed(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options,
                               const ColdResume& resume);

/// solve()'s result for a pose whose answer the lanes found: its converged
/// point z (surrogate units, as a WarmStart keeps it) after `iterations`
/// Newton steps (PairSolver::finish_at). The batch forms a row's
/// derivatives and wrench from it, as the loop forms them from solve()'s.
SolveResult solve_finished(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options,
                           const Vec6& z, int iterations);

/// Whether solve() returns Separated for this pose before any iteration
/// (SolverOptions::alpha_max below its certified bound `lower`, which is
/// then the result's alpha; every other field is SolveResult's default).
bool separated_bound(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options,
                     double& lower);

/// The rows rows[0..m) of one pair screened in lanes, W at a time, as
/// separated_bound screens each: for the row rows[i], verdict[i] = 1 where
/// solve() answers it Separated at once, its bound in lower[i]; 0 where it
/// does not (it iterates); -1 where the scalar screen must decide (a pose
/// near check_pose's limits, or far from the pair's scale; every row where
/// the lanes cannot screen: no lanes, alpha_max infinite, fewer rows than
/// lanes).
void separated_rows_lanes(const Shape& body1, const Shape& body2, const SolverOptions& options, const PoseRows& poses,
                          const std::size_t* rows, std::size_t m, double* lower, std::int8_t* verdict);

/// Whether solve() answers a row Separated at once, its bound then in
/// `lower`: the lanes' verdict on it (separated_rows_lanes: verdict and
/// lanes_lower) where they gave one, else separated_bound at pose().
template <class PoseFn>
bool separated_at_once(std::int8_t verdict, double lanes_lower, const Shape& body1, const Shape& body2, PoseFn&& pose,
                       const SolverOptions& options, double& lower) {
  if (verdict < 0) return separated_bound(body1, body2, pose(), options, lower);
  lower = lanes_lower;
  return verdict == 1;
}

/// No row (SeparatedRowFn's `like`).
constexpr std::size_t kNoRow = static_cast<std::size_t>(-1);

/// Row k, known without a solve: Separated at once with the bound `lower`
/// (separated_bound). `like`: a row of the same call written so before,
/// whose outputs but alpha are row k's (kNoRow: none yet). The batch
/// writes every output of the row, and leaves its warm state as solve()
/// would.
using SeparatedRowFn = void (*)(const void* ctx, std::size_t k, double lower, std::size_t like);

/// A row the lanes answered, as its lane holds it: the converged z (6
/// values), alpha*, x_1 (3) and body 1's gradient at its witness point g1
/// (3), entry j of each at [j * stride], and the iterations. With
/// `derivatives` (the Newton lanes, when derivatives are asked for): the
/// row's derivatives and wrench, formed in lanes as the library's
/// functions form them from solve()'s result, in NewtonFinishIO's rows
/// (batch_simd_abi.hpp), entry e at [e * stride].
struct LaneRow {
  const double* z;
  const double* alpha;
  const double* x;
  const double* g1;
  int stride;
  int iterations;
  const double* derivatives;
};

/// Called for each row the lanes answer when the batch asks for more than
/// alpha, x_1, status, iterations and the kinematics (derivatives, the
/// wrench).
using FinishRowFn = void (*)(const void* ctx, std::size_t k, const LaneRow& row);

/// Rows [lo, hi) of one covered pair: of each row the lanes answer, alpha,
/// x_1, status and iterations in `out`, and the contact kinematics where
/// their spans are not empty (as contact_kinematics()); `scalar` for the
/// others, which fills them.
/// chain = 0: cold, W rows at a time, or, when out.warm is not empty, each
/// row from its own WarmStart (warm[k]), which it leaves as solve() does.
/// chain > 0: warm, chains of `chain`
/// rows (lo a multiple of it), a row of W chains a call (more chains than
/// lanes take turns: rotate_chains), each lane carrying its chain's
/// WarmStart exactly as the loop of solve() does.
/// `finish` (null: none) gets each row the lanes answer, for the outputs
/// beyond these (derivatives, wrench; with `derive` not null, the batch's
/// derivatives asked for, the Newton lanes form the derivatives and the
/// wrench under that contact law, and hand them over in
/// LaneRow::derivatives); `result` each row whose
/// result is known at once (separated_bound). Both with finish_ctx.
/// screened: the caller found no row Separated at once (under a finite
/// alpha_max), so none is tested again.
void solve_rows_simd(const Shape& body1, const Shape& body2, const SolverOptions& options, const HertzModel* derive,
                     const PoseRows& poses, std::size_t lo, std::size_t hi, std::size_t chain, bool screened,
                     const BatchOutput& out, ScalarRowsFn scalar,
                     const void* ctx, FinishRowFn finish, SeparatedRowFn result, const void* finish_ctx);

}  // namespace idcol::detail
