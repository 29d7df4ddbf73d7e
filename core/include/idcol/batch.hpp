// Many contact queries in one call: the batch entry point behind the Python
// module's solve_batch, usable by any C++ caller (the harness, a simulator).
//
// Row k solves body1[k] against body2[k] at the relative pose X_12 of row k,
// exactly as idcol::solve does; the rows are spread over worker threads
// (cold: blocks of 256 rows, each to whichever thread is free next; warm:
// contiguous runs of whole chains). The answer never depends on the number
// of threads or on which thread solved a row:
//
//  - cold (warm_start = false): row k is `solve(body1[k], body2[k], X_k)`;
//  - warm (warm_start = true): the rows form chains of `warm_chain`
//    consecutive rows (chain c = rows [c W, (c+1) W)); inside a chain, row k
//    is warm-started from row k-1 (one WarmStart carried along the chain,
//    as ContactPair does), and the warm start is reset at the start of each
//    chain and wherever the pair changes (body1[k] or body2[k] is another
//    shape object than in row k-1). Threads take whole chains.
//
// So the serial loop that a batch reproduces bit for bit is, for any thread
// count (test_batch.cpp checks this):
//
//   WarmStart ws;
//   for (k = 0; k < N; ++k) {
//     if (k % W == 0 || pair(k) != pair(k-1)) ws.reset();
//     res = solve(*body1[k], *body2[k], X_k, opt, warm_start ? &ws : nullptr);
//   }
//
//  - warm per row (BatchOutput::warm given, one WarmStart per row, in and
//    out): row k is `solve(body1[k], body2[k], X_k, opt, &warm[k])`, each row
//    on its own, as a simulator calls it: row k is one contact pair, and
//    warm[k] is that pair's state from its previous step (the caller keeps
//    it, keyed by the pair; the rows of one call are different pairs).
//    Threads take blocks of rows as cold.
//
// Every optional output of row k (kinematics, wrench, their derivatives) is
// then computed from that row's SolveResult by the functions of
// derivatives.hpp, as the loop would (test_batch_rows.cpp checks this, per
// instruction set, bit for bit). Where the SIMD lanes answer a row (below),
// that SolveResult is rebuilt from the lanes' converged point: the problem
// set up and the point evaluated as solve() does, and the factorisation
// behind the derivatives formed there (the Newton lanes form it, and the
// derivatives from it, W rows at a time, by the library's own formulas),
// so the derivatives and the wrench are the loop's too.
//
// Rows of many pairs (one shape per row), cold or warm per row: the rows of
// each pair (the same two shape objects; Scene gives bodies of one kind one
// shape object) that the lanes take, when they fill the lanes, run as one
// batch of that pair in lanes; the others on the loop. A row's answer does
// not depend on its neighbours in these modes, so the grouping changes no
// bit.
//
// Bad arguments (sizes that disagree, null shapes, bad options) throw
// std::invalid_argument naming the field and the value before any solve
// runs; a bad pose in a row is that row's InvalidInput status, as in solve().
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "idcol/derivatives.hpp"
#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol {

