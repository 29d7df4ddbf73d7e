// The screen of the rows Separated at once, W rows of one pair at a time:
// PairSolver::separated_at_start (solver_impl.hpp) in lanes, its bound the
// scalar one's source (formulas/support_bound.hpp) over LaneNum, so that a
// lane's bound is the loop's to the bit. Included after
// batch_simd_kernel.hpp (LaneNum, load_pose) by each batch_simd_*.cpp,
// which defines IDCOL_SEPARATED_FN (the entry point's name) first.
#if !defined(IDCOL_SEPARATED_FN)
#error "define IDCOL_SEPARATED_FN before including separated_lanes.hpp"
#endif

#include "idcol/detail/formulas/support_bound.hpp"  // templates only: instantiated here over LaneNum

namespace {

/// A body's support function at the unit directions u (one a lane).
inline V support_value(const idcol::detail::SupportShape& s, const V (&u)[3]) {
  namespace F = idcol::detail::formulas;
  using idcol::detail::LaneFamily;
  switch (s.family) {
    case LaneFamily::Superellipsoid: return F::superellipsoid_support_value<LaneNum>(s.ax, s.n, u);
    case LaneFamily::Cylinder: return F::cylinder_support_value<LaneNum>(s.h, s.R, s.n, u);
    case LaneFamily::Cone: return F::cone_support_value<LaneNum>(s.Rb, s.Rt, s.a, s.b, u);
    case LaneFamily::Polytope:
      return F::polytope_support_value<LaneNum>(s.nv, [&](int i, int k) { return s.verts[3 * i + k]; }, u);
    case LaneFamily::Sphere: break;
  }
  return splat(s.R);
}

}  // namespace

namespace idcol::detail {

void IDCOL_SEPARATED_FN(const SeparatedLaneConsts& C, const double* R_in, const double* p_in, double* lower, int* sep) {
  G3 R;
  V3 p, rhat;
  V rn;
  M bad = M{};
  // check_pose with a margin (a lane near its limits is left to the scalar
  // screen), |r| and r_hat as PairSolver forms them.
  load_pose(R_in, p_in, C.pose_tol2, C.rmax_lo, C.rmax_hi, R, p, rn, rhat, bad);
  const V u[3] = {rhat.x, rhat.y, rhat.z};
  const V lo = formulas::alpha_lower_bound<LaneNum>(
      rn, u, R, [&](const V(&v)[3]) { return support_value(C.s1, v); }, [&](const V(&v)[3]) { return support_value(C.s2, v); });
  const M separated = lo > C.alpha_max;
  store_v(lower, lo);
  for (int i = 0; i < W; ++i) sep[i] = bad[i] != 0 ? -1 : separated[i] != 0 ? 1 : 0;
}

}  // namespace idcol::detail
