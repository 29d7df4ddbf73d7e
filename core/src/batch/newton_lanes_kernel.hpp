// The Newton lanes of the SIMD batch path: the warm-started solve of two
// superquadrics (superellipsoids and superelliptic cylinders with an integer
// exponent) for W chains at once, in GCC/Clang vector extensions.
//
// Included after batch_simd_kernel.hpp (whose lane types and helpers it
// uses) by one translation unit per instruction set, which defines
// IDCOL_NEWTON_FN and IDCOL_NEWTON_FINISH_FN (the entry points' names).
// Internal linkage throughout, and only plain data from outside
// (batch_simd_abi.hpp), as for that kernel.
//
// A lane repeats PairSolver::solve's warm path on its chain's row: the
// predictor (SolverOptions::warm_predictor_order) tried for at most
// kPredictorSteps steps, then the last contact; each a Newton run, the
// scalar solver's own (formulas::newton_run, over the lanes' run LaneRun),
// as are the residual, the Jacobian, the LU and the shapes' evaluations
// (idcol/detail/formulas/), instantiated over the lanes' number layer. A lane leaves for the
// scalar solver, which then solves the row from the same WarmStart, at
// every point where the scalar solver would leave that path (an LM step, a
// Jacobian whose pivot ratio fails the fast LU, the iteration limit, a
// spurious root, a failed final check, a cold start) and wherever a value
// that decides the path lies within NewtonLaneConsts::band of its threshold,
// so that rounding cannot send the lane and the scalar solver down different
// paths. On the path they share, the two make the same steps, and their
// answers agree to rounding (test_batch_simd: 1e-12 relative, most rows to
// the bit).

#if !defined(IDCOL_NEWTON_FN) || !defined(IDCOL_NEWTON_FINISH_FN)
#error "define IDCOL_NEWTON_FN and IDCOL_NEWTON_FINISH_FN before including newton_lanes_kernel.hpp"
#endif

namespace {

inline V vmax(V a, V b) { return sel(b > a, b, a); }
inline V vmin(V a, V b) { return sel(b < a, b, a); }
inline V norm(const V3& a) { return vsqrt(dot(a, a)); }
/// Whether a lies within the relative band of the threshold b (a decision
/// that rounding could turn).
inline M near(V a, V b, double band) { return vabs(a - b) <= band * vabs(b); }

/// phi, its gradient and its Hessian (all nine entries, as the scalar
/// solver forms them) per lane.
struct Eval {
  V phi;
  V3 g;
  V h[9];
};

/// The square roots that take S^(1/2n) for n a power of two (2n = 2^k).
constexpr int sqrt_depth_of(int n) { return 1 + __builtin_ctz(static_cast<unsigned>(n)); }

/// The shape's exponent, n_int and sqrt_depth (Exponent), fixed at compile
/// time for kN > 0 (n = kN, a power of two: 2n = 2^sqrt_depth), so that
/// vipow's and root_2n's loops unroll; kN = 0 reads them from the shape.
template <int kN>
struct Expo {
  static_assert(kN == 0 || (kN & (kN - 1)) == 0, "a compile-time exponent is a power of two");
  double n;
  int n_int, sqrt_depth;
  explicit Expo(const idcol::detail::LaneShape& s)
      : n(kN ? kN : s.n), n_int(kN ? kN : s.n_int), sqrt_depth(kN ? sqrt_depth_of(kN ? kN : 1) : s.sqrt_depth) {}
};

/// A superquadric's exponent where it is 1, 2, 4, 8 or 16 (the lanes'
/// compile-time exponents: Expo), else 0.
inline int pow2_exponent(const idcol::detail::LaneShape& s) {
  const int n = s.n_int;
  return n >= 1 && n <= 16 && (n & (n - 1)) == 0 && s.sqrt_depth == sqrt_depth_of(n) ? n : 0;
}

/// Superellipsoid::eval_impl (formulas/shape_eval.hpp). Lanes at the frame
/// origin are flagged.
template <int kN>
inline void eval_se(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M& bad) {
  idcol::detail::formulas::superellipsoid<LaneNum>(s.inv, Expo<kN>(s), y.x, y.y, y.z, e, bad);
}

/// Sphere::eval (formulas/shape_eval.hpp). Lanes at the frame origin are
/// flagged.
inline void eval_sphere(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M& bad) {
  idcol::detail::formulas::sphere<LaneNum>(s.R, s.inv[0], y.x, y.y, y.z, e, bad);
}

/// SuperellipticCylinder::eval_impl (axis along y1; formulas/shape_eval.hpp).
/// Lanes at the frame origin are flagged.
template <int kN>
inline void eval_cyl(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M& bad) {
  idcol::detail::formulas::superelliptic_cylinder<LaneNum>(1.0 / s.h, 1.0 / s.R, Expo<kN>(s), y.x, y.y, y.z, e, bad);
}

}  // namespace

#include "newton_lanes_cone.hpp"
#include "newton_lanes_polytope.hpp"

