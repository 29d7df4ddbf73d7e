#include "idcol/rigid_body.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace idcol {

namespace {

constexpr double kPi = 3.14159265358979323846;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// ad_eta^T mu for eta = (w, v), mu = (mu_w, mu_v): (mu_w x w + mu_v x v, mu_v x w).
Vec6 coadjoint_action(const Vec6& eta, const Vec6& mu) {
  Vec6 r;
  r.head<3>() = mu.head<3>().cross(eta.head<3>()) + mu.tail<3>().cross(eta.tail<3>());
  r.tail<3>() = mu.tail<3>().cross(eta.head<3>());
  return r;
}

/// Ad_{X_WB^{-1}}^T F_B: a wrench (or momentum) F_B = (m, f) of body
/// coordinates about the body origin, in world coordinates about the world
/// origin: (R m + p x (R f), R f).
Vec6 body_to_world_wrench(const Pose& X_W, const Vec6& F_B) {
  const Vec3 f = X_W.R * F_B.tail<3>();
  Vec6 out;
  out.head<3>() = X_W.R * F_B.head<3>() + X_W.p.cross(f);
  out.tail<3>() = f;
  return out;
}

}  // namespace

Mat6 MassProperties::spatial_inertia() const {
  const Mat3 C = skew(com_B);
  Mat6 G;
  G.topLeftCorner<3, 3>() = inertia_com_B - mass * C * C;
  G.topRightCorner<3, 3>() = mass * C;
  G.bottomLeftCorner<3, 3>() = -mass * C;
  G.bottomRightCorner<3, 3>() = mass * Mat3::Identity();
  return G;
}

void MassProperties::validate() const {
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw std::invalid_argument("MassProperties: field 'mass' must be finite and > 0, got " + std::to_string(mass));
  if (!com_B.allFinite()) throw std::invalid_argument("MassProperties: field 'com_B' has a NaN or Inf entry");
  if (!inertia_com_B.allFinite()) throw std::invalid_argument("MassProperties: field 'inertia_com_B' has a NaN or Inf entry");
  if ((inertia_com_B - inertia_com_B.transpose()).norm() > 1e-12 * inertia_com_B.norm())
    throw std::invalid_argument("MassProperties: field 'inertia_com_B' is not symmetric");
  const double lmin = Eigen::SelfAdjointEigenSolver<Mat3>(inertia_com_B).eigenvalues().minCoeff();
  if (!(lmin > 0.0))
    throw std::invalid_argument("MassProperties: field 'inertia_com_B' is not positive definite (smallest eigenvalue " +
                                std::to_string(lmin) + ")");
}

MassProperties mass_properties(const Shape& shape, double density, int cells) {
  if (!(density > 0.0) || !std::isfinite(density))
    throw std::invalid_argument("mass_properties: density must be finite and > 0, got " + std::to_string(density));
  if (cells < 4 || cells > 1024)
    throw std::invalid_argument("mass_properties: cells must be in 4..1024, got " + std::to_string(cells));
  const double r = radii(shape).outer;
  const double a = 2.0 * r / cells, dv = a * a * a;
  double m = 0.0;
  Vec3 s1 = Vec3::Zero();
  Mat3 s2 = Mat3::Zero();  // sum of y y^T over the cells inside
  ShapeEval e;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < cells; ++k) {
        const Vec3 y(-r + (i + 0.5) * a, -r + (j + 0.5) * a, -r + (k + 0.5) * a);
        eval(shape, y, e);
        if (!(e.phi <= 0.0)) continue;
        m += 1.0;
        s1 += y;
        s2 += y * y.transpose();
      }
  if (m == 0.0) throw std::invalid_argument("mass_properties: no cell centre inside the body; use more cells");
  MassProperties p;
  p.mass = density * dv * m;
  p.com_B = s1 / m;
  // Second moment about the centre of mass, each cell a cube of side a
  // (its own second moment a^2/12 per axis); inertia = tr(S) I - S.
  const Mat3 S = density * dv * (s2 - m * p.com_B * p.com_B.transpose()) + p.mass * a * a / 12.0 * Mat3::Identity();
  p.inertia_com_B = S.trace() * Mat3::Identity() - S;
  p.inertia_com_B = 0.5 * (p.inertia_com_B + p.inertia_com_B.transpose()).eval();
  return p;
}

