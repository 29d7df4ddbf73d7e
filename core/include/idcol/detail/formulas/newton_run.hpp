// One Newton run on the KKT system (Algorithm 1's inner loop), written once
// over a number layer N (elementary.hpp) and a run R: the scalar solver
// (PairSolver::newton_run, solver_impl.hpp) instantiates it with double and
// one problem, the Newton lanes (newton_lanes_kernel.hpp) with a vector of W
// doubles and W problems. The control is this one function: the exits and
// their order, the chord step, the Newton step with its fallbacks, the
// Armijo backtracking, the step limits, the iteration limit and its
// extension, the stall count. What differs between the two is what R says:
// where the points live, how a residual is measured, and what an exit does.
//
// Masks say which lanes run (act), and an exit takes lanes out of act. The
// scalar layer's masks are bools, so an exit ends the run and each
// `if (N::any(...))` is the scalar code's branch.
//
// What R provides (the thresholds and limits as member functions, so that
// the scalar solver reads its options where they are):
//   Point, Vec, Mat         a KKT point (kkt.hpp's KktPoint, or the lanes'
//                           Pt), six numbers indexable by [i], a 6x6 matrix
//                           (at(A, i, j))
//   pt, trial, cand         Point pointers at the start: the iterate, the
//                           accepted trial, the candidate. The run rotates
//                           them and writes them back when it returns.
//                           kSharedCand: cand is trial, and stays so (one
//                           problem: a candidate accepted is the trial, one
//                           rejected is not read)
//   residual(z, p, be)      kkt_residual at z into p; be flags lanes whose
//                           evaluation must go to the scalar solver (the
//                           scalar layer never sets it)
//   relres(p, be), tol(), chord_res(), ext_res(), cut()
//                           the convergence measure and its thresholds, in
//                           one unit: the scalar solver's relative residual,
//                           or the lanes' square of it (cut: the factor by
//                           which each block of the extension must cut it)
//   merit(p)                0.5 ||F||^2 (formulas::kkt_merit on both
//                           sides: the same bits, so no merit comparison
//                           needs a band)
//   sum(z, dz, zt), axpy(z, t, dz, zt), negate(F, mF), all_finite(v)
//                           zt = z + dz, zt = z + t dz, mF = -F entry by
//                           entry (each one rounding, as Eigen's
//                           vectorised expressions round), and whether
//                           every entry of v is finite
//   kCheapEnds              an end is a few mask operations, made without
//                           first testing whether any lane ends (the lanes)
//   kBands, near(a, b)
//                           whether a decision within rounding of its
//                           threshold leaves (the lanes: RunEnd::Unsure)
//   limit_step(p, dz)       formulas::limit_step with the run's bounds and tau
//   lo(), hi()              the bounds of s that a genuine root lies within
//   factor(p), fast_ratio(), fast_solve(b, x), fast_pivot()
//                           the Jacobian at p into the structured LU
//                           (KktLu6), its pivot ratio, its solve, and the
//                           ratio above which its step is taken
//   slow_lu()               whether a step whose fast ratio fails is made
//                           here (slow_direction) or leaves (RunEnd::Unsure)
//   jacobian(p), lu6(A, b, x), min_pivot()
//                           the Jacobian at p itself, and Lu6's
//                           factorisation and solve, which returns the
//                           pivot ratio that must pass min_pivot
//   lm_in_run(), lm_max_trials(), lm_begin(lm, p), lm_direction(lm, dz)
//                           whether the LM step (lm_trials) is made here
//                           (else its lanes end LineSearchFailed: the
//                           lanes' warm and first cold runs leave it to the
//                           loop), its trials, J^T J and the first damping
//                           at p, and each trial's step (the mask: finite)
//   lm_record(rec, it, c, p)  where a run that leaves at an LM step may be
//                           resumed (the lanes' ColdResume; the loop: none)
//   take(m, a, b)           b = a in the lanes of m
//   end(m, why, it, res, p), converged(m, it, p),
//   stepped(m, chorded, lm, it, t, stalled, p)
//                           what an exit does, a converged lane, and an
//                           accepted step (the scalar solver's trace)
//   cap(), cap_lanes()      a step cap (> 0) for the lanes of cap_lanes
//   kPerLaneLimit, max_it(), extends(), max_it_ext()
//                           the iteration limit: per lane at c.it0v + k
//                           with no extension, or at the run's iteration
//                           it = c.it0 + k with the extension where extends
//   max_backtracks(), armijo_c(), backtrack_factor()
//   stall_limit(), stall_ratio2()  the stall exit (stall_limit > 0)
//
// Templates only, and no includes but the formulas, for the reason
// elementary.hpp gives.
#pragma once