namespace {

/// A body's evaluation in the lanes: its family's (and, for a superquadric
/// with n = 1, 2, 4, 8 or 16, its exponent's) instance of the formula the
/// scalar family runs (formulas/shape_eval.hpp).
using EvalFn = void (*)(const idcol::detail::LaneShape&, const V3&, Eval&, M&);

/// A compile-time exponent, for instance_for's pick.
template <int K>
struct Exponent {
  static constexpr int value = K;
};

/// pick(Exponent<k>{}) for the superquadric exponent k of s (1, 2, 4, 8,
/// 16; 0: any other n, the general instance).
template <class Pick>
inline EvalFn instance_for(const idcol::detail::LaneShape& s, Pick pick) {
  switch (pow2_exponent(s)) {
    case 1: return pick(Exponent<1>{});
    case 2: return pick(Exponent<2>{});
    case 4: return pick(Exponent<4>{});
    case 8: return pick(Exponent<8>{});
    case 16: return pick(Exponent<16>{});
    default: return pick(Exponent<0>{});
  }
}

/// The evaluation of the body s, chosen once for a kernel call
/// (problem_of): every evaluation of the call then goes straight to its
/// family's, with no family or exponent switched per evaluation.
inline EvalFn eval_fn(const idcol::detail::LaneShape& s) {
  using idcol::detail::LaneFamily;
  switch (s.family) {
    case LaneFamily::Superellipsoid:
      return instance_for(s, [](auto k) -> EvalFn { return &eval_se<decltype(k)::value>; });
    case LaneFamily::Cylinder: return instance_for(s, [](auto k) -> EvalFn { return &eval_cyl<decltype(k)::value>; });
    case LaneFamily::Cone: return &eval_cone;
    case LaneFamily::Sphere: return &eval_sphere;
    case LaneFamily::Polytope: break;
  }
  return &eval_polytope;
}

/// A body of a kernel call: its shape and its evaluation (eval_fn).
struct LaneBody {
  const idcol::detail::LaneShape* s;
  EvalFn fn;
  void eval(const V3& y, Eval& e, M& bad) const { fn(*s, y, e, bad); }
};

/// kkt.hpp's KktPoint, per lane.
struct Pt {
  V z[6], F[6];
  V alpha, ia;
  V3 y1, y2, g2w;
  Eval e1, e2;
};

/// Lane-wise select of a whole point.
static_assert(sizeof(Pt) % sizeof(V) == 0 && alignof(Pt) == alignof(V), "Pt is vectors only");
inline void take(M m, const Pt& a, Pt& b) {
  const V* s = reinterpret_cast<const V*>(&a);
  V* d = reinterpret_cast<V*>(&b);
  for (int i = 0; i < static_cast<int>(sizeof(Pt) / sizeof(V)); ++i) d[i] = sel(m, s[i], d[i]);
}

/// The surrogate problem of each lane's pose (PairSolver::set_problem), and
/// the two bodies.
struct Prob {
  G3 R;
  V3 c1, c2;
  LaneBody b1, b2;
};

/// kkt_residual.
__attribute__((always_inline))
inline void residual(const idcol::detail::NewtonLaneConsts& C, const Prob& P, const V (&z)[6], Pt& p, M& bad) {
  for (int i = 0; i < 6; ++i) p.z[i] = z[i];
  idcol::detail::formulas::kkt_residual<LaneNum>(
      P.R, P.c1, P.c2, C.L, C.inv_sigma1, C.inv_sigma2, z, p, [&](const V3& y, Eval& e) { P.b1.eval(y, e, bad); },
      [&](const V3& y, Eval& e) { P.b2.eval(y, e, bad); });
}

/// x / a and sqrt(a) for a value that only decides, with
/// NewtonLaneConsts::band around its threshold: on AVX-512 the 14-bit
/// estimates vrcp14pd and vrsqrt14pd (relative error at most 2^-14, 6.1e-5;
/// a few cycles each, where a division or a square root of eight lanes
/// holds the divider for about sixteen), elsewhere exact. sqrt_est(a) takes
/// 0 <= a < inf.
inline V div_est(V x, V a) {
#if defined(__AVX512F__) && IDCOL_LANES == 8
  return x * (V)_mm512_maskz_rcp14_pd(static_cast<__mmask8>(0xff), (__m512d)a);
#else
  return x / a;
#endif
}
inline V sqrt_est(V a) {
#if defined(__AVX512F__) && IDCOL_LANES == 8
  return sel(a > 0.0, a * (V)_mm512_maskz_rsqrt14_pd(static_cast<__mmask8>(0xff), (__m512d)a), V{});
#else
  return vsqrt(a);
#endif
}

/// The square of kkt_relative_residual, which only decides (converged,
/// chord step), formed with three divisions and two square roots where the
/// residual takes eight. Each term's square lies within a few units in the
/// last place of the scalar term's squared, or on AVX-512, where the
/// divisions and square roots are 14-bit estimates (div_est, sqrt_est),
/// within 2.5e-4 of it; either is far inside NewtonLaneConsts::band (1e-3),
/// so every decision outside the band is the scalar solver's. A lane whose
/// |y_i|^2 |grad phi_i|^2 could underflow where |y_i| |grad phi_i| does
/// not, whose |grad phi_i|^2 is not finite, or whose w^2 could underflow, is
/// flagged in `bad`.
inline V relres2(const Pt& p, M& bad) {
  const V n1s = dot(p.e1.g, p.e1.g), n2s = dot(p.e2.g, p.e2.g);
  const V d1 = dot(p.y1, p.y1) * n1s, d2 = dot(p.y2, p.y2) * n2s;
  bad |= (d1 < 1e-280) | (d2 < 1e-280) | ~(n1s < __builtin_inf()) | ~(n2s < __builtin_inf());
  const V e1 = div_est(p.e1.phi * p.e1.phi, d1), e2 = div_est(p.e2.phi * p.e2.phi, d2);
  const V l1 = p.z[4], l2 = p.z[5];
  const V w = vabs(l1) * sqrt_est(n1s) + vabs(l2) * sqrt_est(n2s);
  const V3 st = add(scale(l1, p.e1.g), scale(l2, p.g2w));
  const V w2 = w * w;
  bad |= (w > 0.0) & (w2 < 1e-280);
  const V es = sel(w > 0.0, div_est(dot(st, st), w2), splat(1.0));
  return vmax(vmax(vmax(e1, e2), es), p.F[5] * p.F[5]);
}

/// 0.5 ||F||^2, the scalar solver's bits (formulas::kkt_merit).
inline V merit_of(const Pt& p) { return idcol::detail::formulas::kkt_merit<LaneNum>(p.F); }

/// support_guess's ranking of its three starts (formulas::rank_starts).
using Ranking = idcol::detail::formulas::StartRanking<LaneNum>;

/// kkt_jacobian, row-major.
__attribute__((always_inline))
inline void jacobian(const idcol::detail::NewtonLaneConsts& C, const Prob& P, const Pt& p, V (&J)[6][6]) {
  struct Rows {
    V (&J)[6][6];
    V& operator()(int i, int j) { return J[i][j]; }
  } rows{J};
  idcol::detail::formulas::kkt_jacobian<LaneNum>(P.R, C.L, C.inv_sigma1, C.inv_sigma2, p, rows);
}

/// The LU of a Newton step per lane (formulas/lu6.hpp): KktLu6's (kKkt)
/// or Lu6's (the steps whose KktLu6 pivot ratio fails the fast test,
/// PairSolver::newton_direction's second factorisation). The rows are
/// moved: each lane's pivot row is swapped in by selects.
template <bool kKkt>
struct LaneLu {
  using O = idcol::detail::formulas::Lu6Order<kKkt>;
  V a[6][6];  // the factor rows (KktLu6's r), J's columns
  M perm[6];  // J's row of factor row i
  V inv[6];
  V ratio;