Mat3 so3_exp(const Vec3& theta) {
  const double t2 = theta.squaredNorm(), t = std::sqrt(t2);
  const Mat3 W = skew(theta);
  double a, b;  // sin t / t, (1 - cos t) / t^2
  if (t < 1e-4) {
    a = 1.0 - t2 / 6.0;
    b = 0.5 - t2 / 24.0;
  } else {
    a = std::sin(t) / t;
    b = (1.0 - std::cos(t)) / t2;
  }
  return Mat3::Identity() + a * W + b * W * W;
}

Mat3 so3_right_jacobian(const Vec3& theta) {
  const double t2 = theta.squaredNorm(), t = std::sqrt(t2);
  const Mat3 W = skew(theta);
  double b, c;  // (1 - cos t) / t^2, (t - sin t) / t^3
  if (t < 1e-3) {
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    c = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    b = (1.0 - std::cos(t)) / t2;
    c = (t - std::sin(t)) / (t2 * t);
  }
  return Mat3::Identity() - b * W + c * W * W;
}

namespace {
/// c(t) = 1/t^2 - (1 + cos t) / (2 t sin t) = (1 - (t/2) cot(t/2)) / t^2 of
/// J_r^{-1} = I + W/2 + c W^2, and c'(t) / t. Below t = 0.2 their series
/// (from x cot x = 1 - x^2/3 - x^4/45 - 2 x^6/945 - x^8/4725 - ...), whose
/// first omitted term is below 1e-13 of the value there; above, the closed
/// form, which there loses at most ~1e-10 to cancellation.
void jr_inv_coefficients(double t, double& c, double& dc_over_t) {
  const double t2 = t * t;
  if (t < 0.2) {
    c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2 * t2 * t2 / 1209600.0;
    dc_over_t = 1.0 / 360.0 + t2 / 7560.0 + t2 * t2 / 201600.0;
    return;
  }
  const double cot = 1.0 / std::tan(0.5 * t), csc2 = 1.0 + cot * cot;
  c = 1.0 / t2 - cot / (2.0 * t);
  dc_over_t = (-2.0 / (t2 * t) + csc2 / (4.0 * t) + cot / (2.0 * t2)) / t;
}
}  // namespace

Mat3 so3_right_jacobian_inverse(const Vec3& theta) {
  double c, dc;
  jr_inv_coefficients(theta.norm(), c, dc);
  const Mat3 W = skew(theta);
  return Mat3::Identity() + 0.5 * W + c * W * W;
}

Mat3 so3_right_jacobian_inverse_derivative(const Vec3& theta, const Vec3& w) {
  // J_r^{-1} w = w + theta x w / 2 + c(t) theta x (theta x w), and
  // theta x (theta x w) = theta (theta . w) - w |theta|^2.
  double c, dc;
  jr_inv_coefficients(theta.norm(), c, dc);
  const Vec3 ttw = theta * theta.dot(w) - w * theta.squaredNorm();
  const Mat3 dttw = theta.dot(w) * Mat3::Identity() + theta * w.transpose() - 2.0 * w * theta.transpose();
  return -0.5 * skew(w) + dc * ttw * theta.transpose() + c * dttw;
}

MultibodySystem::MultibodySystem(std::vector<Shape> shapes, std::vector<MassProperties> masses, SceneOptions options)
    : mass_(std::move(masses)), scene_(options) {
  if (shapes.size() != mass_.size())
    throw std::invalid_argument("MultibodySystem: " + std::to_string(shapes.size()) + " shapes but " +
                                std::to_string(mass_.size()) + " mass properties");
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    try {
      mass_[i].validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("MultibodySystem: body " + std::to_string(i) + ": " + e.what());
    }
    scene_.add_body(std::move(shapes[i]));
    G_.push_back(mass_[i].spatial_inertia());
    G_inv_.push_back(G_.back().inverse());
  }
}

