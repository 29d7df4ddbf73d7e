// The lane kernel of the SIMD batch path: the solve of two ellipsoids by
// their closed form (detail::PairSolver's first start, ellipsoid_guess,
// cold or warm-started from the last contact's l, and the residual test
// that accepts it) for W poses at once, in GCC/Clang vector extensions.
//
// Included by one translation unit per instruction set (batch_simd_*.cpp),
// each of which defines IDCOL_LANES (the lane count W) and IDCOL_LANE_FN (the
// entry point's name) before including it, and is compiled with that ISA's
// flags and -ffp-contract=off. Everything here has internal linkage and the
// file includes only batch_simd_abi.hpp and idcol/detail/exp2_table.hpp
// (plain data), so that no inline function compiled for AVX can stand in for
// the baseline one elsewhere in the program (the linker keeps one copy of
// each inline function, chosen freely).
//
// What a lane answers (alpha*, x*, and the multipliers a warm chain carries
// to its next row) is the scalar solver's arithmetic on that pose, lane by
// lane, with no fused multiply-adds: the closed form, the KKT residual,
// the start's multipliers and the terms of the residual test are the
// scalar solver's own templates (idcol/detail/formulas/ellipsoid_contact.hpp,
// kkt.hpp), and the rest (solver_impl.hpp: PairSolver::solve, cold,
// ellipsoid_guess; shapes.hpp: Superellipsoid::eval_impl at n = 1) is
// repeated operation for operation, in Eigen's order, so it is the scalar
// answer to the bit. The residual test (kkt_relative_residual), which only
// decides, takes its terms with a margin. A lane is accepted only on the scalar
// solver's usual path: a valid pose, the closed form settled inside the
// trust region, every residual term under half the tolerance (so that no
// rounding can put the scalar test on the other side) and an answer that
// passes the scalar solver's final checks. Any other lane is flagged, and
// the caller solves that pose with the scalar solver.

#if !defined(IDCOL_LANES) || !defined(IDCOL_LANE_FN)
#error "define IDCOL_LANES and IDCOL_LANE_FN before including batch_simd_kernel.hpp"
#endif

#include "batch_simd_abi.hpp"
#include "idcol/detail/exp2_table.hpp"
#include "idcol/detail/formulas/derivatives.hpp"        // templates only: instantiated here over LaneNum, this unit's own
#include "idcol/detail/formulas/ellipsoid_contact.hpp"  // (the same)
#include "idcol/detail/formulas/kkt.hpp"                // (the same)
#include "idcol/detail/formulas/lu6.hpp"                // (the same)
#include "idcol/detail/formulas/newton.hpp"             // (the same)
#include "idcol/detail/formulas/newton_run.hpp"         // (the same)
#include "idcol/detail/formulas/shape_eval.hpp"         // (the same)
#include "idcol/detail/formulas/support.hpp"            // (the same)

#if defined(__SSE2__)
#include <immintrin.h>  // the blend and the whole-vector tests of sel and any
#endif