  V& at(int i, int j) { return a[i][j]; }
  const V& at(int i, int j) const { return a[i][j]; }
  /// Factor row K and the row each lane chose (p), over the rows K+1..Nr-1.
  template <int K, int Nr>
  void swap(M p) {
    for (int i = K + 1; i < Nr; ++i) {
      const M sw = p == i;
      if (!any(sw)) continue;  // no lane takes row i (often none swaps at all)
      for (int j = 0; j < 6; ++j) {
        const V t = a[K][j];
        a[K][j] = sel(sw, a[i][j], t);
        a[i][j] = sel(sw, t, a[i][j]);
      }
      const M t = perm[K];
      perm[K] = (sw & perm[i]) | (~sw & t);
      perm[i] = (sw & t) | (~sw & perm[i]);
    }
  }
  /// b's entry in J's row of factor row i, per lane.
  V rhs(const V (&b)[6], int i) const {
    V v = b[0];
    for (int r = 1; r < 6; ++r) v = sel(perm[i] == r, b[r], v);
    return v;
  }

  /// KktLu6's factorisation inline in the Newton loop; Lu6's (the rare
  /// fallback) out of line, as the compiler placed them when each had one
  /// caller.
  __attribute__((always_inline)) void factor(const V (&J)[6][6]) {
    if constexpr (kKkt)
      factor_impl(J);
    else
      factor_out(J);
  }
  __attribute__((noinline)) void factor_out(const V (&J)[6][6]) { factor_impl(J); }
  __attribute__((always_inline)) void factor_impl(const V (&J)[6][6]) {
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) a[i][j] = J[O::row[i]][j];
      perm[i] = M{} + O::row[i];
    }
    ratio = idcol::detail::formulas::lu6_factor<LaneNum, kKkt>(*this, inv);
  }

  void solve(const V (&b)[6], V (&x)[6]) const { idcol::detail::formulas::lu6_solve<LaneNum, kKkt>(*this, inv, b, x); }
  /// X with J X = B, a column at a time.
  void solve_columns(const V (&B)[6][6], V (&X)[6][6]) const {
    for (int j = 0; j < 6; ++j) {
      V b[6], x[6];
      for (int i = 0; i < 6; ++i) b[i] = B[i][j];
      solve(b, x);
      for (int i = 0; i < 6; ++i) X[i][j] = x[i];
    }
  }
  /// x's entry in J's row of factor row i, per lane.
  void put(V (&x)[6], int i, V v) const {
    for (int r = 0; r < 6; ++r) x[r] = sel(perm[i] == r, v, x[r]);
  }
  /// x with J^T x = b (the dense LU's).
  void solve_transpose(const V (&b)[6], V (&x)[6]) const {
    static_assert(!kKkt, "the transposed solve is the dense LU's");
    for (int r = 0; r < 6; ++r) x[r] = V{};
    idcol::detail::formulas::lu6_solve_transpose<LaneNum>(*this, inv, b, x);
  }
};
using Lu = LaneLu<true>;
using Lu6L = LaneLu<false>;

