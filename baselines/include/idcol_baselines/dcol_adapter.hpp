// DCOL on the exact bodies the competitors take (the competitor table's
// "dcol" row; dcol.hpp is the solver itself and knows nothing of core).
#pragma once

#include "idcol/types.hpp"
#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/dcol.hpp"
#include "idcol_baselines/exact_shape.hpp"

namespace idcol::baselines {

/// DCOL's primitive for an exact body: a sphere, an ellipsoid of semi-axes
/// (a, b, c), or the exact polytope {y : a_i.y <= b_i}.
dcol::Primitive to_dcol(const ExactShape& s);

/// Both bodies as DCOL primitives, built once per pair.
class DcolPair {
 public:
  /// Throws std::invalid_argument for invalid options (naming the field).
  DcolPair(const ExactShape& body1, const ExactShape& body2, dcol::Options options = {});
  /// DCOL's proximity with body 1 at the identity and body 2 at X_12.
  dcol::Result solve(const Pose& X_12) const;
  /// The same as a competitor's answer: alpha, intersect = alpha < 1, the
  /// iteration count; `failed` when DCOL did not converge.
  BaselineAnswer answer(const Pose& X_12) const;
  const dcol::Primitive& body1() const { return p1_; }
  const dcol::Primitive& body2() const { return p2_; }

 private:
  dcol::Primitive p1_, p2_;
  dcol::Options opt_;
};

}  // namespace idcol::baselines