MultibodySystem::Vector MultibodySystem::state(const std::vector<Pose>& X_W, const std::vector<Vec6>& eta) const {
  const int n = num_bodies();
  if (static_cast<int>(X_W.size()) != n || static_cast<int>(eta.size()) != n)
    throw std::invalid_argument("MultibodySystem::state: need " + std::to_string(n) + " poses and twists, got " +
                                std::to_string(X_W.size()) + " and " + std::to_string(eta.size()));
  Vector y(12 * n);
  for (int i = 0; i < n; ++i) {
    const PoseCheck c = check_pose(X_W[i]);
    if (c != PoseCheck::Ok)
      throw std::invalid_argument("MultibodySystem::state: the pose of body " + std::to_string(i) + " is bad: " +
                                  to_string(c));
    const Eigen::AngleAxisd aa(X_W[i].R);
    y.segment<3>(6 * i) = aa.angle() * aa.axis();
    y.segment<3>(6 * i + 3) = X_W[i].p;
    y.segment<6>(6 * n + 6 * i) = eta[i];
  }
  return y;
}

Pose MultibodySystem::pose(const Vector& y, int i) const {
  return Pose{so3_exp(y.segment<3>(6 * i)), y.segment<3>(6 * i + 3)};
}

Vec6 MultibodySystem::twist(const Vector& y, int i) const { return y.segment<6>(6 * num_bodies() + 6 * i); }

std::vector<Pose> MultibodySystem::poses(const Vector& y) const {
  std::vector<Pose> X(static_cast<std::size_t>(num_bodies()));
  for (int i = 0; i < num_bodies(); ++i) X[i] = pose(y, i);
  return X;
}

/// The scene at y (with derivatives or not) and the bodies' wrenches.
bool MultibodySystem::update(const Vector& y, bool derivatives) {
  const int n = num_bodies();
  X_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) X_[i] = pose(y, i);
  scene_.update(X_, derivatives);
  const SceneUpdateStats& s = scene_.last_stats();
  counters_.broad_seconds += s.broad_seconds;
  counters_.narrow_seconds += s.narrow_seconds;
  counters_.narrow_rows += static_cast<long>(s.candidates);
  counters_.active_contacts += static_cast<long>(s.active);
  counters_.newton_iterations += s.newton_iterations;
  counters_.max_active = std::max(counters_.max_active, static_cast<long>(s.active));
  if (s.failed > 0) {
    ++counters_.failed_calls;
    return false;
  }
  scene_.body_wrenches(F_);
  return true;
}

bool MultibodySystem::rhs(const Vector& y, Vector& ydot) {
  ++counters_.rhs_calls;
  const auto t0 = std::chrono::steady_clock::now();
  const double scene_before = counters_.broad_seconds + counters_.narrow_seconds;
  if (!update(y, false)) return false;
  const int n = num_bodies();
  ydot.resize(12 * n);
  for (int i = 0; i < n; ++i) {
    const Vec3 theta = y.segment<3>(6 * i);
    const Vec6 eta = twist(y, i);
    ydot.segment<3>(6 * i) = so3_right_jacobian_inverse(theta) * eta.head<3>();
    ydot.segment<3>(6 * i + 3) = X_[i].R * eta.tail<3>();
    ydot.segment<6>(6 * n + 6 * i) = G_inv_[i] * (coadjoint_action(eta, G_[i] * eta) + F_[i]);
  }
  counters_.dynamics_seconds += seconds_since(t0) - (counters_.broad_seconds + counters_.narrow_seconds - scene_before);
  return true;
}

