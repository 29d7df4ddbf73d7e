// The SIMD batch path's dispatcher (batch_simd.hpp): picks the widest lane
// kernel this CPU runs, gathers W poses at a time into lane order, and
// hands the lanes it declines back to the scalar loop.
//
// The kernels are plain C++ with GCC/Clang vector extensions, one
// translation unit per instruction set (batch_simd_sse2.cpp, _avx2,
// _avx512) compiled with that set's flags. That choice, against Google
// Highway or xsimd: the kernel is about 200 lines of straight arithmetic
// with a handful of selects, which vector extensions express directly; it
// adds no dependency to the library (find_package(idcol) users included);
// and it keeps the arithmetic under our control operation by operation,
// which exact agreement with the scalar solver needs (no library-chosen
// reductions, fused multiply-adds or approximate reciprocals).
#include "batch_simd.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <memory>
#include <variant>

#include "batch_simd_abi.hpp"
#include "../derivatives/contact_kinematics_impl.hpp"
#include "../solver/exact_polytope_start.hpp"
#include "idcol/result.hpp"

namespace idcol::detail {

namespace {

struct Kernel {
  const char* isa;
  int lanes;
  EllipsoidLaneFn fn;
  NewtonLaneFn newton;
  NewtonColdFn newton_cold;
  NewtonColdFn newton_resume;  // the cold rows left at an LM step, resumed together
  NewtonFinishFn newton_finish;  // what the derivatives read of a converged row (PairSolver::finish_at)
  SeparatedLaneFn separated;     // the screen of the rows Separated at once
  bool fma = false;  // its Newton lanes fuse multiply-adds where the polytope's face kernel does (AVX2, AVX-512)
};

Kernel pick_kernel() {
  int cap = 3;  // 0 none, 1 sse2, 2 avx2, 3 avx512
  if (const char* env = std::getenv("IDCOL_SIMD")) {
    if (!std::strcmp(env, "none")) cap = 0;
    else if (!std::strcmp(env, "sse2")) cap = 1;
    else if (!std::strcmp(env, "avx2")) cap = 2;
  }
#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  // AVX-512 groups of 4 chains or fewer run the AVX2 kernel (narrow_for).
  if (cap >= 3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    return {"avx512", 8, &ellipsoid_lanes_avx512, &newton_lanes_avx512, &newton_cold_lanes_avx512, &newton_cold_lanes_avx512_resume, &newton_finish_lanes_avx512, &separated_lanes_avx512, true};
  // The AVX2 kernel is compiled with -mfma (the polytope lanes fuse where
  // the AVX2 face kernel does): a CPU must have both.
  if (cap >= 2 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return {"avx2", 4, &ellipsoid_lanes_avx2, &newton_lanes_avx2, &newton_cold_lanes_avx2, &newton_cold_lanes_avx2_resume, &newton_finish_lanes_avx2, &separated_lanes_avx2, true};
  if (cap >= 1) return {"sse2", 2, &ellipsoid_lanes_sse2, &newton_lanes_sse2, &newton_cold_lanes_sse2, &newton_cold_lanes_sse2_resume, &newton_finish_lanes_sse2, &separated_lanes_sse2};
#endif
  return {"none", 1, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
}

/// Chosen once per call of solve_batch (the environment may change
/// between calls in a test), which costs a few CPUID reads per call.
const Kernel& kernel() {
  thread_local Kernel k;
  k = pick_kernel();
  return k;
}

/// An ellipsoid the lanes take: a superellipsoid with n = 1 whose semi-axes
/// square without overflow or underflow (bodies of extreme size are left to
/// the scalar solver, which may rescale them).
const Superellipsoid* ellipsoid(const Shape& s) {
  const Superellipsoid* e = std::get_if<Superellipsoid>(&s);
  if (!e || e->n() != 1.0) return nullptr;
  for (double v : {e->a(), e->b(), e->c()})
    if (!(v >= 1e-150 && v <= 1e150)) return nullptr;
  return e;
}

/// A smooth truncated cone the Newton lanes take (LaneFamily::Cone,
/// newton_lanes_cone.hpp): any cone whose lengths lie in [2^-300, 2^300],
/// with the constants its own evaluation reads (SmoothTruncatedCone::eval_consts)
/// and its sharpness.
bool lane_shape_cone(const SmoothTruncatedCone& c, LaneShape& out) {
  for (double v : {c.Rb(), c.Rt(), c.a(), c.b()})
    if (!(v >= 0x1p-300 && v <= 0x1p300)) return false;
  out.cone = c.eval_consts();
  out.cone_beta = c.beta();
  return true;
}

/// Whether the smooth polytope's face kernel that the scalar solver runs
/// on this CPU fuses multiply-adds (polytope_kernel.hpp).
bool polytope_fused() { return std::strcmp(polytope_kernel_isa(), "avx2") == 0; }

/// A smooth polytope the Newton lanes take (LaneFamily::Polytope,
/// newton_lanes_polytope.hpp): any, evaluated at its own sharpness, where
/// this CPU's lanes can repeat its face kernel (a fused kernel needs lanes
/// with FMA: not the SSE2 ones). The face block is the shape's own (the
/// shape outlives the batch). poly: beta, L, beta / L, 1 if fused.
bool lane_shape_polytope(const SmoothPolytope& p, LaneShape& out) {
  const bool fused = polytope_fused();
  if (fused && !pick_kernel().fma) return false;
  out.poly = {p.face_block(), p.face_block_rows(), p.beta(), p.L(), p.beta() / p.L(), fused};
  return out.poly.m4 > 0;
}

/// A shape the Newton lanes take: a sphere, a superellipsoid or
/// superelliptic cylinder with an integer exponent (Exponent::n_int), or a
/// family that lane_shape_cone or lane_shape_polytope offers; of a size the scalar
/// solver solves unscaled (PairSolver::kMinLength, kMaxLength; the pair's
/// length is checked in newton_pair).
bool lane_shape(const Shape& s, LaneShape& out) {
  out = LaneShape{};
  if (const SmoothTruncatedCone* c = std::get_if<SmoothTruncatedCone>(&s)) {
    out.family = LaneFamily::Cone;
    return lane_shape_cone(*c, out);
  }
  if (const SmoothPolytope* p = std::get_if<SmoothPolytope>(&s)) {
    out.family = LaneFamily::Polytope;
    return lane_shape_polytope(*p, out);
  }
  if (const Sphere* b = std::get_if<Sphere>(&s)) {
    out.family = LaneFamily::Sphere;
    out.R = b->R();
    out.inv[0] = 1.0 / b->R();  // as Sphere's constructor forms it
    return true;
  }
  double n = 0.0;
  if (const Superellipsoid* e = std::get_if<Superellipsoid>(&s)) {
    out.family = LaneFamily::Superellipsoid;
    out.inv[0] = 1.0 / e->a(), out.inv[1] = 1.0 / e->b(), out.inv[2] = 1.0 / e->c();
    n = e->n();
  } else if (const SuperellipticCylinder* c = std::get_if<SuperellipticCylinder>(&s)) {
    out.family = LaneFamily::Cylinder;
    out.h = c->h(), out.R = c->R();
    n = c->n();
  } else {
    return false;
  }
  const Exponent ex(n);
  if (ex.n_int < 1) return false;
  out.n = n;
  out.n_int = ex.n_int;
  out.sqrt_depth = ex.sqrt_depth;
  return true;
}

/// Whether a pair of length L (r1_out + r2_out) lies in the band that the
/// scalar solver solves unscaled (PairSolver::kMinLength, kMaxLength), the
/// only pairs the lanes take.
bool unscaled_length(double L) { return L >= 0x1p-64 && L <= 0x1p32; }

/// What every lane kernel's load_pose accepts without the scalar solver's
/// check, for a pair of length L: |R^T R - I|_F^2 with a margin below
/// kPoseTolerance's square, so that a pose near the limit goes to the
/// scalar check, and a largest |r| coordinate in [rmax_lo, rmax_hi]: poses
/// far from the pair's own scale are left to the scalar solver (which may
/// treat badly scaled problems differently).
struct PoseMargins {
  double pose_tol2, rmax_lo, rmax_hi;
};
PoseMargins pose_margins(double L) {
  return {(0.999 * kPoseTolerance) * (0.999 * kPoseTolerance), 1e-6 * L, 1e6 * L};
}

/// Whether the Newton lanes take this pair (not two ellipsoids, which the
/// closed-form lanes take, nor a sphere beside an ellipsoid or a sphere).
bool newton_pair(const Shape& b1, const Shape& b2) {
  LaneShape a, b;
  // Two ellipsoids (a sphere is one: ellipsoid_axes, the exact starts'
  // test) of any size: the scalar solver starts them from their closed
  // form (PairSolver::has_ellipsoid_form; two spheres from the ray guess),
  // not the Newton lanes' path.
  auto ellipsoid_form = [](const Shape& s) {
    Vec3 ax;
    return std::visit([&](const auto& x) { return ellipsoid_axes(x, x.sharpness(), ax); }, s);
  };
  if (!lane_shape(b1, a) || !lane_shape(b2, b) || (ellipsoid_form(b1) && ellipsoid_form(b2))) return false;
  return unscaled_length(radii(b1).outer + radii(b2).outer);
}

thread_local std::size_t lane_rows = 0;
thread_local std::size_t screened_rows = 0;  // rows the lanes' screen decided (separated_rows_lanes)
thread_local std::size_t resumed_rows = 0;
thread_local std::size_t lane_resumed_rows = 0;
std::atomic<bool> resume_in_lanes{true};
thread_local std::size_t warm_calls = 0;
thread_local std::vector<std::uint8_t>* declined_marks = nullptr;

/// Row k, which a kernel call declined, to the scalar loop (from the
/// chain's WarmStart where warm), marked where batch_simd_mark_declined
/// asks. Out of line: inlined, it slowed the warm dispatch around it (its
/// thread_local access, and the closed-form lanes' warm rows by a dozen
/// instructions each).
[[gnu::noinline, gnu::cold]] void to_loop(ScalarRowsFn scalar, const void* ctx, std::size_t k, WarmStart* ws,
                                          const ColdResume* resume = nullptr) {
  if (declined_marks) (*declined_marks)[k] = 1;
  scalar(ctx, k, k + 1, ws, resume);
}

struct LaneFinish;  // below

/// One call's rows answered in lanes and warm kernel calls, added to the
/// thread's counts when the call returns, not a row at a time: in a shared
/// library (the Python module) each access to a thread_local is a call
/// into the dynamic linker.
struct Tally {
  std::size_t rows = 0, calls = 0;
  FinishRowFn finish = nullptr;  // the batch's outputs beyond the lanes' (solve_rows_simd)
  const void* ctx = nullptr;
  bool kinematics = false;  // some contact kinematics asked for (gap, normal_1, p1_1, p2_1)
  const HertzModel* derive = nullptr;  // derivatives asked for: the Newton lanes form them, the wrench under this law,
  LaneFinish* fin = nullptr;           // into this buffer
  Tally() = default;
  Tally(const Tally&) = delete;
  Tally& operator=(const Tally&) = delete;
  ~Tally() {
    lane_rows += rows;
    warm_calls += calls;
  }
};

/// The narrowest kernel of this CPU with at least `chains` lanes, for a
/// warm call with fewer live chains than K has lanes (a group of fewer
/// chains than lanes, or the last calls of a rotation): idle lanes cost as
/// much as live ones, and the divisions and square roots of a wider vector
/// take longer. With `fma` (a pair with a fused polytope: polytope_fused),
/// no narrower than AVX2, whose lanes fuse as its face kernel does.
Kernel narrow_for(const Kernel& K, std::size_t chains, bool fma = false) {
#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__))
  if (chains <= 2 && K.lanes > 2 && !fma) return {"sse2", 2, &ellipsoid_lanes_sse2, &newton_lanes_sse2, &newton_cold_lanes_sse2, &newton_cold_lanes_sse2_resume, &newton_finish_lanes_sse2, &separated_lanes_sse2};
  if (chains <= 4 && K.lanes > 4) return {"avx2", 4, &ellipsoid_lanes_avx2, &newton_lanes_avx2, &newton_cold_lanes_avx2, &newton_cold_lanes_avx2_resume, &newton_finish_lanes_avx2, &separated_lanes_avx2, true};
#endif
  (void)chains;
  (void)fma;
  return K;
}

/// The most lanes of any kernel (AVX-512).
constexpr int kMaxLanes = 8;

/// N lane-major vectors of up to kMaxLanes doubles, starting on a cache
/// line: a vector load or store of W doubles never splits a line (AVX-512:
/// one line exactly; their 16-byte stack alignment otherwise moved with
/// each run's stack address, and the timings with it).
template <int N>
struct alignas(64) Lanes {
  double v[N * kMaxLanes];
  operator double*() { return v; }
};

/// The derivatives of the rows of one Newton kernel call, when they are
/// asked for, formed in lanes (newton_finish_lanes_*: PairSolver::
/// finish_at's point and factorisation, then the derivatives' formulas),
/// where the loop formed them on one core from each row's result rebuilt at
/// the lane's answer (solve_finished).
struct LaneFinish {
  Lanes<kDerivRows> out;

  /// The lanes of G at the poses (Rb, pb) and converged points zb, the
  /// wrench under the contact law h.
  void run(const Kernel& G, const NewtonLaneConsts& C, const double* Rb, const double* pb, const double* zb,
           const HertzModel& h) {
    G.newton_finish(C, NewtonFinishIO{Rb, pb, zb, h.stiffness, h.exponent, out});
  }
  /// Lane i's rows (LaneRow::derivatives).
  const double* row(int i) const { return out.v + i; }
};

/// Warm chains in a group take at most this many slots (2 W of AVX-512).
constexpr int kMaxSlots = 2 * kMaxLanes;

/// Warm chains [lo, hi), `chain` rows each (lo a multiple of it), through
/// K's lanes: groups of W chains in lockstep while more than 2 W chains are
/// left, then the last group (W + 1 to 2 W chains) in turn. Each chain of a
/// group keeps its lane from call to call, the others wait in line: after
/// each call one lane, in turn, hands its chain to the back of the line and
/// takes the chain at its front, and a chain without rows left hands its
/// lane to the front chain (or, with none waiting, to the chain of the last
/// lane). So the calls stay full while W chains have rows (10^5 rows in
/// chains of 10^4 on 8 lanes: 12,500 full calls, where groups of 8 and 2
/// made 10^4 calls of 8 live lanes and 10^4 of 2), the chains of a group
/// end within a few calls of each other, and a lane's warm state changes
/// chains once a call, not W times; a chain's rows still run in order,
/// each warm-started from the one before, so every answer is the one
/// lockstep gave. A call with fewer live chains than lanes runs the
/// narrowest kernel that holds them (narrow_for; `fma`: not below AVX2); a
/// group of one chain runs the loop.
/// begin(n): a group of n chains starts (slots 0..n-1, each a fresh chain).
/// call(G, slot, row, live): row[i] of the chain in slot[i], i < live, in
/// lanes of G (G.lanes >= live).
/// Long: the lanes' and the line's bookkeeping of a group, one loop.
template <class Begin, class Call>
void rotate_chains(const Kernel& K, bool fma, std::size_t lo, std::size_t hi, std::size_t chain,
                   ScalarRowsFn scalar, const void* ctx, Tally& tally, Begin begin, Call call) {
  const int W = K.lanes;
  const std::size_t streams = (hi - lo + chain - 1) / chain;
  std::size_t next[kMaxSlots], end[kMaxSlots], row[kMaxSlots];
  for (std::size_t s0 = 0; s0 < streams;) {
    const std::size_t left = streams - s0;
    if (left == 1) {  // one chain: the loop costs less than a kernel call for one live lane
      scalar(ctx, lo + s0 * chain, hi, nullptr, nullptr);
      return;
    }
    const int n = static_cast<int>(left > 2 * static_cast<std::size_t>(W) ? W : left);
    begin(n);
    for (int c = 0; c < n; ++c) {
      next[c] = lo + (s0 + c) * chain;
      end[c] = std::min(hi, next[c] + chain);
    }
    s0 += n;
    // lane[i]: the chain in lane i (i < live); line[head, head + waiting):
    // the chains waiting, front first (a ring of kMaxSlots).
    int lane[kMaxLanes], line[kMaxSlots], live = std::min(n, W), head = 0, waiting = n - live, turn = 0;
    for (int i = 0; i < live; ++i) lane[i] = i;
    for (int c = live; c < n; ++c) line[c - live] = c;
    auto front = [&] {
      const int c = line[head];
      head = (head + 1) % kMaxSlots;
      --waiting;
      return c;
    };
    auto back = [&](int c) {
      line[(head + waiting) % kMaxSlots] = c;
      ++waiting;
    };
    while (live > 0) {
      for (int i = 0; i < live; ++i) row[i] = next[lane[i]]++;
      ++tally.calls;
      call(live < W ? narrow_for(K, static_cast<std::size_t>(live), fma) : K, lane, row, live);
      for (int i = 0; i < live;) {  // chains without rows left hand on their lanes
        if (next[lane[i]] != end[lane[i]]) ++i;
        else if (waiting > 0) lane[i++] = front();
        else lane[i] = lane[--live];
      }
      if (waiting > 0) {  // one lane in turn takes the front chain
        turn = turn % live;
        const int c = front();
        back(lane[turn]);
        lane[turn++] = c;
      }
    }
  }
}

}  // namespace

std::size_t batch_simd_lane_rows() { return lane_rows; }
std::size_t batch_simd_screened_rows() { return screened_rows; }
std::size_t batch_simd_resumed_rows() { return resumed_rows; }
std::size_t batch_simd_lane_resumed_rows() { return lane_resumed_rows; }
void batch_simd_resume_in_lanes(bool on) { resume_in_lanes.store(on, std::memory_order_relaxed); }
std::size_t batch_simd_warm_calls() { return warm_calls; }
void batch_simd_mark_declined(std::vector<std::uint8_t>* marks) { declined_marks = marks; }

const char* batch_simd_isa() { return pick_kernel().isa; }
int batch_simd_lanes() { return pick_kernel().lanes; }

bool batch_simd_covers(const Shape& body1, const Shape& body2, const SolverOptions& o) {
  (void)o;
  return ((ellipsoid(body1) && ellipsoid(body2)) || newton_pair(body1, body2)) && pick_kernel().fn != nullptr;
}

bool batch_simd_finishes(const Shape& body1, const Shape& body2, const SolverOptions& o) {
  (void)o;
  return newton_pair(body1, body2) && pick_kernel().newton_finish != nullptr;
}

namespace {

/// Row k's pose into lane i of W (R: 9 rows of W, row-major entries; p: 3).
[[gnu::always_inline]] inline void gather_pose(const PoseRows& poses, std::size_t k, int W, int i, double* Rb, double* pb) {
  if (poses.list) {
    const Pose& X = poses.list[k];
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) Rb[(3 * a + b) * W + i] = X.R(a, b);
      pb[a * W + i] = X.p[a];
    }
  } else {
    for (int e = 0; e < 9; ++e) Rb[e * W + i] = poses.R[9 * k + e];
    for (int a = 0; a < 3; ++a) pb[a * W + i] = poses.p[3 * k + a];
  }
}

/// Row k's answer from lane i: alpha, x_1, Converged, iterations, and the
/// contact kinematics where asked for (g1: body 1's gradient at its witness
/// point); the rest (derivatives, wrench) by tally.finish from the lane's
/// converged z (zb, 6 rows of W) and, where the lanes formed them, the
/// row's derivatives (LaneFinish).
[[gnu::always_inline]] inline void write_row(Tally& tally, const BatchOutput& out, std::size_t k, int W, int i, const double* ab, const double* xb, const double* pb,
               const double* gb, int iterations, const double* zb, const double* derivatives = nullptr) {
  if (__builtin_expect(tally.finish != nullptr, 0)) tally.finish(tally.ctx, k, LaneRow{zb + i, ab + i, xb + i, gb + i, W, iterations, derivatives});
  out.alpha[k] = ab[i];
  out.x_1[3 * k] = xb[i];
  out.x_1[3 * k + 1] = xb[W + i];
  out.x_1[3 * k + 2] = xb[2 * W + i];
  out.status[k] = static_cast<std::int32_t>(SolveStatus::Converged);
  out.iterations[k] = iterations;
  ++tally.rows;
  if (!tally.kinematics) return;
  const ContactKinematics c = kinematics_from(ab[i], Vec3(xb[i], xb[W + i], xb[2 * W + i]), Vec3(pb[i], pb[W + i], pb[2 * W + i]),
                                              Vec3(gb[i], gb[W + i], gb[2 * W + i]));
  if (!out.gap.empty()) out.gap[k] = c.gap;
  for (int j = 0; j < 3; ++j) {
    if (!out.normal_1.empty()) out.normal_1[3 * k + j] = c.nhat_1[j];
    if (!out.p1_1.empty()) out.p1_1[3 * k + j] = c.p1_1[j];
    if (!out.p2_1.empty()) out.p2_1[3 * k + j] = c.p2_1[j];
  }
}

/// The Newton lanes' constants of a pair under these options, as
/// PairSolver::solve and bounds() form them.
NewtonLaneConsts newton_consts(const Shape& body1, const Shape& body2, const SolverOptions& o) {
  NewtonLaneConsts C;
  lane_shape(body1, C.s1);
  lane_shape(body2, C.s2);
  const Radii r1 = radii(body1), r2 = radii(body2);
  const double fS = o.surrogate_factor;
  C.L = r1.outer + r2.outer;
  C.fSL = fS * C.L;
  C.c1f = fS * r1.outer / C.L;
  C.c2f = fS * r2.outer / C.L;
  const double fL = fS * C.L;
  C.lo = std::log(fL / (r1.outer + r2.outer)) - o.bound_margin;
  C.hi = std::log(fL / (r1.inner + r2.inner)) + o.bound_margin;
  auto phi_scale = [](const Shape& b) { return std::visit([](const auto& x) { return x.phi_scale(); }, b); };
  C.inv_sigma1 = 1.0 / phi_scale(body1);
  C.inv_sigma2 = 1.0 / phi_scale(body2);
  // The cone and the polytope are not homogeneous.
  auto logsumexp = [](const LaneShape& sh) { return sh.family == LaneFamily::Cone || sh.family == LaneFamily::Polytope; };
  C.check_hessians = logsumexp(C.s1) || logsumexp(C.s2);
  C.tol = o.tolerance;
  C.band = 1e-3;
  const PoseMargins pm = pose_margins(C.L);
  C.pose_tol2 = pm.pose_tol2, C.rmax_lo = pm.rmax_lo, C.rmax_hi = pm.rmax_hi;
  C.max_step_s = o.max_step_s;
  C.max_step_x = o.max_step_x;
  C.tau_first = o.lambda_fraction_to_boundary;
  C.tau_restart = o.lambda_fraction_to_boundary_restart;
  C.armijo_c = o.armijo_c;
  C.backtrack_factor = o.backtrack_factor;
  C.max_backtracks = o.max_backtracks;
  C.max_iterations = o.max_iterations;
  C.predictor_order = o.warm_predictor_order;
  C.predictor_steps = 2;      // PairSolver::kPredictorSteps
  C.fast_pivot = 1e5 * o.min_pivot_ratio;  // PairSolver::kFastPivotFactor
  C.chord_res = 1e-7;         // PairSolver::kChordResidual
  C.predictor_max_step = 0.05;  // PairSolver::kPredictorMaxStep
  C.predictor_gain2 = 0.25 * 0.25;  // PairSolver::kPredictorGain squared
  return C;
}

/// The rows of a call: k[0..n), or lo .. lo + n - 1 where k is null.
struct RowList {
  const std::size_t* k;
  std::size_t lo, n;
  std::size_t operator[](std::size_t r) const { return k ? k[r] : lo + r; }
  /// Rows [from, n) of the list to the scalar loop.
  void to_scalar(std::size_t from, ScalarRowsFn scalar, const void* ctx) const {
    if (!k) return scalar(ctx, lo + from, lo + n, nullptr, nullptr);
    for (std::size_t r = from; r < n; ++r) scalar(ctx, k[r], k[r] + 1, nullptr, nullptr);
  }
};

/// Row k's pose.
Pose pose_of(const PoseRows& poses, std::size_t k) {
  if (poses.list) return poses.list[k];
  Pose X;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) X.R(a, b) = poses.R[9 * k + 3 * a + b];
    X.p[a] = poses.p[3 * k + a];
  }
  return X;
}

/// The warm Newton lanes' buffers, and one call of them: row[i] (i < live)
/// warm-started from *ws[i], which it updates where the lane answers, as
/// PairSolver::solve updates a WarmStart; a row a lane declines goes to the
/// scalar loop with its WarmStart.
/// With `hold` (warm chains, whose lanes change chains once a call:
/// rotate_chains), a lane keeps its answered state (z, z_prev, history,
/// extrapolate) in its buffers, newer than its WarmStart, for the chain's
/// next row, and stores it only when the lane is given to another chain,
/// when the chain's row goes to the loop, or when the lanes change width;
/// copying each row's state in and out of its WarmStart was a tenth of the
/// warm calls' time. Without (rows of per-row WarmStarts), each answer is
/// stored at once.
struct NewtonWarmLanes {
  Lanes<9> Rb;
  Lanes<3> pb, xb, gb;
  Lanes<6> zb;
  Lanes<12> zpb;
  Lanes<1> ab;
  int hist[kMaxLanes], extra[kMaxLanes], live_valid[kMaxLanes], iters[kMaxLanes], ok[kMaxLanes];
  /// held[i]: the WarmStart whose newer state lane i holds (null: none), in
  /// lanes of held_w.
  WarmStart* held[kMaxLanes] = {};
  int held_w = 0;

