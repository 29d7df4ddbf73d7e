// The cold Newton lanes of the SIMD batch path: the cold solve of two
// bodies of LaneShape families 0-3 (superellipsoids and superelliptic
// cylinders with an integer exponent, smooth truncated cones, smooth
// polytopes) for W poses at once.
//
// Included after newton_lanes_kernel.hpp (whose evaluations, residual,
// Newton run and KktLu6 it uses) by one translation unit per instruction
// set, which defines IDCOL_NEWTON_COLD_FN (the entry point's name).
// Internal linkage throughout, and only plain data from outside
// (batch_simd_abi.hpp), as for the other kernels.
//
// A lane repeats PairSolver::solve without a warm start on its row up to the
// end of the first Newton run: cold() with its first start, support_guess
// (boundary_on_ray / radial_extent of each body: 1/psi(u) for a superquadric,
// two Newton steps along the ray from the outer radius for a cone, the exact
// face the ray leaves through for a polytope; the two plane offers with each
// family's support_point (a polytope's: the mean of the vertices that reach its
// support), alpha clamped to the trust region, the three candidate points
// evaluated with kkt_residual and init_lambda and ranked by merit:
// formulas::kkt_merit and rank_starts, the scalar solver's own), then
// newton_run from the best candidate as evaluated there, with the first run's
// tau and the stall exit of two homogeneous bodies (PairSolver::stall_exit_; a
// pair with a cone or a polytope has none), its Lu6 and equilibrated steps and
// its extension past the iteration limit (RunExtras). Every value that reaches
// the answer is formed in the scalar code's order of operations, so that the
// answer is the scalar solver's to the bit. A lane that would leave that path
// (no plane offer, a candidate whose merit is not finite, a stall, an LM step,
// the iteration limit, a spurious root, a failed final check, the Hessians'
// traces of a pair with a cone or a polytope not finite) goes to the scalar
// solver. (The merits are the scalar solver's bits, so no ranking needs a
// band.) A lane bound for an LM step (a failed line search, or no
// Newton direction) leaves with where it left the run (ColdResume): W such
// rows go on together in the resumed lanes at the end of this file, and the
// others are resumed there by the scalar solver.
// (The plane offers, the clamps, the radial extents, the cone's choice of
// end disc, the polytope's face on the ray and its vertices at the support
// are compared on the scalar solver's own bits, so no rounding can turn
// those decisions.)

#if !defined(IDCOL_NEWTON_COLD_FN)
#error "define IDCOL_NEWTON_COLD_FN before including newton_lanes_cold.hpp"
#endif

