// The iDCOL contact query: the smallest uniform scaling alpha* at which two
// bodies touch, solved by a safeguarded Newton method on the surrogate KKT
// system (Sec. "Numerical Solution Strategy", Algorithm 1).
#pragma once

#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"

namespace idcol {

/// Solve the contact problem between `body1` (at the identity) and `body2`
/// at relative pose X_12 (body 2 in body-1 coordinates). If `warm` is given
/// and valid, the solve starts from it; on success it is overwritten with the
/// new solution, so a sequence of calls warm-starts itself.
///
/// Dispatches once on the pair and runs code specialised for it. Never
/// throws and never allocates; bad poses come back as InvalidInput.
/// `options` are assumed validated (SolverOptions::validate()).
SolveResult solve(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options = {},
                  WarmStart* warm = nullptr, TraceSink* trace = nullptr);

/// The same, with world poses X_W1 and X_W2: X_12 = X_W1^{-1} X_W2.
inline SolveResult solve_world(const Shape& body1, const Pose& X_W1, const Shape& body2, const Pose& X_W2,
                               const SolverOptions& options = {}, WarmStart* warm = nullptr) {
  return solve(body1, body2, X_W1.inverse() * X_W2, options, warm);
}

/// A contact pair with its own warm-start state: shapes and options are
/// fixed (and validated) at construction, the warm start is the scratch.
class ContactPair {
 public:
  ContactPair(Shape body1, Shape body2, SolverOptions options = {});
  /// Warm-started from the previous successful query (cold the first time).
  SolveResult solve(const Pose& X_12);
  /// Ignores and keeps the warm-start state.
  SolveResult solve_cold(const Pose& X_12) const;
  void reset_warm_start() { warm_.reset(); }
  const Shape& body1() const { return b1_; }
  const Shape& body2() const { return b2_; }
  const SolverOptions& options() const { return opt_; }

 private:
  Shape b1_, b2_;
  SolverOptions opt_;
  WarmStart warm_;
};

}  // namespace idcol