/// A non-owning view of n contiguous T (C++17 has no std::span).
template <class T>
class Span {
 public:
  Span() = default;
  Span(T* data, std::size_t size) : data_(data), size_(size) {}
  template <class U, class A>
  Span(std::vector<U, A>& v) : data_(v.data()), size_(v.size()) {}  // NOLINT: implicit, like std::span
  template <class U, class A>
  Span(const std::vector<U, A>& v) : data_(v.data()), size_(v.size()) {}  // NOLINT
  T* data() const { return data_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T& operator[](std::size_t i) const { return data_[i]; }
  T* begin() const { return data_; }
  T* end() const { return data_ + size_; }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0;
};

struct BatchOptions {
  /// Options of every solve; validated by solve_batch.
  SolverOptions solver;
  /// Warm-start each row from the previous one of its chain (see above).
  bool warm_start = false;
  /// Rows per warm-start chain (>= 1). Fixed, so that chunking over threads
  /// never moves a chain boundary. 1024 keeps the share of cold chain starts
  /// below 0.1% while leaving 10^5 rows ~100 chains to spread over threads.
  std::size_t warm_chain = 1024;
  /// Fill BatchOutput::dalpha_dxi with d alpha*/d xi (alpha_gradient());
  /// sets solver.derivatives for the solves.
  bool derivatives = false;
  /// Worker threads: 0 = every CPU this process may run on (its affinity
  /// mask, so `taskset -c 0` means one), otherwise at most this many. Never
  /// more threads than units of work (cold: blocks of 256 rows; warm:
  /// chains).
  int threads = 1;
  /// When set, every worker checks it before each row and stops once it
  /// reads true (another thread sets it, e.g. on Ctrl-C); the rows not
  /// reached keep whatever their output held. Null: run every row.
  const std::atomic<bool>* cancel = nullptr;
  /// When set, the thread that called solve_batch calls poll(poll_data)
  /// after every 64 of its own rows (on the SIMD path: before each of its
  /// blocks but the first; cold, blocks of 256 rows) and, once
  /// its own rows are done, at least every 20 ms until the other workers
  /// finish. A caller that must answer events while the batch runs (the
  /// Python module checks for Ctrl-C there and sets `cancel`) does it here,
  /// on the calling thread, instead of on a thread of its own: the batch then
  /// runs on exactly `threads` threads. It runs between rows, never during a
  /// solve, and must not throw.
  void (*poll)(void* data) = nullptr;
  void* poll_data = nullptr;
  /// Solve rows several at a time across SIMD lanes (the widest instruction
  /// set of the CPU, chosen at run time): two ellipsoids cold, W rows at a
  /// time, and warm, a row of W chains at a time; two superellipsoids or
  /// superelliptic cylinders with integer n, smooth truncated cones, smooth
  /// polytopes, or a cone, a polytope or a sphere beside such a body (a
  /// sphere not beside an ellipsoid or a sphere), cold, W rows at
  /// a time through the first cold start (the rows whose run needs an LM
  /// step: W at a time again from there), and warm, a row of W chains at a
  /// time (more chains than lanes take turns in them; a polytope only where
  /// the lanes can repeat its face kernel: not in SSE2 lanes beside the
  /// fused AVX2 one); with per-row warm states (BatchOutput::warm), the
  /// rows whose state is valid W at a time from their own states (the
  /// others, a pair's first contact, on the loop). Rows of many pairs: each
  /// pair's rows so, where they fill the lanes. A finite alpha_max: the rows
  /// certified apart at once (Separated) on the loop, the others in lanes;
  /// warm chains on the loop. Every row's answer is still the scalar
  /// solver's, to the bit, the contact kinematics, the derivatives and the
  /// wrench included (the Newton lanes form the derivatives and the wrench
  /// by the formulas the library's functions run; the closed-form
  /// ellipsoid lanes' rows form them on one core from their result rebuilt
  /// at the lanes' answer, and those lanes take no per-row warm rows with
  /// derivatives).
  /// Off: the loop of solve() for every pair.
  bool simd = true;
  /// The contact law of the wrench outputs (BatchOutput::f_n, F1_1, F2_2 and
  /// their derivatives), as contact_wrench() takes it; validated (and used)
  /// only when one of them is asked for.
  HertzModel contact;

  /// Throws std::invalid_argument naming the field and the value.
  void validate() const;
};

/// Caller-owned output storage for N rows, each array row-major.
struct BatchOutput {
  Span<double> alpha;           // N: alpha*
  Span<double> x_1;             // 3N: x* of row k at [3k, 3k+3), body-1 frame
  Span<std::int32_t> status;    // N: static_cast<int32_t>(SolveStatus)
  Span<std::int32_t> iterations;  // N: Newton iterations over every run
  /// 6N when BatchOptions::derivatives, else empty: d alpha*/d xi of row k at
  /// [6k, 6k+6), xi the body twist (w, v) of X_12 (derivatives.hpp). Rows
  /// whose status is not Converged hold zeros, as alpha_gradient() returns.
  Span<double> dalpha_dxi;

