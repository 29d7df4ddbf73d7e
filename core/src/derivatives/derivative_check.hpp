// Pieces shared by the pose derivatives (derivatives.cpp) and the
// shape-parameter derivatives (shape_derivatives.cpp): the co-adjoint that
// carries a wrench between the bodies, and the bookkeeping of a sweep check
// against finite differences. Private to the library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <iomanip>
#include <sstream>

#include "idcol/derivatives.hpp"
#include "idcol/detail/formulas/derivatives.hpp"

namespace idcol::detail {

/// Ad_{X_12}^T: a wrench (moment, force) in frame 1 expressed in frame 2,
/// the moment taken about frame 2's origin.
inline Vec6 coadjoint_T(const Mat3& R, const Vec3& p, const Vec6& F) {
  Vec6 out;
  // Written once with the contact wrench's (formulas/derivatives.hpp); R by columns, as Eigen stores it.
  formulas::coadjoint_t(R.data(), p.data(), F.data(), out.data());
  return out;
}

/// Counts one checked pose of a sweep (after its finite differences were
/// taken) in `rep`: agreement when err <= tolerance; otherwise a flagged or
/// unflagged disagreement with a failure line holding the pose at 17
/// significant digits; the worst error over unflagged poses.
inline void record_checked_pose(DerivativeCheckReport& rep, std::size_t index, const Pose& X, double alpha,
                                const Conditioning& cond, double err, double tolerance) {
  const bool agree = std::isfinite(err) && err <= tolerance;
  if (agree) {
    ++rep.agree;
    rep.min_agreeing_pivot_ratio = std::min(rep.min_agreeing_pivot_ratio, cond.pivot_ratio);
    rep.max_agreeing_sensitivity = std::max(rep.max_agreeing_sensitivity, cond.sensitivity);
  } else {
    if (cond.reliable)
      ++rep.disagree_unflagged;
    else
      ++rep.disagree_flagged;
    std::ostringstream os;
    os << std::setprecision(17) << "pose " << index << " err " << err << " pivot_ratio " << cond.pivot_ratio
       << " sensitivity " << cond.sensitivity << " alpha " << alpha << " R [" << X.R.row(0) << "; " << X.R.row(1)
       << "; " << X.R.row(2) << "] p [" << X.p.transpose() << "]";
    rep.failures.push_back(os.str());
  }
  if (cond.reliable && !(err <= rep.worst_error)) {
    rep.worst_error = err;
    rep.worst_index = static_cast<int>(index);
    rep.worst_pose = X;
    rep.worst_pivot_ratio = cond.pivot_ratio;
  }
}

}  // namespace idcol::detail