namespace {

typedef double V __attribute__((vector_size(8 * IDCOL_LANES)));
typedef decltype(V{} < V{}) M;  // what comparisons give: 64-bit integer lanes, -1 or 0
typedef unsigned long long VU __attribute__((vector_size(8 * IDCOL_LANES)));  // a lane's bits
constexpr int W = IDCOL_LANES;

/// x in every lane, as it is: a broadcast, not V{} + x (an addition, which
/// would also turn -0.0 into +0.0, unlike the scalar code that reads x).
inline V splat(double x) {
#if IDCOL_LANES == 2
  return V{x, x};
#elif IDCOL_LANES == 4
  return V{x, x, x, x};
#else
  return V{x, x, x, x, x, x, x, x};
#endif
}
/// a where m, else b: every bit of the chosen one (a blend where the lanes'
/// instruction set has one for this width; AVX-512 folds the three logical
/// operations into one ternary-logic instruction by itself).
inline V sel(M m, V a, V b) {
#if defined(__AVX__) && IDCOL_LANES == 4
  return (V)_mm256_blendv_pd((__m256d)b, (__m256d)a, (__m256d)m);
#else
  return (V)((m & (M)a) | (~m & (M)b));
#endif
}
inline V vabs(V a) { return (V)((M)a & (M{} + 0x7fffffffffffffff)); }
/// W doubles from v to dst, one unaligned vector store.
inline void store_v(double* dst, V v) { __builtin_memcpy(dst, &v, sizeof(V)); }
inline M finite(V a) { return (a - a) == 0.0; }
inline V vsqrt(V a) {
  V r;
  for (int i = 0; i < W; ++i) r[i] = __builtin_sqrt(a[i]);
  return r;
}
/// kExp2Table[j] in each lane: one gather where the instruction set has it.
inline V lane_table(const double* T, VU j) {
#if defined(__AVX512F__) && IDCOL_LANES == 8
  return _mm512_mask_i64gather_pd(_mm512_setzero_pd(), 0xff, (__m512i)j, T, 8);  // the unmasked form warns in GCC 12
#elif defined(__AVX2__) && IDCOL_LANES == 4
  return _mm256_i64gather_pd(T, (__m256i)j, 8);
#else
  V r;
  for (int i = 0; i < W; ++i) r[i] = T[j[i]];
  return r;
#endif
}
/// Whether any lane of m is set: one test of the whole vector.
inline bool any(M m) {
#if defined(__AVX512F__) && IDCOL_LANES == 8
  return _mm512_test_epi64_mask((__m512i)m, (__m512i)m) != 0;
#elif defined(__AVX__) && IDCOL_LANES == 4
  return !_mm256_testz_si256((__m256i)m, (__m256i)m);
#elif defined(__SSE2__) && IDCOL_LANES == 2
  return _mm_movemask_pd((__m128d)m) != 0;
#else
  long long r = 0;
  for (int i = 0; i < W; ++i) r |= m[i];
  return r != 0;
#endif
}

struct V3 {
  V x, y, z;
  V& operator[](int i) { return i == 0 ? x : i == 1 ? y : z; }
  const V& operator[](int i) const { return i == 0 ? x : i == 1 ? y : z; }
};

/// x^k by repeated squaring, as detail::ipow (the same multiplications).
__attribute__((always_inline)) inline V vipow(V x, int k) {
  if (k == 0) return splat(1.0);
  V r = splat(1.0);
  for (; k > 0; k >>= 1) {
    if (k & 1) r = r * x;
    x = x * x;
  }
  return r;
}

/// a b + c rounded once (kFused: a fused multiply-add, where the polytope's
/// AVX2 face kernel says mul_add) or twice.
template <bool kFused>
inline V lane_mul_add(V a, V b, V c) {
  if constexpr (!kFused) {
    return a * b + c;
  } else {
#if defined(__FMA__) && defined(__GNUC__) && !defined(__clang__) && IDCOL_LANES == 4
    return __builtin_ia32_vfmaddpd256(a, b, c);
#elif defined(__AVX512F__) && defined(__GNUC__) && !defined(__clang__) && IDCOL_LANES == 8
    return __builtin_ia32_vfmaddpd512_mask(a, b, c, static_cast<unsigned char>(-1), 4);  // 4: the current rounding mode
#else
    V r;
    for (int i = 0; i < W; ++i) r[i] = __builtin_fma(a[i], b[i], c[i]);
    return r;
#endif
  }
}

/// The lanes' number layer for the formulas written once
/// (idcol/detail/formulas/elementary.hpp says what each member is): T = V,
/// a Mask is a comparison's M, an early exit flags its lanes in `bad` (the
/// scalar solver answers them), and lazy selects between both sides.
/// Two vectors taken together (LaneNum::T2, the rows 0 and 1 that the
/// scalar layer pairs in one register).
struct V2 {
  V a, b;
};
inline V2 operator+(const V2& x, const V2& y) { return {x.a + y.a, x.b + y.b}; }
inline V2 operator-(const V2& x, const V2& y) { return {x.a - y.a, x.b - y.b}; }
inline V2 operator*(const V2& x, V s) { return {x.a * s, x.b * s}; }
inline V2 operator*(V s, const V2& x) { return {s * x.a, s * x.b}; }
inline V2 operator*(const V2& x, const V2& y) { return {x.a * y.a, x.b * y.b}; }
inline V2 operator/(const V2& x, V s) { return {x.a / s, x.b / s}; }

struct LaneNum {
  using T = V;
  using T2 = V2;
  /// A bound is tested by multiplication first (formulas/newton.hpp).
  static constexpr bool kPrescreen = true;
  using Mask = M;
  using Bits = VU;
  static V2 pair(V a, V b) { return {a, b}; }
  static V2 load2(const V* p) { return {p[0], p[1]}; }
  static V lo(const V2& v) { return v.a; }
  static V hi(const V2& v) { return v.b; }
  static V splat(double x) { return ::splat(x); }
  static V sel(M m, V a, V b) { return ::sel(m, a, b); }
  static M index(int k) { return M{} + k; }
  static M sel_index(M m, int a, M b) { return (m & (M{} + a)) | (~m & b); }
  static M sel_index(M m, M a, M b) { return (m & a) | (~m & b); }
  static V2 sel2(M m, const V2& a, const V2& b) { return {::sel(m, a.a, b.a), ::sel(m, a.b, b.b)}; }
  /// W problems at a time: a formula selects rows where one problem would
  /// index them (formulas/polytope_simplex.hpp).
  static constexpr bool kOneProblem = false;
  static M not_(M m) { return ~m; }
  static M mask(bool b) { return b ? ~M{} : M{}; }
  static bool any(M m) { return ::any(m); }
  static M finite(V a) { return ::finite(a); }
  /// std::copysign(a, b) for a >= 0.
  static V copysign(V a, V b) { return (V)((M)a | ((M)b & (M{} + (-0x7fffffffffffffffLL - 1)))); }
  /// glibc's hypot per lane.
  static V hypot(V a, V b) {
    V r = a;
    for (int i = 0; i < W; ++i) r[i] = __builtin_hypot(a[i], b[i]);
    return r;
  }
  static V abs(V a) { return vabs(a); }
  static V sqrt(V a) { return vsqrt(a); }
  static V log(V a) {
    V r = a;
    for (int i = 0; i < W; ++i) r[i] = __builtin_log(a[i]);
    return r;
  }
  static V pow(V a, double k) {
    V r = a;
    for (int i = 0; i < W; ++i) r[i] = __builtin_pow(a[i], k);
    return r;
  }
  static V ipow(V x, int k) { return vipow(x, k); }
  static VU bits(V x) { return (VU)x; }
  static V from_bits(VU b) { return (V)b; }
  template <bool kFused>
  static V mul_add(V a, V b, V c) {
    return lane_mul_add<kFused>(a, b, c);
  }
  static bool leaves(M m, M& bad) {
    bad |= m;
    return false;
  }
  static V exp2_table(VU j) { return lane_table(idcol::detail::kExp2Table, j); }
  /// 2^k always as 2^k1 2^k2 (the scalar layer splits only where 2^k is
  /// not normal; the first product is exact, so both round once, the same
  /// way). k is formed in doubles: x86 has no 64-bit arithmetic shift of
  /// vectors before AVX-512.
  static V times_pow2(V v, V t, VU j) {
    const V n = t - 0x1.8p52;
    const V k = (n - ((V)(j | 0x4330000000000000ull) - 0x1p52)) * (1.0 / 64.0);  // exact
    const V t1 = k * 0.5 + 0x1.8p52;                                                // round(k / 2) in t1's low bits
    const V t2 = (k - (t1 - 0x1.8p52)) + 0x1.8p52;
    return (v * (V)(((VU)t1 + 1023ull) << 52)) * (V)(((VU)t2 + 1023ull) << 52);
  }
  template <class A, class B>
  static V lazy(M m, A&& a, B&& b) {
    return ::sel(m, a(), b());
  }
  template <class E>
  static auto& phi(E& e) {
    return e.phi;
  }
  template <class E>
  static auto& grad(E& e, int i) {
    return e.g[i];
  }
  template <class E>
  static auto& hess(E& e, int i, int j) {
    return e.h[3 * i + j];
  }
};

/// detail::hypot_any per lane (formulas/elementary.hpp).
__attribute__((always_inline)) inline V lane_hypot_any(V a, V b) { return idcol::detail::formulas::hypot_any<LaneNum>(a, b); }
inline V dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 scale(V s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline V3 add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

/// A general 3x3 per lane, row-major.
struct G3 {
  V m[9];
  const V& operator()(int i, int k) const { return m[3 * i + k]; }
};
// The products below add in Eigen's order for a column-major 3x3 matrix
// times a vector or a matrix (Eigen 3.4, SSE2, as the library is built):
// rows 0 and 1 in one packet, (t0 + t1) + t2; row 2 by the scalar
// unroller, which splits in halves, t0 + (t1 + t2). A transposed matrix
// times a vector, and dot products, add (t0 + t1) + t2. (test_batch_simd
// fails on the first row that rounds otherwise.)
inline V sum_packet(V t0, V t1, V t2) { return (t0 + t1) + t2; }
inline V sum_tail(V t0, V t1, V t2) { return t0 + (t1 + t2); }
__attribute__((always_inline)) inline V3 mul(const G3& A, const V3& v) {
  return {sum_packet(A.m[0] * v.x, A.m[1] * v.y, A.m[2] * v.z), sum_packet(A.m[3] * v.x, A.m[4] * v.y, A.m[5] * v.z),
          sum_tail(A.m[6] * v.x, A.m[7] * v.y, A.m[8] * v.z)};
}

/// The scalar solver's final checks of a converged answer (PairSolver::
/// solve, after fill()): alpha and both multipliers positive and normal,
/// x finite with a normal (or zero) largest coordinate.
inline M answer_ok(V alpha, const V3& x1, V lam1, V lam2) {
  const V tiny = splat(2.2250738585072014e-308);  // DBL_MIN
  const V huge = splat(1.7976931348623157e308);   // DBL_MAX
  auto normal = [&](V v) { return (vabs(v) >= tiny) & (vabs(v) <= huge); };
  V xm = vabs(x1.x);
  xm = sel(vabs(x1.y) > xm, vabs(x1.y), xm);
  xm = sel(vabs(x1.z) > xm, vabs(x1.z), xm);
  return normal(alpha) & (alpha > 0.0) & ((xm == 0.0) | normal(xm)) & finite(x1.x) & finite(x1.y) & finite(x1.z) &
         normal(lam1) & (lam1 > 0.0) & normal(lam2) & (lam2 > 0.0);
}

/// W poses loaded and checked as PairSolver::solve checks them, and its
/// |r| and r_hat. R_in holds 9 rows of W (R_12 row-major, entry e of lane
/// i at [e W + i]), p_in 3 rows of W. Flags in `bad` each lane that fails
/// check_pose (finite entries, |R^T R - I|_F^2 <= pose_tol2, a bound with
/// a margin below kPoseTolerance's, so that a lane near the limit goes to
/// the scalar check; det R > 0) or whose largest |r| coordinate lies
/// outside [rmax_lo, rmax_hi] (concentric, or a scale left to the scalar
/// solver).
inline void load_pose(const double* R_in, const double* p_in, double pose_tol2, double rmax_lo, double rmax_hi, G3& R, V3& p,
                      V& rn, V3& rhat, M& bad) {
  for (int e = 0; e < 9; ++e)
    for (int i = 0; i < W; ++i) R.m[e][i] = R_in[e * W + i];
  for (int i = 0; i < W; ++i) {
    p.x[i] = p_in[i];
    p.y[i] = p_in[W + i];
    p.z[i] = p_in[2 * W + i];
  }
  M fin = finite(p.x) & finite(p.y) & finite(p.z);
  for (int e = 0; e < 9; ++e) fin &= finite(R.m[e]);
  bad |= ~fin;
  V f = V{};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      V s = R.m[a] * R.m[b] + R.m[3 + a] * R.m[3 + b] + R.m[6 + a] * R.m[6 + b];
      if (a == b) s = s - 1.0;
      f = f + s * s;
    }
  bad |= ~(f <= pose_tol2);
  const V det = R.m[0] * (R.m[4] * R.m[8] - R.m[5] * R.m[7]) - R.m[1] * (R.m[3] * R.m[8] - R.m[5] * R.m[6]) +
                R.m[2] * (R.m[3] * R.m[7] - R.m[4] * R.m[6]);
  bad |= ~(det > 0.0);
  // PairSolver::solve: r scaled by its largest coordinate, |r|, r_hat.
  V rmax = vabs(p.x);
  rmax = sel(vabs(p.y) > rmax, vabs(p.y), rmax);
  rmax = sel(vabs(p.z) > rmax, vabs(p.z), rmax);
  bad |= ~((rmax >= rmax_lo) & (rmax <= rmax_hi));
  const V3 rs = {p.x / rmax, p.y / rmax, p.z / rmax};
  const V rsn = vsqrt(dot(rs, rs));
  rn = rmax * rsn;
  rhat = {rs.x / rsn, rs.y / rsn, rs.z / rsn};
}

/// Superellipsoid::eval_impl at n = 1 without the Hessian: phi and grad.
/// Lanes at the frame origin (no gradient) are flagged in `bad`.
inline void eval_ellipsoid(const V3& y, const double inv[3], V& phi, V3& grad, M& bad) {
  const V3 yb = {y.x * inv[0], y.y * inv[1], y.z * inv[2]};
  const V ax = vabs(yb.x), ay = vabs(yb.y), az = vabs(yb.z);
  // Eigen's maxCoeff: the first of equal maxima, and a NaN never wins.
  V m = ax;
  m = sel(ay > m, ay, m);
  m = sel(az > m, az, m);
  bad |= ~(m > 0.0);
  const V im = 1.0 / m;
  const V3 u = {yb.x * im, yb.y * im, yb.z * im};
  const V S = u.x * u.x + u.y * u.y + u.z * u.z;  // p_i = 1 at n = 1
  const V root = vsqrt(S);
  const V psi = m * root;
  const V ir = 1.0 / root;
  phi = psi - 1.0;
  grad = {(u.x * ir) * inv[0], (u.y * ir) * inv[1], (u.z * ir) * inv[2]};
}

}  // namespace