bool MultibodySystem::jacobian(const Vector& y, Matrix& J) {
  ++counters_.jacobian_calls;
  const auto t0 = std::chrono::steady_clock::now();
  const double scene_before = counters_.broad_seconds + counters_.narrow_seconds;
  if (!update(y, true)) return false;
  const int n = num_bodies();
  J.setZero(12 * n, 12 * n);
  std::vector<Eigen::Matrix<double, 6, 6>> B(static_cast<std::size_t>(n));  // xi_i = B_i dq_i
  for (int i = 0; i < n; ++i) {
    const Vec3 theta = y.segment<3>(6 * i);
    const Vec6 eta = twist(y, i);
    const Mat3& R = X_[i].R;
    const Mat3 Jr = so3_right_jacobian(theta);
    B[i].setZero();
    B[i].topLeftCorner<3, 3>() = Jr;
    B[i].bottomRightCorner<3, 3>() = R.transpose();
    const int q = 6 * i, e = 6 * n + 6 * i;
    // Kinematics.
    J.block<3, 3>(q, q) = so3_right_jacobian_inverse_derivative(theta, eta.head<3>());
    J.block<3, 3>(q, e) = so3_right_jacobian_inverse(theta);
    J.block<3, 3>(q + 3, q) = -R * skew(eta.tail<3>()) * Jr;  // d(R v) = R (Jr dtheta) x v
    J.block<3, 3>(q + 3, e + 3) = R;
    // Gyroscopic: d(ad_eta^T G eta)/d eta = ad_eta^T G + [[mu_w~, mu_v~], [mu_v~, 0]], mu = G eta.
    const Vec6 mu = G_[i] * eta;
    Mat6 A;
    for (int j = 0; j < 6; ++j) A.col(j) = coadjoint_action(Vec6::Unit(j), mu);  // ad_{e_j}^T mu: linear in eta
    Mat6 D = Mat6::Zero();
    for (int j = 0; j < 6; ++j) D.col(j) = coadjoint_action(eta, G_[i].col(j));
    J.block<6, 6>(e, e) = G_inv_[i] * (D + A);
  }
  // Contacts: d F_i / d q_k = dF/d(xi_i, xi_j) B.
  for (const Contact& c : scene_.contacts()) {
    if (!c.active) continue;
    const int i = c.body1, j = c.body2;
    const int ei = 6 * n + 6 * i, ej = 6 * n + 6 * j;
    const ContactJacobian& d = scene_.jacobians()[static_cast<std::size_t>(c.jacobian)];
    J.block<6, 6>(ei, 6 * i) += G_inv_[i] * d.dF1.leftCols<6>() * B[i];
    J.block<6, 6>(ei, 6 * j) += G_inv_[i] * d.dF1.rightCols<6>() * B[j];
    J.block<6, 6>(ej, 6 * i) += G_inv_[j] * d.dF2.leftCols<6>() * B[i];
    J.block<6, 6>(ej, 6 * j) += G_inv_[j] * d.dF2.rightCols<6>() * B[j];
  }
  counters_.dynamics_seconds += seconds_since(t0) - (counters_.broad_seconds + counters_.narrow_seconds - scene_before);
  return true;
}

bool MultibodySystem::rechart(Vector& y) const {
  bool changed = false;
  for (int i = 0; i < num_bodies(); ++i) {
    const Vec3 theta = y.segment<3>(6 * i);
    const double t = theta.norm();
    if (t <= kPi) continue;
    y.segment<3>(6 * i) = theta * (1.0 - 2.0 * kPi / t);
    changed = true;
  }
  return changed;
}

Vec6 MultibodySystem::momentum(const Vector& y) const {
  Vec6 h = Vec6::Zero();
  for (int i = 0; i < num_bodies(); ++i) h += body_to_world_wrench(pose(y, i), G_[i] * twist(y, i));
  return h;
}

