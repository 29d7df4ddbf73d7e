#include "idcol/broad_phase.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace idcol {

namespace {

/// The one pair test of every method (broad_phase.hpp).
inline bool spheres_overlap(const BoundingSphere& a, const BoundingSphere& b) {
  const double r = a.radius + b.radius;
  return (a.center_W - b.center_W).squaredNorm() <= r * r;
}

/// Leaves of the tree hold at most this many bodies.
constexpr std::int32_t kLeafSize = 4;

}  // namespace

const char* to_string(BroadPhaseMethod m) {
  switch (m) {
    case BroadPhaseMethod::Auto: return "auto";
    case BroadPhaseMethod::AllPairs: return "all_pairs";
    case BroadPhaseMethod::SweepAndPrune: return "sweep_and_prune";
    case BroadPhaseMethod::Tree: return "tree";
  }
  return "unknown";
}

const std::vector<BodyPair>& BroadPhase::find(const std::vector<BoundingSphere>& s) {
  const std::size_t n = s.size();
  if (n > static_cast<std::size_t>(INT32_MAX)) throw std::invalid_argument("BroadPhase::find: more than 2^31 - 1 bodies");
  boxes_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (!s[k].center_W.allFinite())
      throw std::invalid_argument("BroadPhase::find: sphere " + std::to_string(k) + " has a non-finite center");
    if (!(s[k].radius >= 0.0) || !std::isfinite(s[k].radius))
      throw std::invalid_argument("BroadPhase::find: sphere " + std::to_string(k) + " has radius " +
                                  std::to_string(s[k].radius) + " (must be finite and >= 0)");
    // Widened by a relative 1e-12 of the coordinates' size: a pair that
    // passes the sphere test (rounding ~1e-16 relative) always overlaps.
    const Vec3& c = s[k].center_W;
    const double h = s[k].radius + 1e-12 * (s[k].radius + c.cwiseAbs().maxCoeff());
    boxes_[k].lo = c.array() - h;
    boxes_[k].hi = c.array() + h;
  }
  pairs_.clear();
  tests_ = 0;
  BroadPhaseMethod m = method_;
  if (m == BroadPhaseMethod::Auto)
    m = n <= static_cast<std::size_t>(kAllPairsUpTo) ? BroadPhaseMethod::AllPairs : BroadPhaseMethod::Tree;
  switch (m) {
    case BroadPhaseMethod::SweepAndPrune: sweep_and_prune(s); break;
    case BroadPhaseMethod::Tree: tree(s); break;
    default: all_pairs(s); break;
  }
  if (m != BroadPhaseMethod::AllPairs) std::sort(pairs_.begin(), pairs_.end());
  return pairs_;
}

void BroadPhase::all_pairs(const std::vector<BoundingSphere>& s) {
  const std::int32_t n = static_cast<std::int32_t>(s.size());
  for (std::int32_t i = 0; i < n; ++i)
    for (std::int32_t j = i + 1; j < n; ++j)
      if (spheres_overlap(s[i], s[j])) pairs_.push_back({i, j});
  tests_ = static_cast<std::int64_t>(n) * (n - 1) / 2;
}

void BroadPhase::sweep_and_prune(const std::vector<BoundingSphere>& s) {
  const std::int32_t n = static_cast<std::int32_t>(s.size());
  order_.resize(n);
  for (std::int32_t k = 0; k < n; ++k) order_[k] = k;
  std::sort(order_.begin(), order_.end(), [&](std::int32_t a, std::int32_t b) {
    return boxes_[a].lo.x() != boxes_[b].lo.x() ? boxes_[a].lo.x() < boxes_[b].lo.x() : a < b;
  });
  for (std::int32_t a = 0; a < n; ++a) {
    const Box& A = boxes_[order_[a]];
    for (std::int32_t b = a + 1; b < n; ++b) {
      const Box& B = boxes_[order_[b]];
      if (B.lo.x() > A.hi.x()) break;  // sorted by lo.x: no later box reaches A
      ++tests_;
      if (B.lo.y() > A.hi.y() || A.lo.y() > B.hi.y() || B.lo.z() > A.hi.z() || A.lo.z() > B.hi.z()) continue;
      const std::int32_t i = std::min(order_[a], order_[b]), j = std::max(order_[a], order_[b]);
      if (spheres_overlap(s[i], s[j])) pairs_.push_back({i, j});
    }
  }
}

