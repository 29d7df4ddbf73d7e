// Basic fixed-size types and the relative pose convention used everywhere.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace idcol {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat6r = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;  // the solver's Jacobian, copied straight into Lu6

/// A rigid transform X_AB = (R_AB, p_AB): a point with coordinates p_B in
/// frame B has coordinates p_A = R_AB * p_B + p_AB in frame A.
///
/// The solver takes the relative pose of body 2 in body 1, X_12 = g1^{-1} g2,
/// which the paper calls g = (R, r).
struct Pose {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();

  static Pose Identity() { return Pose{}; }

  /// X_AC = X_AB * X_BC.
  Pose operator*(const Pose& X_BC) const { return Pose{R * X_BC.R, R * X_BC.p + p}; }
  /// X_BA from X_AB.
  Pose inverse() const { return Pose{R.transpose(), -(R.transpose() * p)}; }
};

/// Result of checking a pose before a solve. Orthonormality and det(R) = +1
/// are checked to `kPoseTolerance` in the Frobenius norm of R^T R - I.
inline constexpr double kPoseTolerance = 1e-9;

enum class PoseCheck { Ok, NonFinite, NotOrthonormal, Reflection };

inline PoseCheck check_pose(const Pose& X) {
  if (!X.R.allFinite() || !X.p.allFinite()) return PoseCheck::NonFinite;
  if ((X.R.transpose() * X.R - Mat3::Identity()).norm() > kPoseTolerance) return PoseCheck::NotOrthonormal;
  if (X.R.determinant() < 0.0) return PoseCheck::Reflection;
  return PoseCheck::Ok;
}

inline const char* to_string(PoseCheck c) {
  switch (c) {
    case PoseCheck::Ok: return "ok";
    case PoseCheck::NonFinite: return "pose has a NaN or Inf entry";
    case PoseCheck::NotOrthonormal: return "rotation is not orthonormal (|R^T R - I|_F > 1e-9)";
    case PoseCheck::Reflection: return "rotation has determinant -1 (a reflection)";
  }
  return "unknown";
}

}  // namespace idcol
