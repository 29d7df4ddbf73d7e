// Free rigid bodies in contact: the equations of motion of the paper's
// multibody example (Sec. "Multibody Collision"), their Jacobian with the
// contact wrenches' derivatives in it, and the bodies' mass properties.
//
// State. Body i has six degrees of freedom in exponential coordinates
// q_i = (theta_i, p_i): its rotation R_i = exp(theta_i~) (theta_i the
// rotation vector, the exponential coordinates of SO(3)) and p_i the world
// position of its frame origin; and its body twist eta_i = (w_i, v_i) (the
// angular and linear velocity in body-i coordinates, v_i that of the frame
// origin). The state of N bodies is y = (q_1, ..., q_N, eta_1, ..., eta_N),
// 12 N numbers. (SE(3)'s own exponential coordinates would carry the
// position through the left Jacobian of the rotation; keeping p_i in the
// world makes the kinematics p_i' = R_i v_i and the linear momentum plain.)
//
// Equations (Newton-Euler in the body frame, wrenches ordered (moment,
// force) like the twists):
//   theta_i' = J_r(theta_i)^{-1} w_i,      p_i' = R_i v_i,
//   G_i eta_i' = ad_{eta_i}^T G_i eta_i + F_i(q),
// G_i the spatial inertia about the frame origin, F_i the sum of the
// contact wrenches on body i in its frame (Scene::body_wrenches). No
// gravity: the total momentum sum_i Ad_{X_Wi^{-1}}^T G_i eta_i (angular about
// the world origin, linear) is constant, since every contact's pair of
// wrenches is equal and opposite.
//
// The chart. theta -> exp(theta~) is singular at |theta| = 2 pi; rechart()
// replaces a rotation vector longer than pi by the shorter one of the same
// rotation, theta (1 - 2 pi / |theta|), so |theta| stays near or below pi.
// The integrator then restarts from the new coordinates
// (StiffOdeSolver::Rechart).
//
// Jacobian. The contact wrenches' derivatives w.r.t. the body twists
// (Contact::dF1, dF2) map to the coordinates by xi_i = B_i dq_i,
// B_i = diag(J_r(theta_i), R_i^T) (a change dtheta moves R by the body-frame
// rotation J_r dtheta; a change dp is R^T dp in the body frame). The
// kinematic and gyroscopic blocks are differentiated in closed form.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "idcol/scene.hpp"
#include "idcol/stiff_ode.hpp"

namespace idcol {

/// A rigid body's mass, centre of mass and rotational inertia.
struct MassProperties {
  double mass = 1.0;
  Vec3 com_B = Vec3::Zero();              // centre of mass, body frame
  Mat3 inertia_com_B = Mat3::Identity();  // rotational inertia about the centre of mass, body axes
  /// The spatial inertia about the frame origin for twists (w, v):
  /// [[I_c - m c~ c~, m c~], [-m c~, m I]], c = com_B.
  Mat6 spatial_inertia() const;
  /// Throws std::invalid_argument naming the field: mass must be finite and
  /// > 0, com_B finite, inertia_com_B symmetric positive definite.
  void validate() const;
};

/// The mass properties of the body phi <= 0 of uniform `density`, by the
/// midpoint rule on `cells`^3 cells of the cube around its outer sphere
/// (each cell's own inertia included). The error is that of the body's
/// boundary cut by the grid: 0.3% on the mass of a sphere at 64 cells
/// (test_rigid_body.cpp compares spheres and ellipsoids with their closed forms).
MassProperties mass_properties(const Shape& shape, double density = 1.0, int cells = 64);

/// R = exp(theta~) (Rodrigues).
Mat3 so3_exp(const Vec3& theta);
/// The right Jacobian J_r(theta) of SO(3): exp((theta + d)~) = exp(theta~)
/// exp((J_r d)~) to first order.
Mat3 so3_right_jacobian(const Vec3& theta);
/// Its inverse, J_r(theta)^{-1} (|theta| < 2 pi).
Mat3 so3_right_jacobian_inverse(const Vec3& theta);
/// d (J_r(theta)^{-1} w) / d theta.
Mat3 so3_right_jacobian_inverse_derivative(const Vec3& theta, const Vec3& w);

/// N free rigid bodies with the contacts of a Scene (above).
class MultibodySystem {
 public:
  using Vector = Eigen::VectorXd;
  using Matrix = Eigen::MatrixXd;

  /// Throws std::invalid_argument if the lists' sizes differ or a mass is bad.
  MultibodySystem(std::vector<Shape> shapes, std::vector<MassProperties> masses, SceneOptions options = {});