/// Where lanes left the run for an LM step (a failed line search, or no
/// Newton direction: the scalar solver's ColdResume): the lanes, their
/// point, the run's iteration, the steps before it, the stall count and the
/// chord flags after that step's chord attempt.
struct LmExit {
  M at;
  V z[6];
  V it, iters, stalls;
  M chord_ok, chord_tried;
};

/// The lanes lm leave at an LM step: where (LmExit), at each lane's
/// iteration `it`. Out of line: rare.
__attribute__((noinline, cold)) void record_lm_exit(LmExit& e, M lm, const Pt& p, V it, V iters, V stalls, M chord_ok,
                                                   M chord_tried) {
  if (!any(e.at)) e = LmExit{};  // the first lanes to leave: the record starts empty
  e.at |= lm;
  for (int i = 0; i < 6; ++i) e.z[i] = sel(lm, p.z[i], e.z[i]);
  e.it = sel(lm, it, e.it);
  e.iters = sel(lm, iters - 1.0, e.iters);
  e.stalls = sel(lm, stalls, e.stalls);
  e.chord_ok = (lm & chord_ok) | (~lm & e.chord_ok);
  e.chord_tried = (lm & chord_tried) | (~lm & e.chord_tried);
}

/// The run's counters of lanes that resume a run at an LM step
/// (newton_run<true>): the iteration it0, the steps before it, the stall
/// count and the chord flags, as LmExit recorded them.
struct LmResume {
  V it0, iters, stalls;
  M chord_ok, chord_tried;
};

/// What a cold run adds to newton_run (PairSolver's first cold start):
/// the start, evaluated already with its multipliers (start_evaluated_);
/// the stall exit (stall_exit_: stall_limit > 0 steps in a row that cut
/// the merit by less than the factor stall_ratio2, (1 - lm_min_progress)^2,
/// stall the run); and Lu6's step where KktLu6's pivot ratio fails the
/// fast test (min_pivot: SolverOptions::min_pivot_ratio, which Lu6's ratio
/// must pass), or where Lu6's fails too, Lu6's step of the equilibrated
/// system (PairSolver::newton_direction); and the extension past the
/// iteration limit (SolverOptions::max_iterations_extended, max_it_ext; a
/// run whose residual at the limit is at most extension_residual, whose
/// square is ext_res2, goes on in blocks of ten steps that must each cut
/// the residual tenfold).
struct RunExtras {
  const Pt* start;
  double stall_ratio2;
  int stall_limit;
  double min_pivot;
  int max_it_ext;
  double ext_res2;
  LmExit* lm;  // where the lanes that leave for an LM step left (not past max_iterations)
  // newton_run<true> only:
  const LmResume* resume = nullptr;  // every active lane begins at an LM step with these counters
  M* stalled = nullptr;              // the lanes whose run ends at a stall (PairSolver's stall exit), which stay good
  int lm_max_trials = 0;             // SolverOptions::lm_max_trials and lm_initial_damping
  double lm_damping = 0.0;
};

/// What a converged lane keeps of its last point: z, alpha and body 1's
/// gradient (the contact normal's direction).
struct Done {
  V z[6];
  V alpha;
  V3 g1;
  V trace;  // the sum of the two Hessians' traces (PairSolver::solve's last check for non-homogeneous pairs)
};

inline void keep(M m, const Pt& p, Done& d) {
  for (int i = 0; i < 6; ++i) d.z[i] = sel(m, p.z[i], d.z[i]);
  d.alpha = sel(m, p.alpha, d.alpha);
  d.g1 = {sel(m, p.e1.g.x, d.g1.x), sel(m, p.e1.g.y, d.g1.y), sel(m, p.e1.g.z, d.g1.z)};
  // Eigen's trace() adds h00 + (h11 + h22) (its unroller halves the
  // diagonal), which decides where a sum overflows.
  d.trace = sel(m, (p.e1.h[0] + (p.e1.h[4] + p.e1.h[8])) + (p.e2.h[0] + (p.e2.h[4] + p.e2.h[8])), d.trace);
}

/// The lanes' run of formulas::newton_run (formulas/newton_run.hpp): the
/// points in three buffers whose roles rotate, the residual measured by its
/// square (relres2), every decision within rounding of its threshold an
/// exit to the scalar solver (RunEnd::Unsure), and the exits as masks:
/// `bad` (the scalar solver answers), `capped`, `conv` with the answer in
/// `done`, and with kLm a stall in *x->stalled.
template <bool kLm>
struct LaneRun {
  using Point = Pt;
  using Vec = V[6];
  struct Mat {
    V a[6][6];
  };
  static constexpr bool kBands = true;
  static constexpr bool kPerLaneLimit = kLm;
  static constexpr bool kSharedCand = false;
  static constexpr bool kCheapEnds = true;

  const idcol::detail::NewtonLaneConsts& C;
  const Prob& P;
  const RunExtras* x;
  V tau;
  Done& done;
  M &conv, &capped, &bad;
  Pt buf[3];
  Pt* pt = &buf[0];
  Pt* trial = &buf[1];
  Pt* cand = &buf[2];
  Mat J;
  Lu lu;
  alignas(64) double lm_JtJ[W][36], lm_g[W][6];  // the LM step's normal equations per lane (lm_begin)
  double lm_mu[W];
  // The thresholds in the unit of relres2 (squared residuals).
  V tol_, chord_res_;
  int cap_;
  M cap_lanes_;

