// The smooth truncated cone in the Newton lanes (LaneShape family 2):
// SmoothTruncatedCone::eval per lane. Included by newton_lanes_kernel.hpp
// inside its translation unit (internal linkage, plain data only).
//
// Not yet in lanes: every lane is flagged, and lane_shape_cone
// (batch_simd.cpp) does not offer the family.
namespace {

inline void eval_cone(const idcol::detail::LaneShape&, const V3&, Eval& e, M& bad) {
  e = Eval{};
  bad = ~M{};
}

}  // namespace