  int num_bodies() const { return static_cast<int>(mass_.size()); }
  int state_size() const { return 12 * num_bodies(); }
  const MassProperties& mass(int i) const { return mass_.at(static_cast<std::size_t>(i)); }
  Scene& scene() { return scene_; }
  const Scene& scene() const { return scene_; }

  /// The state of bodies at poses X_W with body twists eta (one each).
  Vector state(const std::vector<Pose>& X_W, const std::vector<Vec6>& eta) const;
  /// Body i's pose and twist in y.
  Pose pose(const Vector& y, int i) const;
  Vec6 twist(const Vector& y, int i) const;
  std::vector<Pose> poses(const Vector& y) const;

  /// y' at y; false when a contact's solve failed (its force is unknown).
  bool rhs(const Vector& y, Vector& ydot);
  /// dy'/dy at y, the contact wrenches' Jacobians from the scene (one
  /// update with derivatives); false as rhs.
  bool jacobian(const Vector& y, Matrix& J);
  /// Every rotation vector longer than pi replaced by the shorter one of
  /// the same rotation; true if one was.
  bool rechart(Vector& y) const;

  /// Total momentum in the world frame: (angular about the world origin,
  /// linear), sum_i Ad_{X_Wi^{-1}}^T G_i eta_i.
  Vec6 momentum(const Vector& y) const;
  /// Total kinetic energy, sum_i eta_i^T G_i eta_i / 2.
  double kinetic_energy(const Vector& y) const;

  /// Counters and clocks over every rhs and jacobian call since the last
  /// reset_counters().
  struct Counters {
    long rhs_calls = 0, jacobian_calls = 0, failed_calls = 0;
    long narrow_rows = 0, active_contacts = 0, newton_iterations = 0;
    long max_active = 0;  // the most active contacts at one call
    double broad_seconds = 0.0, narrow_seconds = 0.0;
    double dynamics_seconds = 0.0;  // everything else in rhs and jacobian
  };
  const Counters& counters() const { return counters_; }
  void reset_counters() { counters_ = Counters{}; }

 private:
  bool update(const Vector& y, bool derivatives);

  std::vector<MassProperties> mass_;
  std::vector<Mat6> G_, G_inv_;
  Scene scene_;
  std::vector<Pose> X_;
  std::vector<Vec6> F_;
  Counters counters_;
};

/// The Newton systems (I - c J) x = b of a MultibodySystem's state, by
/// eliminating the coordinates: q' depends on body i's own q_i and eta_i
/// only, so the blocks J_qq and J_qeta are block diagonal (6 x 6 per body,
/// for any Jacobian of the system, analytical or by differences), and
///   S = I - c J_ee - c^2 J_eq (I - c J_qq)^{-1} J_qe
/// is the 6N x 6N system left for the twists: one LU of half the size (an
/// eighth of the work) and N 6 x 6 inverses. Exact, not an approximation of
/// the dense LU (test_rigid_body.cpp compares the two).
class MultibodyNewtonSolver : public NewtonSystemSolver {
 public:
  explicit MultibodyNewtonSolver(int num_bodies) : n_(num_bodies) {}
  void factorise(double c, const Eigen::MatrixXd& J) override;
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const override;

 private:
  int n_;
  double c_ = 0.0;
  Eigen::MatrixXd Jeq_;                 // J_eta,q (6N x 6N)
  std::vector<Mat6> Aqq_inv_, T_;       // (I - c J_qq)_i^{-1}, and it times (J_q,eta)_i
  Eigen::PartialPivLU<Eigen::MatrixXd> S_;
};

/// One integration of a MultibodySystem by StiffOdeSolver with its
/// MultibodyNewtonSolver and its rechart(): what was asked, what it cost.
struct MultibodyRun {
  StiffOdeStatus status = StiffOdeStatus::Success;
  double t_reached = 0.0;
  double wall_seconds = 0.0;  // the integration alone
  std::vector<double> t;      // 0, then each output time reached
  std::vector<Eigen::VectorXd> y;
  StiffOdeStats ode;
  MultibodySystem::Counters counters;  // over this run
  /// Active contacts at the accepted steps (read from the f evaluation of
  /// each step's last Newton iteration, which converged to its state).
  long step_contacts_max = 0;
  double step_contacts_mean = 0.0;
};

/// Integrates the system from y0 at t = 0 to t_end, reporting y at
/// `outputs` (increasing, in (0, t_end]); with the system's Jacobian
/// (`analytic_jacobian`) or forward differences. Resets the system's
/// counters and its scene's warm starts first.
MultibodyRun simulate(MultibodySystem& system, const Eigen::VectorXd& y0, double t_end,
                      const std::vector<double>& outputs, const StiffOdeOptions& options = {},
                      bool analytic_jacobian = true);

}  // namespace idcol