  [[gnu::always_inline]] inline void load(int W, int i, const WarmStart& w) {
    hist[i] = w.history;
    extra[i] = w.extrapolate;
    for (int j = 0; j < 6; ++j) {
      zb[j * W + i] = w.z[j];
      zpb[j * W + i] = w.z_prev[0][j];
      zpb[(6 + j) * W + i] = w.z_prev[1][j];
    }
  }
  [[gnu::always_inline]] inline void store(int W, int i, WarmStart& w) {
    w.history = hist[i];
    w.extrapolate = extra[i] != 0;
    for (int j = 0; j < 6; ++j) {
      w.z[j] = zb[j * W + i];
      w.z_prev[0][j] = zpb[j * W + i];
      w.z_prev[1][j] = zpb[(6 + j) * W + i];
    }
  }
  /// Lane i's held state into its WarmStart.
  void release(int i) {
    if (!held[i]) return;
    store(held_w, i, *held[i]);
    held[i] = nullptr;
  }
  /// The held states dropped (a new group of chains: the old ones are over).
  void forget() {
    for (WarmStart*& h : held) h = nullptr;
  }

  [[gnu::always_inline]] inline void call(const Kernel& G, const NewtonLaneConsts& C, const PoseRows& poses,
                                          WarmStart* const* ws, const std::size_t* row, int live, const BatchOutput& out,
                                          ScalarRowsFn scalar, const void* ctx, Tally& tally, bool hold) {
    const NewtonLaneIO io = {Rb, pb, zb, zpb, hist, extra, live_valid, ab, xb, gb, iters, ok};
    const int W = G.lanes;
    // Every held state that this call's lanes do not continue, stored
    // before any lane loads (a chain may move to another lane).
    for (int i = 0, n = held_w > W ? held_w : W; i < n; ++i)
      if (held[i] && (held_w != W || i >= live || held[i] != ws[i])) release(i);
    held_w = W;
    for (int i = 0; i < W; ++i) {
      gather_pose(poses, row[i < live ? i : 0], W, i, Rb, pb);
      if (i < live) {
        if (held[i]) {  // it answered the chain's last row, so its WarmStart is valid for this pair
          live_valid[i] = 1;
          continue;
        }
        const WarmStart& w = *ws[i];
        live_valid[i] = w.valid && w.length == C.L;
        load(W, i, w);
        continue;
      }
      live_valid[i] = 0;  // an idle lane repeats lane 0; it is not read
      hist[i] = hist[0];
      extra[i] = extra[0];
      for (int j = 0; j < 6; ++j) zb[j * W + i] = zb[j * W];
      for (int j = 0; j < 12; ++j) zpb[j * W + i] = zpb[j * W];
    }
    G.newton(C, io);
    if (tally.derive) tally.fin->run(G, C, Rb, pb, zb, *tally.derive);
    for (int i = 0; i < live; ++i) {
      WarmStart& w = *ws[i];
      if (!ok[i]) {  // the kernel left the lane's state as it was before the row
        release(i);
        to_loop(scalar, ctx, row[i], &w);
        continue;
      }
      write_row(tally, out, row[i], W, i, ab, xb, pb, gb, iters[i], zb, tally.derive ? tally.fin->row(i) : nullptr);
      if (hold) held[i] = &w;
      else store(W, i, w);
    }
  }
};

/// A polytope whose face kernel fuses: lanes that fuse (lane_shape_polytope, narrow_for).
bool fuses(const NewtonLaneConsts& C) {
  return (C.s1.family == LaneFamily::Polytope && C.s1.poly.fused) || (C.s2.family == LaneFamily::Polytope && C.s2.poly.fused);
}

/// Warm chains of a Newton-lane pair, W chains a call (rotate_chains);
/// each chain's first row (a cold start) and every row a lane declines go
/// to the scalar loop with the chain's WarmStart.
void solve_chains_newton(const Kernel& K, const Shape& body1, const Shape& body2, const SolverOptions& o, const PoseRows& poses,
                         std::size_t lo, std::size_t hi, std::size_t chain, const BatchOutput& out, ScalarRowsFn scalar,
                         const void* ctx, Tally& tally) {
  const NewtonLaneConsts C = newton_consts(body1, body2, o);
  // The chains' WarmStarts, one a slot; a lane holds its chain's newer
  // state from row to row (NewtonWarmLanes, hold).
  WarmStart ws[kMaxSlots];
  NewtonWarmLanes lanes;
  auto begin = [&](int n) {
    lanes.forget();
    for (int c = 0; c < n; ++c) ws[c] = WarmStart{};
  };
  auto call = [&](const Kernel& G, const int* slot, const std::size_t* row, int live) __attribute__((always_inline)) {
    WarmStart* w[kMaxLanes];
    for (int i = 0; i < live; ++i) w[i] = &ws[slot[i]];
    lanes.call(G, C, poses, w, row, live, out, scalar, ctx, tally, true);
  };
  // A chain that leaves the lanes keeps its state there until its lane
  // loads another (NewtonWarmLanes::call stores it then).
  rotate_chains(K, fuses(C), lo, hi, chain, scalar, ctx, tally, begin, call);
}

void solve_rows_newton_cold(const Kernel& K, const Shape& body1, const Shape& body2, const SolverOptions& o,
                            const PoseRows& poses, const RowList& rows, const BatchOutput& out, ScalarRowsFn scalar,
                            const void* ctx, Tally& tally, bool per_row = false);

/// Rows of a Newton-lane pair each warm-started from its own WarmStart
/// (BatchOutput::warm, as solve(..., &warm[k])): the rows whose WarmStart
/// is valid for this pair W a call through the warm lanes, in the order of
/// the rows, a last group of one on the loop (which reads and leaves
/// warm[k] itself); the others (a pair's first contact: a cold solve)
/// through the cold lanes, which leave warm[k] as solve() does.
void solve_rows_newton_warm_rows(const Kernel& K, const Shape& body1, const Shape& body2, const SolverOptions& o,
                                 const PoseRows& poses, const RowList& rows, const BatchOutput& out,
                                 ScalarRowsFn scalar, const void* ctx, Tally& tally) {
  const NewtonLaneConsts C = newton_consts(body1, body2, o);
  const bool fma = fuses(C);
  NewtonWarmLanes lanes;
  WarmStart* w[kMaxLanes];
  std::size_t row[kMaxLanes];
  int live = 0;
  auto flush = [&] {
    if (live == 1) scalar(ctx, row[0], row[0] + 1, nullptr, nullptr);
    else if (live > 1) {
      ++tally.calls;
      lanes.call(live < K.lanes ? narrow_for(K, static_cast<std::size_t>(live), fma) : K, C, poses, w, row, live, out,
                 scalar, ctx, tally, false);
    }
    live = 0;
  };
  std::vector<std::size_t> cold;  // rows with no warm state for this pair, which solve() solves cold
  for (std::size_t r = 0; r < rows.n; ++r) {
    const std::size_t k = rows[r];
    WarmStart& ws = out.warm[k];
    if (!(ws.valid && ws.length == C.L)) {
      cold.push_back(k);
      continue;
    }
    w[live] = &ws;
    row[live] = k;
    if (++live == K.lanes) flush();
  }
  flush();
  // In the cold lanes, each leaving its WarmStart as solve() leaves it:
  // in a simulation, a pair that comes into reach for the first time has
  // none (Scene keeps a state only for the last step's candidate pairs,
  // and a row answered Separated at once sets none), and each such row
  // was a cold solve on one core.
  if (!cold.empty())
    solve_rows_newton_cold(K, body1, body2, o, poses, RowList{cold.data(), 0, cold.size()}, out, scalar, ctx, tally, true);
}

/// Cold rows of a Newton-lane pair (superquadrics, smooth truncated cones,
/// smooth polytopes, spheres: LaneShape families 0-4): W rows at a time through the
/// first cold start (support_guess, then one Newton run); every row a lane
/// declines, and a last row alone (the last rows, fewer than W, run in
/// the narrowest kernel that holds them: narrow_for), go to the scalar
/// loop. Options whose first cold start is another (SolverOptions::
/// support_guess off: the ray guess) run the loop.
/// Long: the cold rows through the lanes, the resumed LM lanes and the loop,
/// one block of W rows at a time, with the tally of where each row went.
void solve_rows_newton_cold(const Kernel& K, const Shape& body1, const Shape& body2, const SolverOptions& o,
                            const PoseRows& poses, const RowList& rows, const BatchOutput& out, ScalarRowsFn scalar,
                            const void* ctx, Tally& tally, bool per_row) {
  NewtonColdConsts CC;
  CC.base = newton_consts(body1, body2, o);
  const NewtonLaneConsts& C = CC.base;
  if (!K.newton_cold || !o.support_guess) return rows.to_scalar(0, scalar, ctx);
  auto cold_shape = [](const Shape& b, NewtonColdShape& c) {
    const Radii r = radii(b);
    c.inner = r.inner, c.outer = r.outer;
    c.ax[0] = c.ax[1] = c.ax[2] = c.Rt = 0.0;
    if (const Superellipsoid* e = std::get_if<Superellipsoid>(&b)) c.ax[0] = e->a(), c.ax[1] = e->b(), c.ax[2] = e->c();
    if (const SmoothTruncatedCone* t = std::get_if<SmoothTruncatedCone>(&b)) c.Rt = t->Rt();
  };
  cold_shape(body1, CC.b1);
  cold_shape(body2, CC.b2);
  auto cold_polytope = [](const Shape& b, NewtonColdShape& c) {  // support_point of a smooth polytope
    if (const SmoothPolytope* q = std::get_if<SmoothPolytope>(&b)) {
      static_assert(sizeof(Vec3) == 3 * sizeof(double), "SmoothPolytope::vertices() is x, y, z of each vertex in turn");
      c.verts = q->vertices().data()->data();
      c.nv = static_cast<int>(q->vertices().size());
      c.vtol = 1e-9 * q->radii().outer;
    }
  };
  cold_polytope(body1, CC.b1);
  cold_polytope(body2, CC.b2);
  CC.exact_start = std::visit([](const auto& s1, const auto& s2) { return exact_start_applies(s1, s2, s1.sharpness(), s2.sharpness()); },
                              body1, body2)
                       ? 1
                       : 0;
  const SmoothPolytope* q1 = std::get_if<SmoothPolytope>(&body1);
  const SmoothPolytope* q2 = std::get_if<SmoothPolytope>(&body2);
  if (CC.exact_start && q1 && q2) {  // two polytopes: the dual simplex in the lanes, as exact_start sets it up
    CC.exact_start = 1;
    NewtonColdConsts::Simplex& X = CC.simplex;
    X.k = simplex_consts(*q1, *q2);
    X.F[0] = q1->face_block(), X.F[1] = q2->face_block();
    X.n[0] = q1->face_block_rows(), X.n[1] = q2->face_block_rows();
    X.m[0] = q1->num_halfspaces(), X.m[1] = q2->num_halfspaces();
    pair_smoothing_lengths(*q1, *q2, q1->sharpness(), q2->sharpness(), X.soft1, X.soft2);
    X.step = kExactStartPolytopeStep;
    X.unique = kExactStartUnique;
  } else if (CC.exact_start) {  // a polytope and an ellipsoid: the active-set method in the lanes
    CC.exact_start = 2;
    NewtonColdConsts::Ball& X = CC.ball;
    const SmoothPolytope& q = q1 ? *q1 : *q2;
    Vec3 ax = Vec3::Zero();
    std::visit([&](const auto& e) { ellipsoid_axes(e, e.sharpness(), ax); }, q1 ? body2 : body1);
    X.k = ball_consts(q, smoothing_length(q, q.sharpness()));
    X.F = q.face_block();
    X.n = q.face_block_rows(), X.m = q.num_halfspaces();
    for (int i = 0; i < 3; ++i) X.ax[i] = ax[i];
    X.polytope_first = q1 ? 1 : 0;
  }
  CC.exp_lo = std::exp(C.lo);
  CC.exp_hi = std::exp(C.hi);
  // PairSolver::stall_exit_: two homogeneous bodies (no cone, no polytope)
  // with the rounding continuation on.
  const double ratio = 1.0 - o.lm_min_progress;
  CC.stall_ratio2 = ratio * ratio;
  CC.stall_limit = !C.check_hessians && o.rounding_continuation && o.lm_stall_limit > 0 ? o.lm_stall_limit : 0;
  CC.min_pivot = o.min_pivot_ratio;
  CC.max_iterations_extended = o.max_iterations_extended;
  CC.extension_residual = o.extension_residual;
  CC.lm_max_trials = o.lm_max_trials;
  CC.lm_damping = o.lm_initial_damping;

  Lanes<9> Rb;
  Lanes<3> pb, xb, gb;
  Lanes<1> ab;
  int iters[kMaxLanes], ok[kMaxLanes];
  Lanes<6> lzb, zo;
  int lm[kMaxLanes], lm_it[kMaxLanes], lm_iters[kMaxLanes], lm_stalls[kMaxLanes], lm_chord[kMaxLanes];
  const NewtonColdIO io = {Rb, pb, ab, xb, gb, iters, ok, lm, lzb, lm_it, lm_iters, lm_stalls, lm_chord, zo};
  const int W = K.lanes;
  // The rows left at an LM step wait here until W of them resume together
  // (newton_resume); those left over at the end, if fewer than half the
  // lanes, go to the scalar solver from where they left.
  struct Left {
    std::size_t k;
    ColdResume at;
  };
  Left left[kMaxLanes];
  int nleft = 0;
  const bool lanes_resume = resume_in_lanes.load(std::memory_order_relaxed);
  Lanes<9> Rq;
  Lanes<3> pq, xq, gq;
  Lanes<1> aq;
  Lanes<6> lzq, zq;
  int iq[kMaxLanes], okq[kMaxLanes], lmq[kMaxLanes], itq[kMaxLanes], itersq[kMaxLanes], stallsq[kMaxLanes], chordq[kMaxLanes];
  const NewtonColdIO ioq = {Rq, pq, aq, xq, gq, iq, okq, lmq, lzq, itq, itersq, stallsq, chordq, zq};
  // per_row: each row's WarmStart (out.warm, none valid for this pair on
  // the way in) left as solve() leaves it after a cold solve: the answer's
  // z, its history restarted. A row left at an LM step that the lanes do
  // not finish is solved again from the start on one core, which sets it.
  auto resume_scalar = [&](const Left& e) {
    if (per_row) return to_loop(scalar, ctx, e.k, nullptr);
    ++resumed_rows;
    to_loop(scalar, ctx, e.k, nullptr, &e.at);
  };
  auto keep = [&](std::size_t k, const double* z, int Wz, int i) {
    if (!per_row) return;
    WarmStart& w = out.warm[k];
    for (int j = 0; j < 6; ++j) w.z[j] = z[j * Wz + i];
    w.valid = true;
    w.history = 0;
    w.length = C.L;
  };
  // Lane i's record in a NewtonColdIO's lm_* (W lanes), and back.
  auto record_of = [](const NewtonColdIO& c, int i, int W) {
    ColdResume r;
    for (int j = 0; j < 6; ++j) r.z[j] = c.lm_z[j * W + i];
    r.it = c.lm_it[i], r.iterations = c.lm_iters[i], r.stalls = c.lm_stalls[i];
    r.chord_ok = (c.lm_chord[i] & 1) != 0, r.chord_tried = (c.lm_chord[i] & 2) != 0;
    return r;
  };
  auto put_record = [W](const ColdResume& r, const NewtonColdIO& c, int i) {
    for (int j = 0; j < 6; ++j) c.lm_z[j * W + i] = r.z[j];
    c.lm_it[i] = r.it, c.lm_iters[i] = r.iterations, c.lm_stalls[i] = r.stalls;
    c.lm_chord[i] = (r.chord_ok ? 1 : 0) | (r.chord_tried ? 2 : 0);
  };
  std::unique_ptr<LaneFinish> fin_q;  // the resumed calls' derivatives (below)
  auto resume_lanes = [&] {
    for (int i = 0; i < W; ++i) {  // idle lanes repeat the first row; their answers are not read
      const Left& e = left[i < nleft ? i : 0];
      gather_pose(poses, e.k, W, i, Rq, pq);
      put_record(e.at, ioq, i);
    }
    K.newton_resume(CC, ioq);
    // Their derivatives in a buffer of their own: a resumed call can come
    // between the lanes of a call whose rows are still being written, and
    // in tally.fin it overwrote theirs.
    if (tally.derive) {
      if (!fin_q) fin_q = std::make_unique<LaneFinish>();
      fin_q->run(K, C, Rq, pq, zq, *tally.derive);
    }
    for (int i = 0; i < nleft; ++i) {
      if (okq[i]) {
        write_row(tally, out, left[i].k, W, i, aq, xq, pq, gq, iq[i], zq, tally.derive ? fin_q->row(i) : nullptr);
        keep(left[i].k, zq, W, i);
        ++lane_resumed_rows;
        continue;
      }
      resume_scalar({left[i].k, record_of(ioq, i, W)});
    }
    nleft = 0;
  };
  // The last rows, fewer than W, in the narrowest kernel that holds them
  // (narrow_for; idle lanes repeat the first row and are not read): a
  // pair's rows in a scene seldom fill the lanes to the last group (the
  // 1,000-body box: 19 pairs, about 2% of its rows after their last full
  // group), and a group of lanes costs less than the loop on two rows or
  // more. One row left: the loop.
  const bool fma = fuses(C);
  for (std::size_t r0 = 0; r0 < rows.n; r0 += W) {
    const std::size_t live = std::min<std::size_t>(rows.n - r0, static_cast<std::size_t>(W));
    if (live < 2) {
      rows.to_scalar(r0, scalar, ctx);
      break;
    }
    const Kernel& G = live < static_cast<std::size_t>(W) ? narrow_for(K, live, fma) : K;
    const int Wg = G.lanes, n = static_cast<int>(live);
    std::size_t k[kMaxLanes];
    for (int i = 0; i < Wg; ++i) k[i] = rows[r0 + (i < n ? i : 0)];
    for (int i = 0; i < Wg; ++i) gather_pose(poses, k[i], Wg, i, Rb, pb);
    G.newton_cold(CC, io);
    if (tally.derive) tally.fin->run(G, C, Rb, pb, zo, *tally.derive);
    for (int i = 0; i < n; ++i) {
      if (ok[i]) {
        write_row(tally, out, k[i], Wg, i, ab, xb, pb, gb, iters[i], zo, tally.derive ? tally.fin->row(i) : nullptr);
        keep(k[i], zo, Wg, i);
      } else if (lm[i]) {  // left at an LM step: resumed from there
        const Left e = {k[i], record_of(io, i, Wg)};
        if (!lanes_resume) {
          resume_scalar(e);
          continue;
        }
        left[nleft++] = e;
        if (nleft == W) resume_lanes();
      } else {
        to_loop(scalar, ctx, k[i], nullptr);
      }
    }
  }
  if (2 * nleft >= W) resume_lanes();
  for (int i = 0; i < nleft; ++i) resume_scalar(left[i]);
}

/// The constants of an ellipsoid pair for the closed-form lanes, exactly as
/// PairSolver::solve and bounds() form them.
EllipsoidLaneConsts ellipsoid_consts(const Superellipsoid* s1, const Superellipsoid* s2, const SolverOptions& o) {
  EllipsoidLaneConsts C;
  const Radii r1 = s1->radii(), r2 = s2->radii();
  const double fS = o.surrogate_factor;
  C.M1[0] = s1->a() * s1->a(), C.M1[1] = s1->b() * s1->b(), C.M1[2] = s1->c() * s1->c();
  C.M2[0] = s2->a() * s2->a(), C.M2[1] = s2->b() * s2->b(), C.M2[2] = s2->c() * s2->c();
  C.inv1[0] = 1.0 / s1->a(), C.inv1[1] = 1.0 / s1->b(), C.inv1[2] = 1.0 / s1->c();
  C.inv2[0] = 1.0 / s2->a(), C.inv2[1] = 1.0 / s2->b(), C.inv2[2] = 1.0 / s2->c();
  C.L = r1.outer + r2.outer;
  C.fSL = fS * C.L;
  C.c1f = fS * r1.outer / C.L;
  C.c2f = fS * r2.outer / C.L;
  const double fL = o.surrogate_factor * C.L;
  C.lo = std::log(fL / (r1.outer + r2.outer)) - o.bound_margin;
  C.hi = std::log(fL / (r1.inner + r2.inner)) + o.bound_margin;
  C.inv_sigma1 = 1.0 / s1->phi_scale();
  C.inv_sigma2 = 1.0 / s2->phi_scale();
  C.accept = 0.5 * o.tolerance;
  const PoseMargins pm = pose_margins(C.L);
  C.pose_tol2 = pm.pose_tol2, C.rmax_lo = pm.rmax_lo, C.rmax_hi = pm.rmax_hi;
  return C;
}

/// Rows of two ellipsoids through the closed-form lanes, W a call; the rows
/// left when fewer than W remain run the loop. Per row (BatchOutput::warm),
/// each lane starts from its row's WarmStart as PairSolver::solve does
/// (warm_l, -1: cold) and leaves in it what solve leaves; else every row is
/// cold. Compiled for each mode (kPerRow) and kind of list (kList: rows.k
/// given), so that a cold call of consecutive rows, the closed form's few
/// hundred instructions a row, carries no test of the others.
template <bool kPerRow, bool kList>
void solve_rows_ellipsoid(const Kernel& K, const Superellipsoid& s1, const Superellipsoid& s2, const SolverOptions& o,
                          const PoseRows& poses, const RowList& rows, const BatchOutput& out, ScalarRowsFn scalar,
                          const void* ctx, Tally& tally) {
  constexpr bool per_row = kPerRow;
  const EllipsoidLaneConsts C = ellipsoid_consts(&s1, &s2, o);
  Lanes<9> Rb;
  Lanes<3> pb, xb, gb;
  Lanes<6> zb;
  Lanes<1> l0, ab;
  int ok[kMaxLanes];
  auto warm_l = [&](const WarmStart& w) { return w.valid && w.length == C.L ? w.z[4] / (w.z[4] + w.z[5]) : -1.0; };
  const int W = K.lanes;
  for (std::size_t r0 = 0; r0 < rows.n; r0 += W) {
    if (rows.n - r0 < static_cast<std::size_t>(W)) {
      rows.to_scalar(r0, scalar, ctx);
      break;
    }
    auto row = [&](int i) { return kList ? rows.k[r0 + i] : rows.lo + r0 + i; };  // lane i's row
    for (int i = 0; i < W; ++i) {
      gather_pose(poses, row(i), W, i, Rb, pb);
      l0[i] = per_row ? warm_l(out.warm[row(i)]) : -1.0;
    }
    K.fn(C, Rb, pb, l0, ab, xb, zb, gb, ok);
    for (int i = 0; i < W; ++i) {
      const std::size_t k = row(i);
      if (!ok[i]) {
        to_loop(scalar, ctx, k, nullptr);
        continue;
      }
      write_row(tally, out, k, W, i, ab, xb, pb, gb, 0, zb);
      if (!per_row) continue;
      WarmStart& w = out.warm[k];
      if (l0[i] < 0.0) w.history = 0;  // a cold solve: the predictor's history restarts
      w.valid = true;
      w.length = C.L;
      for (int j = 0; j < 6; ++j) w.z[j] = zb[j * W + i];
    }
  }
}

/// Warm chains of two ellipsoids through the closed-form lanes, W chains a
/// call (rotate_chains).
void solve_chains_ellipsoid(const Kernel& K, const Superellipsoid& s1, const Superellipsoid& s2, const SolverOptions& o,
                            const PoseRows& poses, std::size_t lo, std::size_t hi, std::size_t chain,
                            const BatchOutput& out, ScalarRowsFn scalar, const void* ctx, Tally& tally) {
  const EllipsoidLaneConsts C = ellipsoid_consts(&s1, &s2, o);
  Lanes<9> Rb;
  Lanes<3> pb, xb, gb;
  Lanes<1> l0, ab;
  int ok[kMaxLanes];
  // Warm: W chains a call (rotate_chains), each lane warm-started from its
  // chain's WarmStart as the loop would be. l_next: the l that
  // PairSolver::solve's warm start of two ellipsoids forms from the chain's
  // WarmStart, lambda1 / (lambda1 + lambda2), or -1 (cold) where the
  // WarmStart is not valid for this pair; formed when the WarmStart changes.
  // A lane's answer z stays in its call's buffer (zring, kRing in turn)
  // until the chain's WarmStart needs it whole: a row the lanes decline,
  // which the loop solves from that WarmStart. A buffer is reused kRing
  // calls later; a chain in the lanes has a row in every call, and one
  // that leaves them has its next row within W + 1 calls (rotate_chains:
  // at most 2 W chains, W of them in the lanes, one let in a call), so
  // its z is there when needed; a chain without rows left never reads its
  // WarmStart again. Copying z into the WarmStart after every row (or
  // settling a buffer's chains before each reuse, or a chain's as it
  // leaves the lanes) cost the closed-form lanes more than warm saved them
  // against cold.
  WarmStart ws[kMaxSlots];
  double l_next[kMaxSlots];
  int zbuf[kMaxSlots], zlane[kMaxSlots], zwidth[kMaxSlots];
  constexpr int kRing = kMaxLanes + 2;
  Lanes<6> zring[kRing];
  int ring = 0;
  auto settle = [&](int c) {  // the chain's z from its buffer into its WarmStart
    if (zbuf[c] < 0) return;
    const double* z = zring[zbuf[c]] + zlane[c];
    for (int j = 0; j < 6; ++j) ws[c].z[j] = z[j * zwidth[c]];
    zbuf[c] = -1;
  };
  auto begin = [&](int n) {
    for (int c = 0; c < n; ++c) ws[c].reset(), l_next[c] = -1.0, zbuf[c] = -1;
  };
  auto call = [&](const Kernel& G, const int* slot, const std::size_t* row, int live) {
    const int W = G.lanes;
    ring = ring == kRing - 1 ? 0 : ring + 1;
    double* zc = zring[ring];
    for (int i = 0; i < W; ++i) {  // an idle lane repeats lane 0
      gather_pose(poses, row[i < live ? i : 0], W, i, Rb, pb);
      l0[i] = i < live ? l_next[slot[i]] : -1.0;
    }
    G.fn(C, Rb, pb, l0, ab, xb, zc, gb, ok);
    for (int i = 0; i < live; ++i) {
      const int c = slot[i];
      WarmStart& w = ws[c];
      if (!ok[i]) {
        settle(c);
        to_loop(scalar, ctx, row[i], &w);
        l_next[c] = w.valid && w.length == C.L ? w.z[4] / (w.z[4] + w.z[5]) : -1.0;
        continue;
      }
      write_row(tally, out, row[i], W, i, ab, xb, pb, gb, 0, zc);
      // What PairSolver::solve leaves in the WarmStart after this answer.
      if (l_next[c] < 0.0) {  // not valid for this pair before
        if (!(w.valid && w.length == C.L)) w.history = 0;
        w.valid = true;
        w.length = C.L;
      }
      zbuf[c] = ring, zlane[c] = i, zwidth[c] = W;
      l_next[c] = zc[4 * W + i] / (zc[4 * W + i] + zc[5 * W + i]);
    }
  };
  rotate_chains(K, false, lo, hi, chain, scalar, ctx, tally, begin, call);
}

/// What the screen of the rows Separated at once reads of a body.
SupportShape support_shape(const Shape& b) {
  SupportShape c{};
  c.family = LaneFamily::Sphere;
  if (const Sphere* x = std::get_if<Sphere>(&b)) c.R = x->R();
  if (const Superellipsoid* x = std::get_if<Superellipsoid>(&b)) {
    c.family = LaneFamily::Superellipsoid;
    c.ax[0] = x->a(), c.ax[1] = x->b(), c.ax[2] = x->c(), c.n = x->n();
  }
  if (const SuperellipticCylinder* x = std::get_if<SuperellipticCylinder>(&b))
    c.family = LaneFamily::Cylinder, c.h = x->h(), c.R = x->R(), c.n = x->n();
  if (const SmoothTruncatedCone* x = std::get_if<SmoothTruncatedCone>(&b))
    c.family = LaneFamily::Cone, c.Rb = x->Rb(), c.Rt = x->Rt(), c.a = x->a(), c.b = x->b();
  if (const SmoothPolytope* x = std::get_if<SmoothPolytope>(&b)) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "SmoothPolytope::vertices() is x, y, z of each vertex in turn");
    c.family = LaneFamily::Polytope;
    c.verts = x->vertices().data()->data();
    c.nv = static_cast<int>(x->vertices().size());
  }
  return c;
}

}  // namespace

