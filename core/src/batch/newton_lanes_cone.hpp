// The smooth truncated cone in the Newton lanes (LaneFamily::Cone):
// SmoothTruncatedCone::eval per lane, at the cone's own beta (the warm path
// evaluates each body at its own sharpness), by the same template the shape
// runs (formulas/shape_eval.hpp, smooth_truncated_cone) over this unit's
// LaneNum. Included by newton_lanes_kernel.hpp inside its translation unit
// (internal linkage, plain data only).
//
// LaneShape::cone, as lane_shape_cone (batch_simd.cpp) fills it:
//   [0] Rb   [1] kappa = (Rt - Rb) / (a + b)   [2] a   [3] b
//   [4] Rfloor = 0.5 min(Rb, Rt)   [5] beta   [6] -1 / a   [7] 1 / b
namespace {

inline void eval_cone(const idcol::detail::LaneShape& s, const V3& y, Eval& e, M& bad) {
  idcol::detail::formulas::smooth_truncated_cone<LaneNum>(s.cone, s.cone_beta, y.x, y.y, y.z, e, bad);
}

}  // namespace