  LaneRun(const idcol::detail::NewtonLaneConsts& c, const Prob& p, const RunExtras* ex, V t, int cp, M cl, Done& d, M& cv,
          M& capd, M& b)
      : C(c), P(p), x(ex), tau(t), done(d), conv(cv), capped(capd), bad(b), tol_(splat(c.tol * c.tol)),
        chord_res_(splat(c.chord_res * c.chord_res)), cap_(cp), cap_lanes_(cl) {}

  V tol() const { return tol_; }
  V chord_res() const { return chord_res_; }
  double ext_res() const { return x->ext_res2; }
  static double cut() { return 0.01; }  // res <= 0.1 res_at_limit, squared
  double lo() const { return C.lo; }
  double hi() const { return C.hi; }
  int cap() const { return cap_; }
  M cap_lanes() const { return cap_lanes_; }
  int max_it() const { return C.max_iterations; }
  bool extends() const { return x != nullptr; }
  int max_it_ext() const { return x->max_it_ext; }
  int max_backtracks() const { return C.max_backtracks; }
  double armijo_c() const { return C.armijo_c; }
  double backtrack_factor() const { return C.backtrack_factor; }
  int stall_limit() const { return x ? x->stall_limit : 0; }
  double stall_ratio2() const { return x->stall_ratio2; }
  double fast_pivot() const { return C.fast_pivot; }
  double min_pivot() const { return x->min_pivot; }
  bool slow_lu() const { return x != nullptr; }

  [[gnu::always_inline]] void residual(const V (&z)[6], Pt& p, M& be) const { ::residual(C, P, z, p, be); }
  [[gnu::always_inline]] static V relres(const Pt& p, M& be) { return relres2(p, be); }
  [[gnu::always_inline]] static V merit(const Pt& p) { return merit_of(p); }
  [[gnu::always_inline]] static void sum(const V (&z)[6], const V (&dz)[6], V (&zt)[6]) {
    for (int i = 0; i < 6; ++i) zt[i] = z[i] + dz[i];
  }
  [[gnu::always_inline]] static void axpy(const V (&z)[6], V t, const V (&dz)[6], V (&zt)[6]) {
    for (int i = 0; i < 6; ++i) zt[i] = z[i] + t * dz[i];
  }
  [[gnu::always_inline]] static void negate(const V (&F)[6], V (&mF)[6]) {
    for (int i = 0; i < 6; ++i) mF[i] = -F[i];
  }
  [[gnu::always_inline]] static M all_finite(const V (&v)[6]) {
    M f = finite(v[0]);
    for (int i = 1; i < 6; ++i) f &= finite(v[i]);
    return f;
  }
  M near(V a, V b) const { return ::near(a, b, C.band); }
  M near(V a, double b) const { return ::near(a, splat(b), C.band); }
  /// formulas::limit_step: clamps dz[3] to the trust region and returns t,
  /// each bound's division made only in a group where some lane may reach
  /// it (rarely: a warm step is short).
  [[gnu::always_inline]] V limit_step(const Pt& p, V (&dz)[6]) const {
    return idcol::detail::formulas::limit_step<LaneNum>(p.z, p.alpha, dz, C.lo, C.hi, C.max_step_s, C.max_step_x, tau, C.band);
  }
  [[gnu::always_inline]] void factor(const Pt& p) {
    ::jacobian(C, P, p, J.a);
    lu.factor(J.a);
  }
  V fast_ratio() const { return lu.ratio; }
  [[gnu::always_inline]] void fast_solve(const V (&b)[6], V (&out)[6]) const { lu.solve(b, out); }
  const Mat& jacobian(const Pt&) const { return J; }  // formed by factor, kept
  static V& at(Mat& m, int i, int j) { return m.a[i][j]; }
  static const V& at(const Mat& m, int i, int j) { return m.a[i][j]; }
  static V lu6(const Mat& A, const V (&b)[6], V (&out)[6]) {
    Lu6L l6;
    l6.factor(A.a);
    l6.solve(b, out);
    return l6.ratio;
  }
  [[gnu::always_inline]] static void take(M m, const Pt& a, Pt& b) { ::take(m, a, b); }
  [[gnu::always_inline]] void converged(M m, int, const Pt& p) {
    keep(m, p, done);
    conv |= m;
  }
  [[gnu::always_inline]] void end(M m, idcol::detail::formulas::RunEnd why, int, V, const Pt&) {
    using idcol::detail::formulas::RunEnd;
    if (why == RunEnd::Capped)
      capped |= m;
    else if (kLm && why == RunEnd::Stalled)
      *x->stalled |= m;
    else
      bad |= m;
  }
  void stepped(M, M, M, int, V, M, const Pt&) const {}
  /// The LM step (formulas::lm_trials) is made in lanes by the cold rows
  /// that met it, resumed together (kLm); elsewhere the lanes leave it to
  /// the scalar solver.
  static constexpr bool lm_in_run() { return kLm; }
  int lm_max_trials() const { return x->lm_max_trials; }
  /// J^T J, g and the first damping of each lane in lm, by the scalar
  /// solver's own compiled code (lm_system.hpp) from the lane's J and F
  /// (the scalar solver's bits). Out of line: rare.
  __attribute__((noinline)) void lm_begin(M lm, const Pt& p) {
    for (int l = 0; l < W; ++l) {
      if (!lm[l]) continue;
      double Jl[36], Fl[6];
      for (int r = 0; r < 6; ++r) {
        Fl[r] = p.F[r][l];
        for (int c = 0; c < 6; ++c) Jl[6 * r + c] = J.a[r][c][l];
      }
      idcol::detail::lm_normal_equations(Jl, Fl, x->lm_damping, lm_JtJ[l], lm_g[l], &lm_mu[l]);
    }
  }
  /// Each lane's damped step (zero where it is not finite, or not in lm),
  /// and the next trial's damping.
  __attribute__((noinline)) M lm_direction(M lm, V (&dz)[6]) {
    M fin = M{};
    for (int i = 0; i < 6; ++i) dz[i] = V{};
    for (int l = 0; l < W; ++l) {
      if (!lm[l]) continue;
      double d[6];
      if (idcol::detail::lm_direction(lm_JtJ[l], lm_g[l], lm_mu[l], d)) {
        fin[l] = -1;
        for (int i = 0; i < 6; ++i) dz[i][l] = d[i];
      }
      lm_mu[l] *= 10.0;
    }
    return fin;
  }
  /// Where lanes that reach an LM step are (where a lane leaves later, the
  /// scalar solver goes on from its last record): with kLm always where
  /// x->lm is set; else before max_iterations, where the scalar solver goes
  /// on from here.
  [[gnu::always_inline]] void lm_record(M rec, int it, const idcol::detail::formulas::RunCounters<LaneNum>& c,
                                        const Pt& p) {
    if (!x || !x->lm || !any(rec)) return;
    if constexpr (kLm)
      record_lm_exit(*x->lm, rec, p, c.it0v + static_cast<double>(it - c.it0), c.iters, c.stalls, c.chord_ok, c.chord_tried);
    else if (it < C.max_iterations)
      record_lm_exit(*x->lm, rec, p, splat(static_cast<double>(it)), c.iters, c.stalls, c.chord_ok, c.chord_tried);
  }
};