double MultibodySystem::kinetic_energy(const Vector& y) const {
  double e = 0.0;
  for (int i = 0; i < num_bodies(); ++i) {
    const Vec6 eta = twist(y, i);
    e += 0.5 * eta.dot(G_[i] * eta);
  }
  return e;
}

void MultibodyNewtonSolver::factorise(double c, const Eigen::MatrixXd& J) {
  const int m = 6 * n_;
  c_ = c;
  Aqq_inv_.resize(static_cast<std::size_t>(n_));
  T_.resize(static_cast<std::size_t>(n_));
  Jeq_ = J.block(m, 0, m, m);
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(m, m) - c * J.block(m, m, m, m);
  for (int i = 0; i < n_; ++i) {
    const Mat6 A = Mat6::Identity() - c * J.block<6, 6>(6 * i, 6 * i);
    Aqq_inv_[i] = A.inverse();
    T_[i] = Aqq_inv_[i] * J.block<6, 6>(6 * i, m + 6 * i);
  }
  // S -= c^2 J_eq T, T block diagonal: column block i of J_eq times T_i.
  for (int i = 0; i < n_; ++i) S.middleCols<6>(6 * i).noalias() -= (c * c) * (Jeq_.middleCols<6>(6 * i) * T_[i]);
  S_.compute(S);
}

void MultibodyNewtonSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  const int m = 6 * n_;
  x.resize(2 * m);
  // u = (I - c J_qq)^{-1} b_q; S x_e = b_e + c J_eq u; x_q = u + c T x_e.
  Eigen::VectorXd u(m);
  for (int i = 0; i < n_; ++i) u.segment<6>(6 * i) = Aqq_inv_[i] * b.segment<6>(6 * i);
  x.tail(m) = S_.solve(b.tail(m) + c_ * (Jeq_ * u));
  for (int i = 0; i < n_; ++i) x.segment<6>(6 * i) = u.segment<6>(6 * i) + c_ * (T_[i] * x.segment<6>(m + 6 * i));
}

MultibodyRun simulate(MultibodySystem& sys, const Eigen::VectorXd& y0, double t_end, const std::vector<double>& outputs,
                      const StiffOdeOptions& options, bool analytic_jacobian) {
  if (y0.size() != sys.state_size())
    throw std::invalid_argument("simulate: y0 has " + std::to_string(y0.size()) + " entries, the system's state " +
                                std::to_string(sys.state_size()));
  sys.reset_counters();
  sys.scene().reset_warm_starts();
  MultibodyRun run;
  run.t.push_back(0.0);
  run.y.push_back(y0);
  StiffOdeSolver::Jacobian jac;
  if (analytic_jacobian) jac = [&](double, const Eigen::VectorXd& x, Eigen::MatrixXd& J) { return sys.jacobian(x, J); };
  StiffOdeSolver ode([&](double, const Eigen::VectorXd& x, Eigen::VectorXd& f) { return sys.rhs(x, f); }, jac, options);
  MultibodyNewtonSolver newton(sys.num_bodies());
  ode.set_newton_solver(&newton);
  long contacts_sum = 0;
  auto keep = [&](double t, const Eigen::VectorXd& x) {
    run.t.push_back(t);
    run.y.push_back(x);
  };
  auto each_step = [&](double, const Eigen::VectorXd&) {
    const long active = static_cast<long>(sys.scene().last_stats().active);
    run.step_contacts_max = std::max(run.step_contacts_max, active);
    contacts_sum += active;
  };
  auto rechart = [&](double, Eigen::VectorXd& x) { return sys.rechart(x); };
  Eigen::VectorXd y = y0;
  const auto t0 = std::chrono::steady_clock::now();
  run.status = ode.integrate(0.0, t_end, y, outputs, keep, each_step, rechart);
  run.wall_seconds = seconds_since(t0);
  run.t_reached = ode.t();
  run.ode = ode.stats();
  run.counters = sys.counters();
  run.step_contacts_mean = static_cast<double>(contacts_sum) / std::max(1L, run.ode.steps);
  return run;
}

}  // namespace idcol