void separated_rows_lanes(const Shape& body1, const Shape& body2, const SolverOptions& o, const PoseRows& poses,
                          const std::size_t* rows, std::size_t m, double* lower, std::int8_t* verdict) {
  // At most 4 lanes: on a CPU with AVX-512 its 512-bit arithmetic lowers
  // the core's clock for a while after, and a step whose screened rows all
  // then run on the scalar solver (bench_sim_batch's box100) ran 8% slower
  // with an 8-lane screen than without one; with 4 lanes it does not, and
  // the screen of many rows (ten64) is as fast.
  const Kernel K = narrow_for(kernel(), 4);
  const double L = radii(body1).outer + radii(body2).outer;
  const int W = K.lanes;
  // The pair's length outside the band solved unscaled, where solve()
  // never answers at once, or no lanes: the scalar screen decides.
  if (K.separated == nullptr || !unscaled_length(L) || !(o.alpha_max < std::numeric_limits<double>::infinity()) ||
      m < static_cast<std::size_t>(W)) {
    std::fill_n(verdict, m, std::int8_t{-1});
    return;
  }
  SeparatedLaneConsts C;
  C.s1 = support_shape(body1);
  C.s2 = support_shape(body2);
  const PoseMargins pm = pose_margins(L);
  C.pose_tol2 = pm.pose_tol2, C.rmax_lo = pm.rmax_lo, C.rmax_hi = pm.rmax_hi;
  C.alpha_max = o.alpha_max;
  Lanes<9> Rb;
  Lanes<3> pb;
  Lanes<1> lb;
  int sep[kMaxLanes];
  for (std::size_t r0 = 0; r0 < m; r0 += static_cast<std::size_t>(W)) {
    // The last call overlaps the one before (m >= W): its first lanes
    // screen rows again, to the same answer.
    const std::size_t b = std::min(r0, m - static_cast<std::size_t>(W));
    for (int i = 0; i < W; ++i) gather_pose(poses, rows[b + static_cast<std::size_t>(i)], W, i, Rb, pb);
    K.separated(C, Rb, pb, lb, sep);
    for (int i = 0; i < W; ++i) {
      lower[b + static_cast<std::size_t>(i)] = lb[i];
      verdict[b + static_cast<std::size_t>(i)] = static_cast<std::int8_t>(sep[i]);
      screened_rows += sep[i] >= 0 && b + static_cast<std::size_t>(i) >= r0;
    }
  }
}