void BroadPhase::tree(const std::vector<BoundingSphere>& s) {
  const std::int32_t n = static_cast<std::int32_t>(s.size());
  order_.resize(n);
  for (std::int32_t k = 0; k < n; ++k) order_[k] = k;
  nodes_.clear();
  if (n == 0) return;
  nodes_.reserve(2 * (n / kLeafSize + 1));
  centres_.resize(3 * static_cast<std::size_t>(n));
  for (std::int32_t k = 0; k < n; ++k)
    for (int d = 0; d < 3; ++d) centres_[3 * k + d] = boxes_[k].lo[d] + boxes_[k].hi[d];
  build(0, n);
  self_overlaps(s);
}

/// The node over order_[first, first + count): its box, and two children
/// split at the median of the centres along the box's longest axis
/// (nth_element: O(count) per level, O(N log N) in all).
std::int32_t BroadPhase::build(std::int32_t first, std::int32_t count) {
  const std::int32_t id = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  Box box{boxes_[order_[first]].lo, boxes_[order_[first]].hi};
  for (std::int32_t k = first + 1; k < first + count; ++k) {
    box.lo = box.lo.cwiseMin(boxes_[order_[k]].lo);
    box.hi = box.hi.cwiseMax(boxes_[order_[k]].hi);
  }
  nodes_[id].box = box;
  nodes_[id].first = first;
  nodes_[id].count = count;
  if (count <= kLeafSize) return id;
  int axis = 0;
  const Vec3 ext = box.hi - box.lo;
  if (ext.y() > ext[axis]) axis = 1;
  if (ext.z() > ext[axis]) axis = 2;
  const std::int32_t half = count / 2;
  auto* b = order_.data() + first;
  const double* c = centres_.data() + axis;
  std::nth_element(b, b + half, b + count, [c](std::int32_t p, std::int32_t q) {
    const double cp = c[3 * p], cq = c[3 * q];
    return cp != cq ? cp < cq : p < q;
  });
  const std::int32_t left = build(first, half);
  const std::int32_t right = build(first + half, count - half);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

namespace {
/// Whether two boxes overlap. Without short-circuits: the six comparisons
/// are independent, and a branch on each mispredicts half the time in a
/// traversal.
template <class Box>
inline bool boxes_overlap(const Box& A, const Box& B) {
  return static_cast<bool>((B.lo.x() <= A.hi.x()) & (A.lo.x() <= B.hi.x()) & (B.lo.y() <= A.hi.y()) &
                           (A.lo.y() <= B.hi.y()) & (B.lo.z() <= A.hi.z()) & (A.lo.z() <= B.hi.z()));
}
}  // namespace

/// Every pair of bodies whose boxes overlap, by one traversal of the tree
/// against itself: a node pair is opened only when their boxes overlap, and
/// a node is paired with itself once (its two children with themselves and
/// with each other), so each pair of leaves is reached at most once.
void BroadPhase::self_overlaps(const std::vector<BoundingSphere>& s) {
  auto leaf_pairs = [&](const Node& a, const Node& b) {
    for (std::int32_t p = a.first; p < a.first + a.count; ++p)
      for (std::int32_t q = (&a == &b ? p + 1 : b.first); q < b.first + b.count; ++q) {
        const std::int32_t i = std::min(order_[p], order_[q]), j = std::max(order_[p], order_[q]);
        ++tests_;
        if (boxes_overlap(boxes_[i], boxes_[j]) && spheres_overlap(s[i], s[j])) pairs_.push_back({i, j});
      }
  };
  stack_.clear();
  stack_.push_back(0);  // (a, b) pairs of node ids, flattened
  stack_.push_back(0);
  while (!stack_.empty()) {
    const std::int32_t b = stack_.back();
    stack_.pop_back();
    const std::int32_t a = stack_.back();
    stack_.pop_back();
    const Node& A = nodes_[a];
    const Node& B = nodes_[b];
    if (a == b) {
      if (A.left < 0) {
        leaf_pairs(A, A);
        continue;
      }
      stack_.insert(stack_.end(), {A.left, A.left, A.right, A.right, A.left, A.right});
      continue;
    }
    ++tests_;
    if (!boxes_overlap(A.box, B.box)) continue;
    if (A.left < 0 && B.left < 0) {
      leaf_pairs(A, B);
      continue;
    }
    // Open the node with more bodies (a leaf cannot be opened).
    if (B.left < 0 || (A.left >= 0 && A.count >= B.count)) {
      stack_.insert(stack_.end(), {A.left, b, A.right, b});
    } else {
      stack_.insert(stack_.end(), {a, B.left, a, B.right});
    }
  }
}

}  // namespace idcol
