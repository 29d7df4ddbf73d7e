// The broad phase of a scene of many bodies: the pairs whose bounding
// spheres overlap, the only pairs that can touch (Sec. "Differentiable
// Contact Physics": "a broad-phase filter based on outer-sphere bounds").
//
// Each body is bounded by the certified outer sphere of its shape
// (radii().outer, about the shape's frame origin) at its world pose. Three
// methods find the same pairs, every one of them, in the same order:
//
//  - AllPairs: every pair tested, N (N - 1) / 2 tests. The paper's filter;
//    the fastest below a few dozen bodies.
//  - SweepAndPrune: the spheres' bounding boxes sorted along x, each box
//    tested against the boxes whose x-interval overlaps its own. O(N log N)
//    to sort, plus one test per pair overlapping in x: in a 3-D box of
//    bodies at constant density that is ~N^(2/3) pairs per body, so the
//    cost per body grows with N (measured: results/multibody_scaling.json).
//  - Tree: a bounding-volume hierarchy of the boxes, rebuilt at every call
//    by median splits (O(N log N)), traversed against itself (a pair of
//    nodes opened only where their boxes overlap): with a bounded number of
//    neighbours per body, O(N log N) to build and about O(N) to traverse,
//    whatever the layout.
//
// Auto takes AllPairs up to kAllPairsUpTo (192) bodies and Tree above.
//
// The pair test is the same in every method: bodies i < j are a candidate
// when |c_i - c_j|^2 <= (r_i + r_j)^2 (touching spheres count). The boxes
// only skip pairs that cannot pass it (they are widened by a relative 1e-12,
// far beyond the rounding of the test), so the three lists are equal
// (test_broad_phase.cpp checks this against AllPairs on random scenes).
#pragma once

#include <cstdint>
#include <vector>

#include "idcol/types.hpp"

namespace idcol {

/// A bounding sphere in world coordinates.
struct BoundingSphere {
  Vec3 center_W = Vec3::Zero();
  double radius = 0.0;
};

/// A candidate pair of bodies, i < j (indices into the list of spheres).
struct BodyPair {
  std::int32_t i = 0;
  std::int32_t j = 0;
  bool operator==(const BodyPair& o) const { return i == o.i && j == o.j; }
  bool operator<(const BodyPair& o) const { return i != o.i ? i < o.i : j < o.j; }
};

enum class BroadPhaseMethod { Auto, AllPairs, SweepAndPrune, Tree };

/// "auto", "all_pairs", "sweep_and_prune", "tree".
const char* to_string(BroadPhaseMethod m);

/// Finds the candidate pairs; keeps its scratch between calls, so that a
/// call in a simulation's loop allocates only when the scene grows.
class BroadPhase {
 public:
  /// Auto's switch from AllPairs to Tree: below it the N (N - 1) / 2 sphere
  /// tests cost less than building and traversing the tree (measured on
  /// spheres of radius 0.3-0.6 on a unit lattice, 2-core Xeon VM: all pairs
  /// 10.8 us against the tree's 15.1 us at 128 bodies, 40.0 against 36.8 at
  /// 256). Sweep and prune, faster than both from about 50 to 400 bodies
  /// there, is not Auto's choice: its cost depends on the layout (bodies
  /// lined up along x make it quadratic), the tree's does not.
  static constexpr int kAllPairsUpTo = 192;

  explicit BroadPhase(BroadPhaseMethod method = BroadPhaseMethod::Auto) : method_(method) {}

  /// The pairs i < j whose spheres overlap, sorted by (i, j). Throws
  /// std::invalid_argument naming the sphere if a center is not finite or
  /// a radius is negative or not finite. The reference stays valid until
  /// the next call.
  const std::vector<BodyPair>& find(const std::vector<BoundingSphere>& spheres);

  BroadPhaseMethod method() const { return method_; }
  /// Box tests made by the last call (AllPairs: sphere tests): the work of
  /// the method, for benchmarks.
  std::int64_t tests() const { return tests_; }

 private:
  struct Box {
    Vec3 lo, hi;
  };
  struct Node {
    Box box;
    std::int32_t left = -1, right = -1;  // children, or -1 for a leaf
    std::int32_t first = 0, count = 0;   // a leaf's items: order_[first, first + count)
  };
  void all_pairs(const std::vector<BoundingSphere>& s);
  void sweep_and_prune(const std::vector<BoundingSphere>& s);
  void tree(const std::vector<BoundingSphere>& s);
  std::int32_t build(std::int32_t first, std::int32_t count);
  void self_overlaps(const std::vector<BoundingSphere>& s);

  BroadPhaseMethod method_;
  std::vector<BodyPair> pairs_;
  std::vector<Box> boxes_;
  std::vector<std::int32_t> order_;
  std::vector<double> centres_;  // twice each box's centre, xyz per body: the tree's split keys
  std::vector<Node> nodes_;
  std::vector<std::int32_t> stack_;
  std::int64_t tests_ = 0;
};

}  // namespace idcol