  // Optional contact kinematics of each row (contact_kinematics(), body-1
  // frame), each filled when its span is non-empty. Rows whose result has no
  // valid kinematics (status not Converged) hold NaN.
  Span<double> gap;       // N: gap = (1 - 1/alpha*)|r|, > 0 separated
  Span<double> normal_1;  // 3N: body 1's outward unit normal at p1
  Span<double> p1_1;      // 3N: witness point on body 1
  Span<double> p2_1;      // 3N: witness point on body 2 (p2 - p1 = gap r/|r|)
  // Their derivatives w.r.t. xi = (w, v) of X_12 (contact_kinematics_
  // derivatives()), each filled when non-empty; need
  // BatchOptions::derivatives. Row-major blocks: 6 per row for the gap, 18
  // (3 x 6) for the vectors. Rows not Converged hold zeros.
  Span<double> dgap_dxi;     // 6N
  Span<double> dnormal_dxi;  // 18N
  Span<double> dp1_dxi;      // 18N
  Span<double> dp2_dxi;      // 18N

  /// In and out: one warm-start state per row (N), the caller's. Row k
  /// starts from warm[k] when it is valid and leaves its state there, exactly
  /// as solve(..., &warm[k]) does; the rows are independent (no chains), so
  /// the rows of one call may be N different pairs, each with its own state
  /// from its previous call. Needs BatchOptions::warm_start = false (that is
  /// the chained mode). Empty: no per-row warm start.
  Span<WarmStart> warm;

  // Optional contact wrench of each row (contact_wrench() with
  // BatchOptions::contact), each filled when its span is non-empty: F1_1 on
  // body 1 in body-1 coordinates, F2_2 = -Ad_{X_12}^T F1_1 on body 2 in
  // body-2 coordinates, both (moment, force) about the body's origin. A row
  // whose contact is inactive (gap >= 0) holds zeros; so does a row with
  // status Separated when SolverOptions::alpha_max >= 1 (alpha* > 1 is
  // certified, so the bodies do not touch). Any other row that did not
  // converge holds NaN: its force is unknown.
  Span<double> f_n;   // N: f_n = k delta^p, delta = -gap
  Span<double> F1_1;  // 6N
  Span<double> F2_2;  // 6N
  // Their derivatives w.r.t. xi = (w, v) of X_12
  // (contact_wrench_derivatives()), each filled when non-empty; need
  // BatchOptions::derivatives. Row-major: 6 per row for f_n, 36 (6 x 6) for
  // the wrenches. Rows without an active converged contact hold zeros.
  Span<double> df_n_dxi;  // 6N
  Span<double> dF1_dxi;   // 36N
  Span<double> dF2_dxi;   // 36N
};

/// The number of threads `threads` (0 = all) means for this process.
int resolve_thread_count(int threads);

/// The instruction set of solve_batch's SIMD path on this CPU: "avx512",
/// "avx2", "sse2", or "none" (every row then runs the loop of solve()).
const char* batch_simd_isa();

/// N rows given by spans. body1 and body2 hold either one shape (every row)
/// or N (one per row). R holds 9N doubles, row k's rotation R_12 row-major at
/// [9k, 9k+9) (a C-contiguous NumPy array of shape (N, 3, 3)); p holds 3N,
/// row k's r = p_12 at [3k, 3k+3). N is p.size() / 3.
void solve_batch(Span<const Shape* const> body1, Span<const Shape* const> body2, Span<const double> R,
                 Span<const double> p, const BatchOptions& options, const BatchOutput& out);

/// The same with the poses as Pose objects (N = poses.size()).
void solve_batch(Span<const Shape* const> body1, Span<const Shape* const> body2, Span<const Pose> poses,
                 const BatchOptions& options, const BatchOutput& out);

/// One pair for every row.
inline void solve_batch(const Shape& body1, const Shape& body2, Span<const Pose> poses, const BatchOptions& options,
                        const BatchOutput& out) {
  const Shape* a = &body1;
  const Shape* b = &body2;
  solve_batch(Span<const Shape* const>(&a, 1), Span<const Shape* const>(&b, 1), poses, options, out);
}

}  // namespace idcol