#include "idcol/detail/formulas/newton.hpp"

namespace idcol::detail::formulas {

/// Why a lane's run ends without a genuine root.
enum class RunEnd {
  NonFinite,         // the merit is not finite
  Spurious,          // a root outside the bounds or with a multiplier <= 0
  Capped,            // the run's step cap (R::cap)
  IterationLimit,    // the iteration limit, not extended
  LineSearchFailed,  // no step cut the merit, LM's neither
  Stalled,           // stall_limit steps in a row barely cut the merit
  Unsure,            // the lanes only: a decision within rounding of its threshold
};

/// A run's counters per lane, set by the caller (a resumed run carries them
/// over) and updated by the run: the steps so far (the caller's total), the
/// stall count, the chord flags (the LU of the last step may serve a chord
/// step; this run has tried its one), the lanes whose first step is an LM
/// step, and the first iteration's number (uniform, it0; per lane, it0v).
template <class N>
struct RunCounters {
  typename N::T iters{}, stalls{}, it0v{};
  typename N::Mask chord_ok{}, chord_tried{}, lm_first{};
  int it0 = 0;
};

/// A root of the KKT residual is the contact (a genuine root) only with both
/// multipliers positive (both bodies' constraints active at a minimum of
/// alpha, eq:kkt_residual) and s = log alpha within [lo, hi]; any other root
/// (the inner tangency of two nested bodies has multipliers of opposite
/// signs) is spurious, and the solver must try another start. The scalar
/// layer stops at the first test that fails.
template <class N, class Z>
[[gnu::always_inline]] inline typename N::Mask genuine_root(const Z& z, double lo, double hi) {
  if constexpr (N::kOneProblem)
    return z[4] > 0.0 && z[5] > 0.0 && z[3] >= lo && z[3] <= hi;
  else
    return (z[4] > 0.0) & (z[5] > 0.0) & (z[3] >= lo) & (z[3] <= hi);
}

/// A trial evaluated into *cand: where no lane has been accepted yet, the
/// candidate becomes the trial point whole (the other lanes' trial is not
/// read); else the lanes of ok take it into *trial.
template <class N, class R, class P>
[[gnu::always_inline]] inline void accept_candidate(R& r, typename N::Mask ok, typename N::Mask acc, P*& trial, P*& cand) {
  if (!N::any(acc)) {
    P* t2 = trial;
    trial = cand;
    cand = t2;
  } else {
    r.take(ok, *cand, *trial);
  }
}

/// The Newton direction where the structured LU's pivot ratio fails its
/// fast test (PairSolver::newton_direction's fallback), for the lanes in
/// `slow`, from the Jacobian J: Lu6 of J, taken where its ratio passes
/// min_pivot; else the system equilibrated (rows, then columns, scaled to
/// unit max norm) and factorised again by Lu6, whose ratio must pass (else
/// there is no direction: `nodir`, an LM step follows); dz = cs .* solve(rs
/// .* -F). Scaling leaves the step unchanged in exact arithmetic and lets
/// the pivot test see the conditioning that is real (a beta = 10^4 plate
/// 10^4 times smaller than its partner gives J singular values 15 orders
/// apart that are a matter of units). A lane with a NaN in J has no
/// direction (the lanes: Unsure). Writes the slow lanes' dz.
template <class N, class R, class Mat, class Vec>
inline void slow_direction(R& r, const Mat& J, typename N::Mask slow, const Vec& mF, Vec& dz, typename N::Mask& nodir,
                           typename N::Mask& unsure) {
  using T = typename N::T;
  using M = typename N::Mask;
  Vec d6;
  const T ratio = r.lu6(J, mF, d6);
  const M plain = ratio > r.min_pivot();
  if constexpr (R::kBands) unsure = unsure | (slow & r.near(ratio, r.min_pivot()));
  const M eq = slow & N::not_(plain | unsure);
  if (N::any(eq)) {
    typename R::Mat Js;
    Vec rs, cs;
    M nan = N::mask(false);
    for (int i = 0; i < 6; ++i) {
      T m = N::abs(R::at(J, i, 0));
      nan = nan | N::not_(m == m);
      for (int j = 1; j < 6; ++j) {
        const T v = N::abs(R::at(J, i, j));
        nan = nan | N::not_(v == v);
        m = N::sel(v > m, v, m);
      }
      rs[i] = N::sel((m > 0.0) & N::finite(m), 1.0 / m, N::splat(1.0));
      for (int j = 0; j < 6; ++j) R::at(Js, i, j) = R::at(J, i, j) * rs[i];
    }
    for (int j = 0; j < 6; ++j) {
      T m = N::abs(R::at(Js, 0, j));
      for (int i = 1; i < 6; ++i) m = N::sel(N::abs(R::at(Js, i, j)) > m, N::abs(R::at(Js, i, j)), m);
      cs[j] = N::sel((m > 0.0) & N::finite(m), 1.0 / m, N::splat(1.0));
      for (int i = 0; i < 6; ++i) R::at(Js, i, j) = R::at(Js, i, j) * cs[j];
    }
    Vec b, w;
    for (int i = 0; i < 6; ++i) b[i] = rs[i] * mF[i];  // -(rs_i F_i), to the bit
    const T re = r.lu6(Js, b, w);
    M unsure_eq = N::mask(false);
    if constexpr (R::kBands) unsure_eq = eq & (nan | r.near(re, r.min_pivot()));
    unsure = unsure | unsure_eq;
    const M fails = eq & (nan | N::not_(re > r.min_pivot()));
    nodir = nodir | (fails & N::not_(unsure_eq));
    for (int i = 0; i < 6; ++i) d6[i] = N::sel(plain, d6[i], cs[i] * w[i]);
  }
  for (int i = 0; i < 6; ++i) dz[i] = N::sel(slow, d6[i], dz[i]);
}

/// The Levenberg-Marquardt step (damped least squares: (J^T J + mu I) dz =
/// -J^T F, mu growing tenfold a trial until the merit falls) for the lanes
/// in `lm`, from p: J^T J, its first damping and each trial's Cholesky step
/// by the loop's compiled code (lm_system.hpp), lane by lane in the lanes
/// (R::lm_begin, R::lm_direction); each trial's step limit, residual and
/// merit test as a Newton trial's. A lane that some trial moves leaves its
/// point in *trial and joins acc (t_used: its step length); a lane that no
/// trial moves stays out of acc; a lane whose test lies within rounding
/// leaves (RunEnd::Unsure, through `leave`).
template <class N, class R, class P, class Leave>
[[gnu::always_inline]] inline void lm_trials(R& r, typename N::Mask lm, const P& p, typename N::T merit,
                                             typename N::Mask& acc, typename N::T& t_used, P*& trial, P*& cand,
                                             const Leave& leave) {
  using T = typename N::T;
  using M = typename N::Mask;
  using Vec = typename R::Vec;
  r.lm_begin(lm, p);
  for (int tr = 0; tr < r.lm_max_trials() && N::any(lm); ++tr) {
    Vec dz;
    const M tri = lm & r.lm_direction(lm, dz);  // mu *= 10 for the next trial, whether or not this one's step is finite
    if (!N::any(tri)) continue;
    const T t = r.limit_step(p, dz);
    Vec zt;
    r.axpy(p.z, t, dz, zt);
    M be = N::mask(false);
    r.residual(zt, *cand, be);
    const T m2 = r.merit(*cand);
    if constexpr (R::kBands) {
      const M unsure = tri & be;
      leave(unsure, RunEnd::Unsure);
      lm = lm & N::not_(unsure);
    }
    const M ok = tri & lm & (m2 < merit);
    accept_candidate<N>(r, ok, acc, trial, cand);
    t_used = N::sel(ok, t, t_used);
    acc = acc | ok;
    lm = lm & N::not_(ok);
  }
}

/// The steps of newton_run, on its local copies of the counters and the
/// point pointers.
///
/// Long: the run's exits in one order for the loop and the lanes over one
/// set of lane masks (which lanes run, leave, converge); split, the masks,
/// points and counters would pass through every piece.
template <class N, class R, class P>
[[gnu::always_inline]] inline void newton_steps(R& r, typename N::Mask act, RunCounters<N>& c, P*& pt, P*& trial,
                                                P*& cand) {
  using T = typename N::T;
  using M = typename N::Mask;
  using Vec = typename R::Vec;
  const M none = N::mask(false);
  T merit = r.merit(*pt);
  T res_lim{};  // the residual at the iteration limit (the extension's)
  for (int k = 0;; ++k) {
    const int it = c.it0 + k;
    // Takes the lanes of m out of the run as `why`, measured at res. The
    // lanes' ends are mask operations, made without a test (kCheapEnds).
    const auto leave = [&](M m, RunEnd why, const T& at) {
      if constexpr (!R::kCheapEnds) {
        if (!N::any(m)) return;
      }
      r.end(m, why, it, at, *pt);
      act = act & N::not_(m);
    };
    leave(act & N::not_(N::finite(merit)), RunEnd::NonFinite, merit);
    if (!N::any(act)) return;
    M unsure = none;
    const T res = r.relres(*pt, unsure);
    if constexpr (R::kBands) leave(act & (unsure | r.near(res, r.tol())), RunEnd::Unsure, res);
    const M done = act & (res <= r.tol());
    if (N::any(done)) {
      const M genuine = genuine_root<N>(pt->z, r.lo(), r.hi());
      const M finished = done & genuine;
      if (N::any(finished)) r.converged(finished, it, *pt);
      leave(done & N::not_(genuine), RunEnd::Spurious, res);
      act = act & N::not_(done);
      if (!N::any(act)) return;
    }
    if (r.cap() > 0 && it >= r.cap()) {
      leave(act & r.cap_lanes(), RunEnd::Capped, res);
      if (!N::any(act)) return;
    }
    if constexpr (R::kPerLaneLimit) {
      leave(act & (c.it0v + static_cast<double>(k) >= static_cast<double>(r.max_it())), RunEnd::IterationLimit, res);
      if (!N::any(act)) return;
    } else if (it >= r.max_it()) {
      // A run that reaches the limit close to a root and still closing in
      // (nearly parallel flat faces make Newton slow, not wrong) goes on to
      // max_it_ext, in blocks of ten steps that must each cut the residual
      // by the factor cut.
      const int max_it = r.max_it();
      M ext = none;
      unsure = none;
      if (r.extends() && it < r.max_it_ext()) {
        if (it == max_it) res_lim = res;
        if constexpr (R::kBands) unsure = act & r.near(res_lim, r.ext_res());
        const M close = act & (res_lim <= r.ext_res());
        ext = close & N::not_(unsure);
        if (it > max_it && (it - max_it) % 10 == 0) {
          const T cut = r.cut() * res_lim;
          if constexpr (R::kBands) unsure = unsure | (ext & r.near(res, cut));
          ext = ext & N::not_(unsure) & (res <= cut);
          res_lim = N::sel(ext, res, res_lim);
        }
      }
      if constexpr (R::kBands) leave(unsure, RunEnd::Unsure, res);
      leave(act & N::not_(ext), RunEnd::IterationLimit, res);
      if (!N::any(act)) return;
    }
    c.iters = N::sel(act, c.iters + 1.0, c.iters);
    M acc = none;      // the lanes whose step is accepted (into *trial)
    M chorded = none;  // ... by the chord step
    T t_used{};        // the accepted step's length
    Vec mF;
    r.negate(pt->F, mF);
    // The last step: close to the root, the factorisation of the last full
    // Newton step serves once more (a chord step). From a relative residual
    // of 1e-7 its error is about the residual times the last step, far
    // below the tolerance, for the cost of one triangular solve instead of
    // a Jacobian and its LU. It is kept only if it reaches the tolerance,
    // so it never adds a step; if it does not, the Newton step is made, and
    // the run makes no second chord attempt. Measured by callgrind on the
    // paper's sweep: 2-5% fewer instructions per cold solve, up to 6% warm.
    const M chord_cand = act & c.chord_ok & N::not_(c.lm_first);
    if constexpr (R::kBands) leave(chord_cand & r.near(res, r.chord_res()), RunEnd::Unsure, res);
    const M ch = chord_cand & act & (res <= r.chord_res());
    if (N::any(ch)) {
      c.chord_ok = c.chord_ok & N::not_(ch);
      c.chord_tried = c.chord_tried | ch;
      Vec dz;
      r.fast_solve(mF, dz);
      const M fin = r.all_finite(dz);
      const T t = r.limit_step(*pt, dz);
      const M tried = ch & fin & (t == 1.0);
      if (N::any(tried)) {
        Vec zt;
        r.sum(pt->z, dz, zt);
        M be = none;
        r.residual(zt, *trial, be);
        const T rr = r.relres(*trial, be);
        if constexpr (R::kBands) leave(tried & (be | r.near(rr, r.tol())), RunEnd::Unsure, res);
        acc = tried & act & (rr <= r.tol());
        chorded = acc;
        t_used = N::sel(acc, N::splat(1.0), t_used);
      }
    }
    // The Newton step, with backtracking.
    M nw = act & N::not_(acc | c.lm_first);
    const M first = act & c.lm_first;
    M rec = none;  // the lanes whose Newton step fails: an LM step follows
    if (N::any(nw) || N::any(first)) {
      r.factor(*pt);
      const T ratio = r.fast_ratio();
      const M fast = ratio > r.fast_pivot();
      unsure = none;
      if constexpr (R::kBands) unsure = nw & r.near(ratio, r.fast_pivot());
      Vec dz;
      r.fast_solve(mF, dz);
      M nodir = none;
      const M slow = nw & N::not_(fast | unsure);
      if (N::any(slow)) {
        if (r.slow_lu())
          slow_direction<N>(r, r.jacobian(*pt), slow, mF, dz, nodir, unsure);
        else
          unsure = unsure | slow;
      }
      if constexpr (R::kBands) leave(unsure, RunEnd::Unsure, res);
      nw = nw & N::not_(unsure | nodir);
      nodir = nodir | (nw & N::not_(r.all_finite(dz)));
      nw = nw & N::not_(nodir);
      M search = nw;
      if (N::any(search)) {
        T t = r.limit_step(*pt, dz);
        for (int bt = 0; bt <= r.max_backtracks() && N::any(search); ++bt) {
          Vec zt;
          r.axpy(pt->z, t, dz, zt);
          M be = none;
          r.residual(zt, *cand, be);
          const T m2 = r.merit(*cand);
          const T rhs = (1.0 - 2.0 * r.armijo_c() * t) * merit;
          if constexpr (R::kBands) {
            unsure = search & be;
            leave(unsure, RunEnd::Unsure, res);
            search = search & N::not_(unsure);
          }
          const M ok = search & (m2 <= rhs);
          accept_candidate<N>(r, ok, acc, trial, cand);
          if constexpr (N::kOneProblem) {
            if (ok) c.chord_ok = t == 1.0 && fast && !c.chord_tried;
          } else {
            c.chord_ok = (ok & (t == 1.0) & fast & N::not_(c.chord_tried)) | (N::not_(ok) & c.chord_ok);
          }
          t_used = N::sel(ok, t, t_used);
          acc = acc | ok;
          search = search & N::not_(ok);
          t = N::sel(search, t * r.backtrack_factor(), t);
        }
      }
      rec = act & (search | nodir);
    }
    const M lm = rec | first;
    if (N::any(lm)) {
      r.lm_record(rec, it, c, *pt);
      if (r.lm_in_run())
        lm_trials<N>(r, lm, *pt, merit, acc, t_used, trial, cand, [&](M m, RunEnd why) { leave(m, why, res); });
    }
    c.lm_first = none;
    leave(act & N::not_(acc), RunEnd::LineSearchFailed, res);
    if (!N::any(act)) return;
    // A step the line search cut to a sliver is as much a stall as an LM
    // step that barely moves: at a stationary point of ||F|| that is not a
    // root the two alternate.
    const T mt = r.merit(*trial);  // the moving lanes' new merit
    M stalled = none;
    if (r.stall_limit() > 0) {
      const T lim = r.stall_ratio2() * merit;
      c.stalls = N::sel(act & (mt > lim), c.stalls + 1.0, T{});
      stalled = act & (c.stalls >= static_cast<double>(r.stall_limit()));
    }
    r.stepped(act, chorded, lm, it, t_used, stalled, *pt);
    // Every lane still running moves: swap, as the scalar solver does.
    P* t2 = pt;
    pt = trial;
    trial = t2;
    if constexpr (R::kSharedCand) cand = trial;
    merit = mt;
    leave(stalled, RunEnd::Stalled, res);
  }
}

/// One Newton run from *r.pt (evaluated, with its multipliers) for the
/// lanes in `act`, its counters in `counters`. Each lane ends at a genuine
/// root (r.converged, at that point) or at an exit (r.end). The counters
/// and the point pointers are copied into locals, which the steps keep in
/// registers, and written back when the run ends.
///
/// Inlined into the caller's run (PairSolver::newton_run, the lanes'
/// newton_run), whose R then lives in registers where it can.
template <class N, class R>
[[gnu::always_inline]] inline void newton_run(R& r, typename N::Mask act, RunCounters<N>& counters) {
  using P = typename R::Point;
  RunCounters<N> c = counters;
  P* pt = r.pt;
  P* trial = r.trial;
  P* cand = R::kSharedCand ? trial : r.cand;  // kSharedCand: the compiler sees one pointer
  newton_steps<N>(r, act, c, pt, trial, cand);
  counters = c;
  r.pt = pt;
  r.trial = trial;
  r.cand = cand;
}

}  // namespace idcol::detail::formulas
