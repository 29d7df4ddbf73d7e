// The smooth polytope in the Newton lanes (LaneShape family 3):
// SmoothPolytope::eval per lane, as the face kernel the scalar solver runs
// (polytope_kernel.hpp) computes it. Included by newton_lanes_kernel.hpp
// inside its translation unit (internal linkage, plain data only).
//
// Not yet in lanes: every lane is flagged, and lane_shape_polytope
// (batch_simd.cpp) does not offer the family.
namespace {

inline void eval_polytope(const idcol::detail::LaneShape&, const V3&, Eval& e, M& bad) {
  e = Eval{};
  bad = ~M{};
}

}  // namespace