/// One Newton run (PairSolver::newton_run, written once as
/// formulas::newton_run) for the lanes in `active`, from z0, with
/// multipliers as given. Adds its steps to iters; leaves each converged
/// lane's answer in `done` and flags it in `conv`, each lane of `cap_lanes`
/// stopped at the step cap (cap > 0) in `capped` (the other lanes run on),
/// and every lane that left the shared path in `bad`.
/// With `x` (a cold run, RunExtras), the run begins at x->start, not at
/// z0; a lane that stalls goes to the scalar solver; a step whose KktLu6
/// fails the fast pivot test is taken by Lu6, or by Lu6 on the equilibrated
/// system, as the scalar solver takes it (without x such a lane goes to the
/// scalar solver); and a run close to a root at max_iterations is extended
/// as the scalar solver extends it.
/// kLm (the cold rows that met an LM step, resumed together: x required):
/// a lane whose line search fails takes the LM step in lanes
/// (formulas::lm_trials) rather than leave; with x->resume every active lane
/// begins at an LM step, at its own iteration; a lane that stalls ends in
/// *x->stalled rather than in `bad`; a lane that reaches max_iterations
/// leaves (no extension); LM steps are recorded only where x->lm is set.
template <bool kLm = false>
inline void newton_run(const idcol::detail::NewtonLaneConsts& C, const Prob& P, const V (&z0)[6], M active, V tau, int cap,
                       M cap_lanes, Done& done_out, V& iters, M& conv, M& capped, M& bad, const RunExtras* x = nullptr) {
  LaneRun<kLm> r(C, P, x, tau, cap, cap_lanes, done_out, conv, capped, bad);
  M b = M{};
  if (x)
    r.buf[0] = *x->start;
  else
    residual(C, P, z0, r.buf[0], b);
  bad |= active & b;
  const M act = active & ~bad;
  idcol::detail::formulas::RunCounters<LaneNum> c;
  c.iters = iters;
  if constexpr (kLm) {
    if (x->resume) {
      c.it0v = x->resume->it0;
      c.iters = sel(act, x->resume->iters, iters);
      c.stalls = x->resume->stalls;
      c.chord_ok = x->resume->chord_ok;
      c.chord_tried = x->resume->chord_tried;
      c.lm_first = act;
    }
  }
  idcol::detail::formulas::newton_run<LaneNum>(r, act, c);
  iters = c.iters;
}

/// W poses loaded and checked (load_pose), and each lane's surrogate
/// problem, its k = |r| / (f_S L) and r_hat (PairSolver::solve and
/// set_problem).
inline Prob problem_of(const idcol::detail::NewtonLaneConsts& C, const double* R_in, const double* p_in, V& k, V3& rhat,
                       M& bad) {
  Prob P;
  V3 p;
  V rn;
  load_pose(R_in, p_in, C.pose_tol2, C.rmax_lo, C.rmax_hi, P.R, p, rn, rhat, bad);
  k = rn / C.fSL;
  P.c1 = scale(splat(C.c1f), rhat);
  P.c2 = scale(splat(C.c2f), rhat);
  P.b1 = {&C.s1, eval_fn(C.s1)};
  P.b2 = {&C.s2, eval_fn(C.s2)};
  return P;
}