void solve_rows_simd(const Shape& body1, const Shape& body2, const SolverOptions& o, const HertzModel* derive,
                     const PoseRows& poses, std::size_t lo, std::size_t hi, std::size_t chain, bool screened,
                     const BatchOutput& out, ScalarRowsFn scalar,
                     const void* ctx, FinishRowFn finish, SeparatedRowFn result, const void* finish_ctx) {
  const Kernel& K = kernel();
  Tally tally;
  tally.finish = finish;
  tally.kinematics = !(out.gap.empty() && out.normal_1.empty() && out.p1_1.empty() && out.p2_1.empty());
  tally.ctx = finish_ctx;
  tally.derive = finish != nullptr ? derive : nullptr;
  std::unique_ptr<LaneFinish> fin;
  if (tally.derive) tally.fin = (fin = std::make_unique<LaneFinish>()).get();
  const Superellipsoid* s1 = ellipsoid(body1);
  const Superellipsoid* s2 = ellipsoid(body2);
  const bool warm = chain > 0;
  const bool per_row = !warm && !out.warm.empty();  // each row its own WarmStart
  const bool newton = K.newton && newton_pair(body1, body2);
  // A finite alpha_max: chains run the loop (a Separated row breaks a
  // chain's history); cold and per-row rows whose certified bound already
  // exceeds it run the loop (solve() returns Separated there at once), the
  // others the lanes, which then solve what solve() solves.
  const bool bounded = o.alpha_max < std::numeric_limits<double>::infinity();
  if ((!newton && !(K.fn && s1 && s2)) || (warm && bounded)) {
    if (!warm) return scalar(ctx, lo, hi, nullptr, nullptr);
    for (std::size_t c = lo; c < hi; c += chain) scalar(ctx, c, std::min(hi, c + chain), nullptr, nullptr);
    return;
  }
  if (warm) {
    if (newton) return solve_chains_newton(K, body1, body2, o, poses, lo, hi, chain, out, scalar, ctx, tally);
    return solve_chains_ellipsoid(K, *s1, *s2, o, poses, lo, hi, chain, out, scalar, ctx, tally);
  }
  // Cold or per row: [lo, hi), or under a finite alpha_max the rows not
  // Separated at once, in lists of at most kListRows.
  // (screened: the caller has answered those already.)
  constexpr std::size_t kListRows = 256;
  std::size_t list[kListRows];
  std::size_t like = kNoRow;  // a row answered Separated at once before (SeparatedRowFn)
  const bool screen = bounded && !screened;
  for (std::size_t b0 = lo; b0 < hi; b0 += screen ? kListRows : hi - lo) {
    const std::size_t b1 = screen ? std::min(hi, b0 + kListRows) : hi;
    RowList rows{nullptr, b0, b1 - b0};
    if (screen) {  // in lanes first (separated_rows_lanes), the rows they leave by separated_bound
      rows = RowList{list, 0, 0};
      std::size_t cand[kListRows];
      double lw[kListRows];
      std::int8_t verdict[kListRows];
      for (std::size_t k = b0; k < b1; ++k) cand[k - b0] = k;
      separated_rows_lanes(body1, body2, o, poses, cand, b1 - b0, lw, verdict);
      for (std::size_t k = b0; k < b1; ++k) {
        double lower = 0.0;
        if (!separated_at_once(verdict[k - b0], lw[k - b0], body1, body2, [&] { return pose_of(poses, k); }, o, lower)) {
          list[rows.n++] = k;
          continue;
        }
        result(finish_ctx, k, lower, like);
        if (like == kNoRow) like = k;
      }
    }
    if (newton && per_row) solve_rows_newton_warm_rows(K, body1, body2, o, poses, rows, out, scalar, ctx, tally);
    else if (newton) solve_rows_newton_cold(K, body1, body2, o, poses, rows, out, scalar, ctx, tally);
    else {
      auto fn = per_row ? (rows.k ? &solve_rows_ellipsoid<true, true> : &solve_rows_ellipsoid<true, false>)
                        : (rows.k ? &solve_rows_ellipsoid<false, true> : &solve_rows_ellipsoid<false, false>);
      fn(K, *s1, *s2, o, poses, rows, out, scalar, ctx, tally);
    }
  }
}

}  // namespace idcol::detail