namespace {

/// R^T v as Eigen forms it: (t0 + t1) + t2 in every row.
inline V3 mul_t(const G3& R, const V3& v) {
  return {(R.m[0] * v.x + R.m[3] * v.y) + R.m[6] * v.z, (R.m[1] * v.x + R.m[4] * v.y) + R.m[7] * v.z,
          (R.m[2] * v.x + R.m[5] * v.y) + R.m[8] * v.z};
}

/// boundary_on_ray of a homogeneous body (radial_extent): the boundary
/// point p = rho u along the unit u, rho = 1/psi(u) clamped to the radii,
/// and the gradient n of phi at u (the normal there).
__attribute__((always_inline))
inline void ray_point_sq(const LaneBody& s, const idcol::detail::NewtonColdShape& b, const V3& u, V3& p, V3& n, M& bad) {
  Eval e;
  s.eval(u, e, bad);
  n = e.g;
  p = scale(idcol::detail::formulas::homogeneous_extent<LaneNum>(e.phi, b.inner, b.outer), u);
}

/// boundary_on_ray of the smooth truncated cone (radial_extent of a
/// LogSumExp body): two Newton steps along u from the outer radius,
/// rho <- clamp(rho - phi / (u.grad), inner, outer), each from a full
/// SmoothTruncatedCone::eval at rho u; a lane whose u.grad is not positive
/// or whose phi is not finite stops (its rho stays). n is the gradient at
/// the last point the lane evaluated, the stopping point included. Every
/// decision is taken on the scalar solver's own bits.
__attribute__((always_inline))
inline void ray_point_cone(const idcol::detail::LaneShape& s, const idcol::detail::NewtonColdShape& b, const V3& u, V3& p,
                           V3& n, M& bad) {
  V g[3];
  const V rho = idcol::detail::formulas::newton_extent<LaneNum>(u, b.inner, b.outer, g, [&](const V (&y)[3], V& phi, V (&gy)[3]) {
    Eval e;
    eval_cone(s, V3{y[0], y[1], y[2]}, e, bad);
    phi = e.phi;
    for (int k = 0; k < 3; ++k) gy[k] = e.g[k];
  });
  n = {g[0], g[1], g[2]};
  p = scale(rho, u);
}

__attribute__((always_inline))
inline void ray_point(const LaneBody& body, const idcol::detail::NewtonColdShape& b, const V3& u, V3& p, V3& n, M& bad) {
  if (body.s->family == idcol::detail::LaneFamily::Cone)
    ray_point_cone(*body.s, b, u, p, n, bad);
  else
    ray_point_sq(body, b, u, p, n, bad);
}

/// superquadric_support<N> (shapes.cpp): the support point of the unit
/// superquadric for the scaled direction v. Lanes with v = 0 are flagged.
template <int N>
inline void sq_support(const idcol::detail::LaneShape& s, const V (&v)[N], V (&w)[N], M& bad) {
  idcol::detail::formulas::superquadric_support<LaneNum, N>(Expo<0>(s), v, w, bad);
}

/// SmoothTruncatedCone::support_point: the rim point of the end disc that
/// reaches the frustum's support (the disc's centre along the axis).
__attribute__((always_inline))
inline V3 cone_support(const idcol::detail::LaneShape& s, const idcol::detail::NewtonColdShape& b, const V3& u) {
  V p[3];
  idcol::detail::formulas::cone_support<LaneNum>(s.cone.Rb, b.Rt, s.cone.a, s.cone.b, u, p);
  return {p[0], p[1], p[2]};
}

/// Superellipsoid::support_point, SuperellipticCylinder::support_point (at
/// the body's own exponent), SmoothTruncatedCone::support_point and
/// Sphere::support_point (R u).
__attribute__((always_inline))
inline V3 support_point(const idcol::detail::LaneShape& s, const idcol::detail::NewtonColdShape& b, const V3& u, M& bad) {
  if (s.family == idcol::detail::LaneFamily::Cone) return cone_support(s, b, u);
  if (s.family == idcol::detail::LaneFamily::Sphere) return scale(splat(s.R), u);
  if (s.family == idcol::detail::LaneFamily::Superellipsoid) {
    const V v[3] = {b.ax[0] * u.x, b.ax[1] * u.y, b.ax[2] * u.z};
    V w[3];
    sq_support<3>(s, v, w, bad);
    return {b.ax[0] * w[0], b.ax[1] * w[1], b.ax[2] * w[2]};
  }
  const V wr = lane_hypot_any(u.y, u.z);
  const V v[2] = {s.h * u.x, s.R * wr};
  V p[2];
  sq_support<2>(s, v, p, bad);
  const V radial = sel(wr > 0.0, (s.R * p[1]) / wr, V{});
  return {s.h * p[0], radial * u.y, radial * u.z};
}

/// boundary_on_ray of the smooth polytope (LaneFamily::Polytope): the exact
/// face through which the ray along u leaves P, the first face i of the
/// largest c_i = (a_i . u) / b_i > 0, found from the face block as the
/// scalar solver's loop over the half-spaces finds it (the padding faces
/// give c = 0, which never wins); p = u / c_i, n = a_i. Each c_i is the
/// scalar solver's own bits, so the choice is its choice. A lane with no
/// face (the scalar solver's radial_extent follows: only for a u that is
/// not finite) is flagged.
__attribute__((always_inline))
inline void poly_ray_point(const idcol::detail::LaneShape& s, const V3& u, V3& p, V3& n, M& bad) {
  const int m = s.poly.m4;
  const double* ax = s.poly.faces;
  const double* ay = ax + m;
  const double* az = ay + m;
  const double* b = az + m;
  V pp[3], nn[3];
  const M found = idcol::detail::formulas::polytope_exit_face<LaneNum>(
      m, [&](int i, int k) { return (k == 0 ? ax : k == 1 ? ay : az)[i]; }, [&](int i) { return b[i]; }, u, pp, nn);
  bad |= ~found;
  p = {pp[0], pp[1], pp[2]};
  n = {nn[0], nn[1], nn[2]};
}

/// SmoothPolytope::support_point: the mean of the vertices v whose u.v
/// reaches the support h = max u.v to within NewtonColdShape::vtol (1e-9
/// of the outer radius), summed in the vertex list's order and divided by
/// their count. The products, h and the test are the scalar solver's own
/// bits. Lanes with no such vertex (u not finite) are flagged.
__attribute__((always_inline)) inline V3 poly_support(const idcol::detail::NewtonColdShape& b, const V3& u, M& bad) {
  V q[3];
  idcol::detail::formulas::polytope_support<LaneNum>(b.nv, [&](int i, int k) { return b.verts[3 * i + k]; }, b.vtol, u, q, bad);
  return {q[0], q[1], q[2]};
}

/// boundary_on_ray and support_point of each family the cold lanes take:
/// the polytope's (above), else ray_point's and support_point's.
__attribute__((always_inline))
inline void cold_ray_point(const LaneBody& body, const idcol::detail::NewtonColdShape& b, const V3& u, V3& p, V3& n, M& bad) {
  if (body.s->family == idcol::detail::LaneFamily::Polytope) return poly_ray_point(*body.s, u, p, n, bad);
  ray_point(body, b, u, p, n, bad);
}
__attribute__((always_inline))
inline V3 cold_support_point(const idcol::detail::LaneShape& s, const idcol::detail::NewtonColdShape& b, const V3& u, M& bad) {
  if (s.family == idcol::detail::LaneFamily::Polytope) return poly_support(b, u, bad);
  return support_point(s, b, u, bad);
}

/// init_lambda (PairSolver): the multipliers of eq:guess at a point that
/// kkt_residual evaluated, and the rows of F that they enter.
__attribute__((always_inline)) inline void init_lambda(const idcol::detail::NewtonLaneConsts& C, const Prob& P, Pt& p) {
  idcol::detail::formulas::kkt_init_lambda<LaneNum>(C.L, P.c1, P.c2, p);
}

/// support_guess of W rows: the three candidate starts, each evaluated
/// (kkt_residual, init_lambda), and their ranking by merit
/// (formulas::kkt_merit, rank_starts: the scalar solver's own). A lane with
/// a merit that is not finite goes to `bad` (the scalar solver skips that
/// start, so its spares would differ).
__attribute__((always_inline)) inline void cold_candidates(const idcol::detail::NewtonColdConsts& CC, const Prob& P,
                                                           const V3& rhat, Pt (&cand)[3], Ranking& rank, M& bad) {
  const idcol::detail::NewtonLaneConsts& C = CC.base;
  // support_guess: each body's boundary point on the line of centres.
  const V3 rS = scale(splat(C.L), add(P.c1, P.c2));
  const V3 m2 = mul_t(P.R, rhat);
  const V3 d2 = {-m2.x, -m2.y, -m2.z};
  V3 p1, n1, p2, n2;
  cold_ray_point(P.b1, CC.b1, rhat, p1, n1, bad);
  cold_ray_point(P.b2, CC.b2, d2, p2, n2, bad);
  // The best plane and its three starts: the scalar solver's formulas
  // (formulas::support_plane, support_starts). A lane whose normal is zero
  // is flagged, and so is one with no plane: the ray guess follows, the
  // scalar solver's.
  V best, q1[3], q2[3];
  auto support = [&](const idcol::detail::LaneShape& sh, const idcol::detail::NewtonColdShape& b) {
    return [&sh, &b, &bad](const V (&u)[3], V (&a)[3]) {
      const V3 q = cold_support_point(sh, b, V3{u[0], u[1], u[2]}, bad);
      a[0] = q.x, a[1] = q.y, a[2] = q.z;
    };
  };
  idcol::detail::formulas::support_plane<LaneNum>(P.R, rS, p1, n1, p2, n2, support(C.s1, CC.b1), support(C.s2, CC.b2),
                                                  best, q1, q2, bad);
  bad |= ~(best > 0.0) | ~finite(best);
  V alpha0 = sel(best < CC.exp_lo, splat(CC.exp_lo), sel(CC.exp_hi < best, splat(CC.exp_hi), best));  // std::clamp
  V s0;
  for (int l = 0; l < W; ++l) s0[l] = __builtin_log(alpha0[l]);
  V xa[3][3];
  idcol::detail::formulas::support_starts<LaneNum>(P.R, rS, alpha0, q1, q2, xa);
  const V3 xs[3] = {{xa[0][0], xa[0][1], xa[0][2]}, {xa[1][0], xa[1][1], xa[1][2]}, {xa[2][0], xa[2][1], xa[2][2]}};
  // Each candidate evaluated (kkt_residual, init_lambda) and ranked by
  // merit; the best is the run's start, evaluated.
  V mer[3];
  for (int c = 0; c < 3; ++c) {
    V z[6] = {xs[c].x / C.L - P.c1.x, xs[c].y / C.L - P.c1.y, xs[c].z / C.L - P.c1.z, s0, V{}, V{}};
    residual(C, P, z, cand[c], bad);
    init_lambda(C, P, cand[c]);
    mer[c] = merit_of(cand[c]);
    bad |= ~finite(mer[c]);
  }
  rank = idcol::detail::formulas::rank_starts<LaneNum>(mer);
}

/// The candidate that index k names, lane by lane.
__attribute__((always_inline)) inline Pt candidate(const Pt (&cand)[3], M k) {
  Pt p = cand[0];
  take(k == 1, cand[1], p);
  take(k == 2, cand[2], p);
  return p;
}

/// The W rows' problems (problem_of), their k = |r| / (f_S L),
/// support_guess's candidates with their ranking (cold_candidates), and
/// the best of them, the first run's start.
struct ColdStart {
  Prob P;
  V k;
  Pt cand[3], start;
  Ranking rank;
};
/// The face of F (n rows a column, m faces, rows counted from base) that y
/// at scaling a violates most, by more than worst: the first with the
/// largest violation, one face for W poses, as the scalar search
/// (most_violated) finds it four faces at a time. Its data go to e, found
/// marks the lanes with one, odd those with a face value that is not a
/// number (the two searches could then differ).
__attribute__((always_inline)) inline void lane_faces(const double* Fb, int n, int m, int base, bool body2, const V (&y)[3],
                                                      V a, V& worst, idcol::detail::formulas::SimplexEntering<LaneNum>& e,
                                                      M& found, M& odd) {
  for (int i = 0; i < m; ++i) {
    const V ax = splat(Fb[i]), ay = splat(Fb[n + i]), az = splat(Fb[2 * n + i]), b = splat(Fb[3 * n + i]);
    const V v = ((ax * y[0] + ay * y[1]) + az * y[2]) - b * a;
    odd |= v != v;
    const M up = v > worst;
    worst = sel(up, v, worst);
    e.row = LaneNum::sel_index(up, base + i, e.row);
    e.ax = sel(up, ax, e.ax), e.ay = sel(up, ay, e.ay), e.az = sel(up, az, e.az), e.b = sel(up, b, e.b);
    e.body2 = body2 ? e.body2 | up : e.body2 & ~up;
    found |= up;
  }
}

/// A polytope and an ellipsoid's exact start (detail::exact_start: the
/// active-set method of formulas/polytope_ellipsoid.hpp in the polytope's
/// frame) for the W lanes together: alpha and x (body 1's frame) where a
/// lane has one, none where it has not, bad where a face value is not a
/// number.
__attribute__((always_inline)) inline void cold_ball(const idcol::detail::NewtonColdConsts& CC, const Prob& P,
                                                     const V3& rS, V& a0, V3& x0, M& bad, M& none) {
  namespace F = idcol::detail::formulas;
  const auto& X = CC.ball;
  const V nan = splat(__builtin_nan(""));
  const V rs[3] = {sel(bad, nan, rS.x), sel(bad, nan, rS.y), sel(bad, nan, rS.z)};  // bad lanes: no start to look for
  V R[3][3], C[3][3], r[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = P.R.m[3 * i + j];
  F::ball_frame<LaneNum>(R, rs, X.ax, X.polytope_first != 0, C, r);
  M odd = M{};
  auto scan = [&](const V (&y)[3], V a, V worst, F::SimplexEntering<LaneNum>& e) {
    M found = M{};
    e = F::SimplexEntering<LaneNum>::none();
    lane_faces(X.F, X.n, X.m, 0, false, y, a, worst, e, found, odd);
    return found;
  };
  F::BallState<LaneNum> st;
  int steps = 0;
  M ok = F::ball_contact<LaneNum>(C, r, X.k, scan, st, steps);
  bad |= odd;
  V x[3];
  F::ball_point<LaneNum>(R, rs, st.v, X.polytope_first != 0, x);
  ok &= finite(x[0]) & finite(x[1]) & finite(x[2]);
  none |= ~ok & ~bad;
  a0 = sel(ok, st.a, splat(1.0));
  x0 = {sel(ok, x[0], V{}), sel(ok, x[1], V{}), sel(ok, x[2], V{})};
}

/// The two polytopes' exact start (detail::exact_start: the dual simplex of
/// formulas/polytope_simplex.hpp, then its vertex's move) for the W lanes
/// together: alpha and x where a lane has one, none where it has not (no
/// start, or an optimum that is not unique), bad where a face value is not
/// a number (the scalar search and this one could then differ).
/// The entering face is searched one face for W poses: the first whose
/// violation is the largest, strictly above the threshold, as the scalar
/// search (most_violated) finds it four faces at a time.
__attribute__((always_inline)) inline void cold_simplex(const idcol::detail::NewtonColdConsts& CC, const Prob& P,
                                                        const V3& rS, V& a0, V3& x0, M& bad, M& none) {
  namespace F = idcol::detail::formulas;
  const auto& X = CC.simplex;
  V R[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = P.R.m[3 * i + j];
  const V nan = splat(__builtin_nan(""));
  const V r[3] = {sel(bad, nan, rS.x), sel(bad, nan, rS.y), sel(bad, nan, rS.z)};  // bad lanes: no start to look for
  M odd = M{};  // a face value that is not a number
  auto scan = [&](int it, const V (&x)[3], V a, const V (&u)[3], V worst, F::SimplexEntering<LaneNum>& e) {
    M found = M{};
    e = F::SimplexEntering<LaneNum>::none();
    if (it > 0) lane_faces(X.F[0], X.n[0], X.m[0], 0, false, x, a, worst, e, found, odd);  // at z = 0 body 1's rows all read 0
    lane_faces(X.F[1], X.n[1], X.m[1], X.m[0], true, u, a, worst, e, found, odd);
    return found;
  };
  F::SimplexState<LaneNum> st;
  int pivots = 0;
  const V rr[3] = {r[0], r[1], r[2]};
  const M fail = F::polytope_simplex<LaneNum>(R, rr, X.k, scan, st, pivots);
  const V ratio = F::simplex_finish<LaneNum>(st, X.k.m1, X.soft1, X.soft2, X.step);
  a0 = st.alpha();
  x0 = {st.z[0].a, st.z[0].b, st.z[1].a};
  const M ok = ~fail & (a0 > 0.0) & finite(a0) & finite(x0.x) & finite(x0.y) & finite(x0.z) & (ratio > X.unique);
  bad |= odd;
  none |= ~ok & ~bad;
  a0 = sel(ok, a0, splat(1.0));
  x0 = {sel(ok, x0.x, V{}), sel(ok, x0.y, V{}), sel(ok, x0.z, V{})};
}

/// support_guess's start for two polytopes, or a polytope and an
/// ellipsoid: the exact bodies' contact (cold_simplex, cold_ball: the
/// scalar solver's own templates, in the lanes), evaluated; no candidates,
/// no spares. A lane without a start is marked in none (it takes
/// support_guess's three ranked points, cold_start); one whose start is not
/// finite goes to the scalar solver.
__attribute__((always_inline)) inline void cold_exact(const idcol::detail::NewtonColdConsts& CC, const Prob& P, Pt& start,
                                                      M& bad, M& none) {
  const idcol::detail::NewtonLaneConsts& C = CC.base;
  const V3 rS = scale(splat(C.L), add(P.c1, P.c2));
  V a0 = splat(1.0);
  V3 x0 = {V{}, V{}, V{}};
  if (CC.exact_start == 1)
    cold_simplex(CC, P, rS, a0, x0, bad, none);
  else
    cold_ball(CC, P, rS, a0, x0, bad, none);
  const V alpha0 = sel(a0 < CC.exp_lo, splat(CC.exp_lo), sel(CC.exp_hi < a0, splat(CC.exp_hi), a0));  // std::clamp
  V s0;
  for (int l = 0; l < W; ++l) s0[l] = __builtin_log(alpha0[l]);
  V z[6] = {x0.x / C.L - P.c1.x, x0.y / C.L - P.c1.y, x0.z / C.L - P.c1.z, s0, V{}, V{}};
  M b = M{};
  residual(C, P, z, start, b);
  init_lambda(C, P, start);
  const V m = merit_of(start);
  bad |= ~none & (b | ~finite(m) | (m > 1e300));
}

__attribute__((always_inline)) inline void cold_start(const idcol::detail::NewtonColdConsts& CC,
                                                      const idcol::detail::NewtonColdIO& io, ColdStart& s, M& bad) {
  V3 rhat;
  s.P = problem_of(CC.base, io.R, io.p, s.k, rhat, bad);
  if (CC.exact_start) {
    M none = M{};
    cold_exact(CC, s.P, s.start, bad, none);
    none &= ~bad;
    // No candidates otherwise: with an exact start the spares (s.cand,
    // s.rank) are never read (the resumed lanes' stall branch).
    if (!any(none)) return;
    // Lanes without an exact start (two polytopes whose optimum is not
    // unique, or numerical trouble): the three ranked points, as the scalar
    // solver then takes them.
    const Pt exact = s.start;
    M bc = M{};
    cold_candidates(CC, s.P, rhat, s.cand, s.rank, bc);
    bad |= none & bc;
    s.start = candidate(s.cand, s.rank.best);
    take(~none, exact, s.start);
    return;
  }
  cold_candidates(CC, s.P, rhat, s.cand, s.rank, bad);
  s.start = candidate(s.cand, s.rank.best);
}

/// Lane i's LmExit record into io.lm_*.
__attribute__((always_inline))
inline void write_lm_record(const LmExit& lm, const idcol::detail::NewtonColdIO& io, int i) {
  for (int j = 0; j < 6; ++j) io.lm_z[j * W + i] = lm.z[j][i];
  io.lm_it[i] = static_cast<int>(lm.it[i]);
  io.lm_iters[i] = static_cast<int>(lm.iters[i]);
  io.lm_stalls[i] = static_cast<int>(lm.stalls[i]);
  io.lm_chord[i] = (lm.chord_ok[i] != 0 ? 1 : 0) | (lm.chord_tried[i] != 0 ? 2 : 0);
}

}  // namespace

namespace idcol::detail {

void IDCOL_NEWTON_COLD_FN(const NewtonColdConsts& CC, const NewtonColdIO& io) {
  const NewtonLaneConsts& C = CC.base;
  M bad = M{};
  ColdStart s;
  cold_start(CC, io, s, bad);
  const Prob& P = s.P;

  // The first Newton run from it (PairSolver::cold, run_ = 0).
  V iters = V{};
  M conv = M{}, capped = M{};
  Done d{};
  const V z0[6] = {};
  LmExit lm;
  lm.at = M{};  // the rest is written where a lane leaves (record_lm_exit)
  const RunExtras extras = {&s.start, CC.stall_ratio2, CC.stall_limit, CC.min_pivot, CC.max_iterations_extended,
                            CC.extension_residual * CC.extension_residual, &lm};
  newton_run(C, P, z0, ~bad, splat(C.tau_first), 0, M{}, d, iters, conv, capped, bad, &extras);
  bad |= ~conv;

  store_answer(C, P, s.k, d, io.alpha, io.x, io.g1, bad);
  for (int j = 0; j < 6; ++j) store_v(io.z + j * W, d.z[j]);
  for (int i = 0; i < W; ++i) {
    io.ok[i] = bad[i] == 0;
    io.iters[i] = static_cast<int>(iters[i]);
    io.lm[i] = lm.at[i] != 0;
  }
  if (any(lm.at))  // where the lanes that left at an LM step left (rare)
    for (int i = 0; i < W; ++i) write_lm_record(lm, io, i);
}

}  // namespace idcol::detail

#define IDCOL_COLD_CAT2(a, b) a##b
#define IDCOL_COLD_CAT(a, b) IDCOL_COLD_CAT2(a, b)

namespace idcol::detail {

/// W cold rows that the cold lanes left at an LM step of their first run,
/// resumed together where they left it (io.lm_z and the counters, as the
/// cold lanes wrote them), as PairSolver::resume_at and cold() go on: the
/// LM steps in lanes (newton_run<true>); a run that ends at a stall (two
/// homogeneous bodies) goes on from the other two support-guess points
/// (the spares, best first, with the restarts' tau), as cold() does. A lane
/// that leaves anywhere else goes to the scalar solver, from the last LM
/// step of its first run (the io.lm_* of that step, written over the
/// input), so that the scalar solver makes again only what follows it.
/// The support guess is formed again: the same bits as the first call.
/// Long: the resumed cold lanes follow cold()'s order (the LM run, then the
/// spares) over one set of lane masks.
void IDCOL_COLD_CAT(IDCOL_NEWTON_COLD_FN, _resume)(const NewtonColdConsts& CC, const NewtonColdIO& io) {
  const NewtonLaneConsts& C = CC.base;
  M bad = M{};
  ColdStart s;
  cold_start(CC, io, s, bad);
  const Prob& P = s.P;

  // Where each row left: the start itself (it = 0, support_guess's point
  // with its multipliers) or a later point, evaluated again (the same bits
  // as when the run reached it).
  LmResume rs;
  V zr[6];
  for (int j = 0; j < 6; ++j) __builtin_memcpy(&zr[j], io.lm_z + j * W, sizeof(V));
  for (int i = 0; i < W; ++i) {
    rs.it0[i] = io.lm_it[i];
    rs.iters[i] = io.lm_iters[i];
    rs.stalls[i] = io.lm_stalls[i];
    rs.chord_ok[i] = (io.lm_chord[i] & 1) != 0 ? -1 : 0;
    rs.chord_tried[i] = (io.lm_chord[i] & 2) != 0 ? -1 : 0;
  }
  Pt at = s.start;
  const M later = rs.it0 > 0.0;
  if (any(later)) {
    Pt r;
    M b = M{};
    residual(C, P, zr, r, b);
    bad |= later & b;
    take(later, r, at);
  }
  V iters = V{};
  M conv = M{}, capped = M{}, stalled = M{};
  Done d{};
  const V z0[6] = {};
  LmExit lm;
  lm.at = M{};
  RunExtras ex = {&at, CC.stall_ratio2, CC.stall_limit, CC.min_pivot, CC.max_iterations_extended,
                  CC.extension_residual * CC.extension_residual, &lm};
  ex.resume = &rs;
  ex.stalled = &stalled;
  ex.lm_max_trials = CC.lm_max_trials;
  ex.lm_damping = CC.lm_damping;
  newton_run<true>(C, P, z0, ~bad, splat(C.tau_first), 0, M{}, d, iters, conv, capped, bad, &ex);

  if (CC.exact_start) bad |= stalled;  // no spares: the scalar solver's ray guess follows (never met: polytopes never stall)
  if (any(stalled) && !CC.exact_start) {
    // The spares, best first, as support_guess ranked them.
    const Pt sp[2] = {candidate(s.cand, s.rank.spare[0]), candidate(s.cand, s.rank.spare[1])};
    M go = stalled & ~bad;
    for (int sub = 0; sub < 2 && any(go); ++sub) {
      M again = M{};
      RunExtras ex2 = ex;
      ex2.start = &sp[sub];
      ex2.resume = nullptr;
      ex2.lm = nullptr;  // a later run's LM steps are not where the scalar solver can resume
      ex2.stalled = &again;
      newton_run<true>(C, P, z0, go, splat(C.tau_restart), 0, M{}, d, iters, conv, capped, bad, &ex2);
      go = again;
    }
    bad |= go;  // stalled from both spares: the ray guess follows, the scalar solver's
  }
  bad |= ~conv;

  store_answer(C, P, s.k, d, io.alpha, io.x, io.g1, bad);
  for (int j = 0; j < 6; ++j) store_v(io.z + j * W, d.z[j]);
  for (int i = 0; i < W; ++i) {
    io.ok[i] = bad[i] == 0;
    io.iters[i] = static_cast<int>(iters[i]);
    io.lm[i] = 1;
    if (lm.at[i] != 0) write_lm_record(lm, io, i);  // else its last record is the one it came with
  }
}

}  // namespace idcol::detail

#undef IDCOL_COLD_CAT
#undef IDCOL_COLD_CAT2