/// fill() and the scalar solver's final checks of the lanes converged in d
/// (a lane that fails them is flagged in `bad`), and the answer of every
/// lane stored, W to a row (the caller reads the lanes it accepts): alpha*,
/// x_1 and body 1's gradient at its witness point.
inline void store_answer(const idcol::detail::NewtonLaneConsts& C, const Prob& P, V k, const Done& d, double* alpha_out,
                         double* x_out, double* g1_out, M& bad) {
  const V kL = k * C.L;
  const V alpha = k * d.alpha;
  const V3 x1 = scale(kL, add(V3{d.z[0], d.z[1], d.z[2]}, P.c1));
  const V lam1 = k * d.z[4], lam2 = k * d.z[5];
  bad |= ~answer_ok(alpha, x1, lam1, lam2);
  if (C.check_hessians) bad |= ~finite(d.trace);
  store_v(alpha_out, alpha);
  store_v(x_out, x1.x), store_v(x_out + W, x1.y), store_v(x_out + 2 * W, x1.z);
  store_v(g1_out, d.g1.x), store_v(g1_out + W, d.g1.y), store_v(g1_out + 2 * W, d.g1.z);
}

}  // namespace

namespace idcol::detail {

// Long: the warm lanes' entry point: the predictor's runs, then the last
// contact's, then the answers, as PairSolver::solve's warm path.
void IDCOL_NEWTON_FN(const NewtonLaneConsts& C, const NewtonLaneIO& io) {
  M bad = M{};
  V k;
  V3 rhat;
  const Prob P = problem_of(C, io.R, io.p, k, rhat, bad);
  // The chains' WarmStarts.
  V z[6], zp0[6], zp1[6];
  for (int j = 0; j < 6; ++j) {
    __builtin_memcpy(&z[j], io.z + j * W, sizeof(V));
    __builtin_memcpy(&zp0[j], io.zp + j * W, sizeof(V));
    __builtin_memcpy(&zp1[j], io.zp + (6 + j) * W, sizeof(V));
  }
  V hist, extra;
  for (int i = 0; i < W; ++i) {
    hist[i] = io.history[i];
    extra[i] = io.extrapolate[i] ? 1.0 : 0.0;
    if (!io.valid[i]) bad[i] = -1;  // a cold start: the scalar solver's
  }
  // The predictor (PairSolver::solve).
  const V pms = splat(C.predictor_max_step);
  const V ds = vabs(z[3] - zp0[3]);
  const V3 dxv = {z[0] - zp0[0], z[1] - zp0[1], z[2] - zp0[2]};
  const V dx2 = dot(dxv, dxv), pms2 = pms * pms;  // |dx| against the bound, squared
  bad |= (hist > 0.0) & (near(ds, pms, C.band) | near(dx2, pms2, C.band));
  const M steady = (hist > 0.0) & (ds <= pms) & (dx2 <= pms2);
  const V order = sel(steady, vmin(splat(C.predictor_order), hist), V{});
  V zpred[6];
  for (int j = 0; j < 6; ++j) zpred[j] = sel(order == 1.0, 2.0 * z[j] - zp0[j], 3.0 * (z[j] - zp0[j]) + zp1[j]);
  const M predict = (order > 0.0) & (extra > 0.0) & ~bad;
  V iters = V{};
  M conv = M{}, capped = M{};
  Done d{};
  {
    // One run for every lane: the predictor's (from zpred, at most
    // predictor_steps steps) where the lane predicts, the run from the last
    // contact elsewhere. Both take tau_first, and a lane's steps do not
    // depend on the other lanes', so each lane makes the steps that its own
    // run would make alone, without a second pass over the whole vector
    // where a call mixes lanes that predict with lanes that do not.
    V z0[6];
    for (int j = 0; j < 6; ++j) z0[j] = sel(predict, zpred[j], z[j]);
    z0[4] = vmax(z0[4], splat(1e-12));
    z0[5] = vmax(z0[5], splat(1e-12));
    newton_run(C, P, z0, ~bad, splat(C.tau_first), C.predictor_steps, predict, d, iters, conv, capped, bad);
  }
  // A prediction that missed: the run from the last contact, with tau_restart.
  const M missed = predict & ~conv;
  const M again = missed & ~bad;
  if (any(again)) {
    V z0[6];
    for (int j = 0; j < 6; ++j) z0[j] = z[j];
    z0[4] = vmax(z0[4], splat(1e-12));
    z0[5] = vmax(z0[5], splat(1e-12));
    M unused = M{};
    newton_run(C, P, z0, again, splat(C.tau_restart), 0, M{}, d, iters, conv, unused, bad);
  }
  bad |= ~conv;

  store_answer(C, P, k, d, io.alpha, io.x, io.g1, bad);

  // The WarmStart that PairSolver::solve leaves: WarmStart::extrapolate
  // judged where the predictor was formed, the history shifted.
  V d_pred = V{}, d_last = V{};
  for (int j = 0; j < 4; ++j) {
    d_pred = d_pred + (d.z[j] - zpred[j]) * (d.z[j] - zpred[j]);
    d_last = d_last + (d.z[j] - z[j]) * (d.z[j] - z[j]);
  }
  const V rhs = C.predictor_gain2 * d_last;
  bad |= (order > 0.0) & ~missed & near(d_pred, rhs, C.band);
  const M ok = ~bad;
  const M judged = (order > 0.0) & ok;
  const M good = ~missed & (d_pred < rhs);
  // The WarmStart updated in place where ok.
  for (int j = 0; j < 6; ++j) {
    store_v(io.zp + (6 + j) * W, sel(ok, zp0[j], zp1[j]));
    store_v(io.zp + j * W, sel(ok, z[j], zp0[j]));
    store_v(io.z + j * W, sel(ok, d.z[j], z[j]));
  }
  for (int i = 0; i < W; ++i) {
    io.ok[i] = ok[i] != 0;
    io.iters[i] = static_cast<int>(iters[i]);
    if (judged[i]) io.extrapolate[i] = good[i] != 0;
    if (ok[i]) io.history[i] = io.history[i] + 1 < 2 ? io.history[i] + 1 : 2;
  }
}

/// The derivatives of W converged rows (NewtonFinishIO), as the library
/// forms them from solve()'s result: each lane's problem set up as solve()
/// sets it, z evaluated as every iterate is, Lu6's factorisation of the
/// Jacobian there (PairSolver::finish_at's point and factorisation), then
/// formulas/derivatives.hpp over the lanes. Every step is the scalar
/// code's formula, so each lane's derivatives are the loop's to the bit.
// Long: one straight line of formulas, and the stores of their outputs.
void IDCOL_NEWTON_FINISH_FN(const NewtonLaneConsts& C, const NewtonFinishIO& io) {
  namespace F = idcol::detail::formulas;
  M bad = M{};
  V k;
  V3 rhat;
  const Prob P = problem_of(C, io.R, io.p, k, rhat, bad);
  V z[6];
  for (int j = 0; j < 6; ++j) __builtin_memcpy(&z[j], io.z + j * W, sizeof(V));
  Pt p;
  residual(C, P, z, p, bad);
  V J[6][6];
  jacobian(C, P, p, J);
  Lu6L lu;
  lu.factor_impl(J);
  // SolveResult's alpha, x_1, lambda2 and internal part (PairSolver::fill).
  F::DerivPoint<V> q;
  q.alpha = k * p.alpha;
  q.k = k;
  q.lambda2 = k * z[5];
  q.L = splat(C.L);
  const double rs[6] = {C.inv_sigma1, C.inv_sigma2, C.L, C.L, C.L, 1.0};
  for (int i = 0; i < 6; ++i) q.rs[i] = splat(rs[i]);
  const V kL = k * C.L;
  const V c1[3] = {P.c1.x, P.c1.y, P.c1.z};
  V x1[3], r[3], y1[3], y2[3], g1[3], g2[3], R[9], H1[9], H2[9];  // the matrices by columns (formulas::m3)
  for (int i = 0; i < 3; ++i) {
    x1[i] = kL * (z[i] + c1[i]);
    __builtin_memcpy(&r[i], io.p + i * W, sizeof(V));
    y1[i] = p.y1[i];
    y2[i] = p.y2[i];
    g1[i] = p.e1.g[i];
    g2[i] = p.e2.g[i];
    for (int j = 0; j < 3; ++j) {
      R[i + 3 * j] = P.R(i, j);
      H1[i + 3 * j] = p.e1.h[3 * i + j];
      H2[i + 3 * j] = p.e2.h[3 * i + j];
    }
  }
  q.x1 = x1, q.r = r, q.y1 = y1, q.y2 = y2, q.g1 = g1, q.g2 = g2, q.R = R, q.H1 = H1, q.H2 = H2;
  V G[5][6], dalpha[6], dz[6][6];
  F::g_matrix<LaneNum>(q, G);
  F::alpha_gradient<LaneNum>(q, G, lu, dalpha);
  F::sensitivity<LaneNum>(q, G, lu, dz);
  F::KinematicsDerivs<V> kd;
  F::kinematics_derivatives<LaneNum>(q, dz, kd);
  // The wrench (contact_kinematics' gap and normal, then contact_wrench).
  V n[3];
  F::stable_normalized<LaneNum>(q.g1, n);
  const V gap = F::contact_gap<LaneNum>(F::stable_norm<LaneNum>(q.r), q.alpha);
  F::Wrench<LaneNum> w;
  F::contact_wrench<LaneNum>(q, gap, n, io.stiffness, io.exponent, w);
  F::WrenchDerivs<V> wd{};
  if (any(w.active & w.representable))  // else no lane's is read
    F::wrench_derivatives<LaneNum>(q, dz, n, kd, w, io.stiffness, io.exponent, wd);
  double* const o = io.out;
  auto put = [&](int row, V v) { store_v(o + row * W, v); };
  for (int j = 0; j < 6; ++j) {
    put(kDerivAlpha + j, dalpha[j]);
    put(kDerivGap + j, kd.dgap[j]);
    put(kDerivF1 + j, w.F1[j]);
    put(kDerivF2 + j, w.F2[j]);
    put(kDerivDFn + j, wd.df_n[j]);
    for (int i = 0; i < 3; ++i) {
      put(kDerivNormal + 6 * i + j, kd.dn[i][j]);
      put(kDerivP1 + 6 * i + j, kd.dp1[i][j]);
      put(kDerivP2 + 6 * i + j, kd.dp2[i][j]);
    }
    for (int i = 0; i < 6; ++i) {
      put(kDerivDF1 + 6 * i + j, wd.dF1[i][j]);
      put(kDerivDF2 + 6 * i + j, wd.dF2[i][j]);
    }
  }
  put(kDerivFn, w.f_n);
  put(kDerivActive, sel(w.active, splat(1.0), V{}));
  put(kDerivRepresentable, sel(w.representable, splat(1.0), V{}));
}

}  // namespace idcol::detail