namespace idcol::detail {

// Long: the lane kernel's entry point: the pose checks, the closed form, the
// residual test and the answer, in the order of the scalar solver's path.
void IDCOL_LANE_FN(const EllipsoidLaneConsts& C, const double* R_in, const double* p_in, const double* l0_in, double* alpha_out,
                   double* x_out, double* z_out, double* g1_out, int* ok_out) {
  G3 R;
  V3 p, rhat;
  V rn;
  M bad = M{};
  load_pose(R_in, p_in, C.pose_tol2, C.rmax_lo, C.rmax_hi, R, p, rn, rhat, bad);
  const V k = rn / C.fSL;
  const V3 c1 = scale(splat(C.c1f), rhat), c2 = scale(splat(C.c2f), rhat);

  // ellipsoid_guess: M2 in body 1's frame, R diag(M2) R^T, and r_S.
  const double* d2 = C.M2;
  G3 RM;  // R * diag(M2): Eigen forms the dense product, zeros included
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const V t0 = R.m[3 * a] * (b == 0 ? d2[0] : 0.0), t1 = R.m[3 * a + 1] * (b == 1 ? d2[1] : 0.0),
              t2 = R.m[3 * a + 2] * (b == 2 ? d2[2] : 0.0);
      RM.m[3 * a + b] = a < 2 ? sum_packet(t0, t1, t2) : sum_tail(t0, t1, t2);
    }
  // (R diag(M2)) R^T, all nine entries: the scalar solver's products read
  // both triangles, which rounding need not leave equal.
  G3 M2r;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const V t0 = RM.m[3 * a] * R.m[3 * b], t1 = RM.m[3 * a + 1] * R.m[3 * b + 1], t2 = RM.m[3 * a + 2] * R.m[3 * b + 2];
      M2r.m[3 * a + b] = a < 2 ? sum_packet(t0, t1, t2) : sum_tail(t0, t1, t2);
    }
  // M1 = diag(C.M1): the scalar solver's dense Mat3, zeros included.
  auto M1 = [&](int i, int j) { return i == j ? splat(C.M1[i]) : V{}; };
  const V3 r = scale(splat(C.L), add(c1, c2));
  const V ra[3] = {r.x, r.y, r.z};

  // ellipsoid_contact: Perram and Wertheim's l by safeguarded Newton, each
  // lane until it settles; a lane that does not within 40 steps is flagged.
  // The warm start (ellipsoid_contact_from) or the cold one.
  V l0;
  for (int i = 0; i < W; ++i) l0[i] = l0_in[i];
  const V l = sel((l0 > 0.0) & (l0 < 1.0), l0, idcol::detail::formulas::ellipsoid_contact_start<LaneNum>(M1, M2r, ra));
  V alpha_pw, xa[3];
  idcol::detail::formulas::ellipsoid_contact_from<LaneNum>(M1, M2r, ra, l, alpha_pw, xa, bad);
  const V3 x = {xa[0], xa[1], xa[2]};

  // s = log(alpha) inside the trust region (formulas::log_positive, as the
  // scalar solver's guess); z0 = (x / L - c1, s, 0, 0).
  bad |= ~(alpha_pw > 0.0);
  const V s = idcol::detail::formulas::log_positive<LaneNum>(alpha_pw);
  bad |= ~((s >= C.lo) & (s <= C.hi));
  const V3 xi = sub(V3{x.x / C.L, x.y / C.L, x.z / C.L}, c1);

  // kkt_residual at z0, then init_lambda's multipliers: the scalar solver's
  // own formulas (formulas/kkt.hpp), the ellipsoids evaluated without their
  // Hessians (neither formula reads one).
  struct PhiGrad {
    V phi;
    V3 g;
  };
  struct Point {
    V z[6], F[6];
    V alpha, ia;
    V3 y1, y2, g2w;
    PhiGrad e1, e2;
  } pt;
  const V z0[6] = {xi.x, xi.y, xi.z, s, V{}, V{}};
  for (int i = 0; i < 6; ++i) pt.z[i] = z0[i];
  idcol::detail::formulas::kkt_residual<LaneNum>(
      R, c1, c2, C.L, C.inv_sigma1, C.inv_sigma2, z0, pt, [&](const V3& y, PhiGrad& e) { eval_ellipsoid(y, C.inv1, e.phi, e.g, bad); },
      [&](const V3& y, PhiGrad& e) { eval_ellipsoid(y, C.inv2, e.phi, e.g, bad); });
  idcol::detail::formulas::kkt_init_lambda<LaneNum>(C.L, c1, c2, pt);
  const V ea = pt.alpha, l1 = pt.z[4], l2 = pt.z[5];
  const V3& g1 = pt.e1.g;
  const V F0 = pt.F[0], F1 = pt.F[1], F5 = pt.F[5];
  const V3 F24 = {pt.F[2], pt.F[3], pt.F[4]};
  const V merit = 0.5 * (F0 * F0 + F1 * F1 + dot(F24, F24) + F5 * F5);
  bad |= ~finite(merit);

  // kkt_relative_residual's terms (the scalar solver's formula), each
  // accepted with a margin (see the top); a NaN term is not accepted.
  V rel[4];
  idcol::detail::formulas::kkt_relative_terms<LaneNum>(pt, rel);
  bad |= ~((rel[0] <= C.accept) & (rel[1] <= C.accept) & (rel[2] <= C.accept) & (rel[3] <= C.accept));

  // fill(): alpha = k e^s, x_1 = k L (xi + c1), and the final checks that
  // the scalar solver makes (normal, positive alpha and multipliers).
  const V kL = k * C.L;
  const V alpha = k * ea;
  const V3 x1 = scale(kL, add(xi, c1));
  const V lam1 = k * l1, lam2 = k * l2;
  bad |= ~answer_ok(alpha, x1, lam1, lam2);
  store_v(alpha_out, alpha);
  store_v(x_out, x1.x), store_v(x_out + W, x1.y), store_v(x_out + 2 * W, x1.z);
  store_v(z_out, xi.x), store_v(z_out + W, xi.y), store_v(z_out + 2 * W, xi.z);
  store_v(z_out + 3 * W, s), store_v(z_out + 4 * W, l1), store_v(z_out + 5 * W, l2);
  store_v(g1_out, g1.x), store_v(g1_out + W, g1.y), store_v(g1_out + 2 * W, g1.z);
  for (int i = 0; i < W; ++i) ok_out[i] = bad[i] == 0;
}

}  // namespace idcol::detail
