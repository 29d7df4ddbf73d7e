#include "idcol/derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "idcol/solver.hpp"
#include "contact_kinematics_impl.hpp"
#include "derivative_check.hpp"

namespace idcol {

Mat6 adjoint(const Pose& X) {
  Mat6 A;
  A.topLeftCorner<3, 3>() = X.R;
  A.topRightCorner<3, 3>().setZero();
  A.bottomLeftCorner<3, 3>() = skew(X.p) * X.R;
  A.bottomRightCorner<3, 3>() = X.R;
  return A;
}

Pose se3_exp(const Vec6& xi) {
  const Vec3 w = xi.head<3>(), v = xi.tail<3>();
  const double th2 = w.squaredNorm(), th = std::sqrt(th2);
  const Mat3 W = skew(w), W2 = W * W;
  double a, b, c;  // sin(th)/th, (1-cos th)/th^2, (th - sin th)/th^3
  if (th < 1e-4) {  // Taylor, error below 1e-18
    a = 1.0 - th2 / 6.0;
    b = 0.5 - th2 / 24.0;
    c = 1.0 / 6.0 - th2 / 120.0;
  } else {
    a = std::sin(th) / th;
    b = (1.0 - std::cos(th)) / th2;
    c = (th - std::sin(th)) / (th2 * th);
  }
  Pose X;
  X.R = Mat3::Identity() + a * W + b * W2;
  X.p = (Mat3::Identity() + b * W + c * W2) * v;
  return X;
}

namespace {
}  // namespace

namespace detail {
void reject_separated(const SolveResult& res, const char* function) {
  if (res.status == SolveStatus::Separated)
    throw std::invalid_argument(std::string(function) +
                                ": the SolveResult has status Separated (SolverOptions::alpha_max): it carries a lower "
                                "bound on alpha*, not a contact to differentiate; solve with alpha_max = +inf");
}
}  // namespace detail

namespace {
/// Derivatives read the factorisation the solve kept only when asked to.
void require_factorisation(const SolveResult& res, const char* function) {
  if (res.status == SolveStatus::Converged && !res.internal.factorised)
    throw std::invalid_argument(std::string(function) +
                                ": the SolveResult carries no KKT factorisation; solve with "
                                "SolverOptions::derivatives = true to take derivatives of it");
}
}  // namespace

Conditioning conditioning(const SolveResult& res) {
  detail::reject_separated(res, "conditioning");
  Conditioning c;
  if (res.status != SolveStatus::Converged) return c;
  require_factorisation(res, "conditioning");
  c.pivot_ratio = res.internal.lu.pivot_ratio();
  c.reliable = std::isfinite(c.pivot_ratio) && c.pivot_ratio >= kReliablePivotRatio;
  // The witness-point and gap derivatives carry L/alpha, and the solve of
  // T_c passes through 1/k (k = |r| / (f_S L)): below kMinReliableScale they
  // overflow, or come within a few orders of it (found by fuzz_solve).
  // The gap and witness derivatives in the v columns are O(L / alpha).
  c.reliable = c.reliable && res.alpha >= kMinReliableScale * std::max(1.0, res.internal.length) &&
               res.internal.k >= kMinReliableScale && res.alpha >= kMinReliableAlpha;
  // A problem solved in units of a power of two (bodies of 1e-200) keeps its
  // curvatures in the caller's units for the derivatives; where those leave
  // the double range (a Hessian of 1/size^2 = 1e400) no derivative can be
  // formed from them.
  const SolveResult::Internal& in = res.internal;
  c.reliable = c.reliable && in.e1.grad.allFinite() && in.e2.grad.allFinite() && in.e1.hess.allFinite() &&
               in.e2.hess.allFinite() && in.y1.allFinite() && in.y2.allFinite();
  return c;
}

namespace {

/// G_c of eq:df_dq with J = I, for the *unscaled* residual of eq:kkt_residual
/// in the unknowns (x, s = log alpha, lambda1, lambda2). Row 0 (phi1) does
/// not depend on the pose. Rows: a^T (eq:phi_q), lambda2 B (eq:phi_xq),
/// lambda2 c^T (eq:phi_alphaq), with y_q from eq:y_partials_q.
Mat6 g_matrix(const SolveResult& res) {
  const SolveResult::Internal& in = res.internal;
  const double a = res.alpha, l2 = res.lambda2;
  const Vec3& y = in.y2;
  const Vec3& g = in.e2.grad;
  const Mat3& H = in.e2.hess;
  Mat36 Yq;  // eq:y_partials_q
  Yq.leftCols<3>() = skew(y);
  Yq.rightCols<3>() = (-1.0 / a) * Mat3::Identity();
  Mat6 G;
  G.row(0).setZero();
  G.row(1) = g.transpose() * Yq;  // eq:phi_q
  Mat36 B;                        // eq:phi_xq
  B.leftCols<3>() = H * skew(y) - skew(g);
  B.rightCols<3>() = (-1.0 / a) * H;
  G.middleRows<3>(2) = (l2 / a) * (in.R * B);
  G.row(5) = (-l2 / a) * (g + H * y).transpose() * Yq;  // eq:phi_alphaq
  return G;
}

}  // namespace

// The solver factorised J_int = D_r J_c D_c^{-1} (result.hpp, kkt.hpp):
// rows scaled by D_r = diag(row_scale), unknowns z_S with
// dz/dz_S = D_c^{-1} = diag(kL I3, 1, k, k). Hence
//   T_c = -J_c^{-1} G_c = -D_c^{-1} J_int^{-1} D_r G_c     (eq:dz_dq)
// with the stored LU and no refactorisation.
SolutionSensitivity solution_sensitivity(const SolveResult& res) {
  detail::reject_separated(res, "solution_sensitivity");
  SolutionSensitivity s;
  if (res.status != SolveStatus::Converged) return s;
  require_factorisation(res, "solution_sensitivity");
  const SolveResult::Internal& in = res.internal;
  Mat6 rhs = in.row_scale.asDiagonal() * g_matrix(res);
  rhs = -in.lu.solve_many<6>(rhs);
  const double kL = in.k * in.length;
  s.dz_dxi.topRows<3>() = kL * rhs.topRows<3>();
  s.dz_dxi.row(3) = res.alpha * rhs.row(3);  // d alpha = alpha ds
  s.dz_dxi.bottomRows<2>() = in.k * rhs.bottomRows<2>();
  s.cond = conditioning(res);
  Eigen::Matrix<double, 4, 6> N = s.dz_dxi.topRows<4>();
  N.topRows<3>() /= in.length;
  N.rightCols<3>() *= in.length;
  s.cond.sensitivity = N.cwiseAbs().maxCoeff();
  // allFinite: maxCoeff() may skip a NaN, so the bound alone can pass one.
  s.cond.reliable = s.cond.reliable && s.dz_dxi.allFinite() && s.cond.sensitivity <= kReliableSensitivity;
  s.valid = true;
  return s;
}

// d alpha/dxi = alpha e_s^T T_c = -alpha (J_int^{-T} e_s)^T D_r G_c.
Row6 alpha_gradient(const SolveResult& res) {
  detail::reject_separated(res, "alpha_gradient");
  if (res.status != SolveStatus::Converged) return Row6::Zero();
  require_factorisation(res, "alpha_gradient");
  const SolveResult::Internal& in = res.internal;
  Vec6 e = Vec6::Zero();
  e[3] = 1.0;
  const Vec6 w = in.row_scale.cwiseProduct(in.lu.solve_transpose(e));
  return (-res.alpha) * (w.transpose() * g_matrix(res));
}

void relative_twist_jacobians(const Pose& X_12, Mat6& dxi_dxi1, Mat6& dxi_dxi2) {
  dxi_dxi1 = -adjoint(X_12.inverse());
  dxi_dxi2.setIdentity();
}

Mat6x12 world_pose_sensitivity(const SolutionSensitivity& s, const Pose& X_12) {
  Mat6x12 D;
  D.leftCols<6>() = -s.dz_dxi * adjoint(X_12.inverse());
  D.rightCols<6>() = s.dz_dxi;
  return D;
}

ContactKinematics contact_kinematics(const SolveResult& res) {
  detail::reject_separated(res, "contact_kinematics");
  if (res.status != SolveStatus::Converged) return ContactKinematics{};
  return detail::kinematics_from(res.alpha, res.x_1, res.internal.r, res.internal.e1.grad);
}

ContactKinematicsDerivatives contact_kinematics_derivatives(const SolveResult& res, const SolutionSensitivity& s) {
  detail::reject_separated(res, "contact_kinematics_derivatives");
  ContactKinematicsDerivatives d;
  if (res.status != SolveStatus::Converged || !s.valid) return d;
  const SolveResult::Internal& in = res.internal;
  const double a = res.alpha, ia = 1.0 / a, nr = in.r.stableNorm();
  const Mat36 dx = s.dz_dxi.topRows<3>();
  const Row6 da = s.dz_dxi.row(3);
  Mat36 dr;  // dr/dxi = [0, R] (eq:ddD_dq: dr/dq = R J_v)
  dr.leftCols<3>().setZero();
  dr.rightCols<3>() = in.R;
  // eq:witness by the product rule.
  // Products grouped so that none overflows at tiny |r| (alpha ~ |r|, x ~ r):
  // x/alpha and (r - x)/alpha are O(1) (found by fuzz_solve).
  const Row6 da_a = ia * da;
  d.dp1_1_dxi = ia * dx - in.y1 * da_a;
  d.dp2_1_dxi = (in.r / a - res.x_1 / a) * da_a + (1.0 - ia) * dr + ia * dx;
  // eq:ddD_dq
  d.dgap_dxi = ((nr * ia) * ia) * da + (1.0 - ia) * (in.r / nr).transpose() * dr;
  // eq:dnhat_dq, with y1 = x/alpha: d nhat = (I - n n^T) H1 dy1 / |grad phi1|
  // and dy1 = dx/alpha - y1 d alpha/alpha. The paper's form keeps alpha fixed
  // (its term in d alpha vanishes for shapes with phi + 1 homogeneous of
  // degree 1, whose H1 y1 = 0); the smooth polytope and cone need it.
  const double ng = in.e1.grad.stableNorm();
  const Vec3 n = in.e1.grad / ng;
  const Mat3 P = Mat3::Identity() - n * n.transpose();  // = -(n~)^2
  const Mat36 dy1 = ia * dx - in.y1 * da_a;
  d.dnhat_1_dxi = (P * in.e1.hess / ng) * dy1;
  d.cond = s.cond;
  d.valid = true;
  return d;
}

Row6 gap_gradient(const SolveResult& res) {
  detail::reject_separated(res, "gap_gradient");
  if (res.status != SolveStatus::Converged) return Row6::Zero();
  require_factorisation(res, "gap_gradient");  // name this call, not alpha_gradient, in the error
  const SolveResult::Internal& in = res.internal;
  const double ia = 1.0 / res.alpha, nr = in.r.stableNorm();
  // Grouped so that no intermediate overflows at tiny |r| (alpha ~ |r|):
  // nr/alpha is O(1), r/nr a unit vector (found by fuzz_solve).
  Row6 g = ((nr * ia) * ia) * alpha_gradient(res);  // eq:ddD_dq
  g.tail<3>() += (1.0 - ia) * (in.R.transpose() * (in.r / nr)).transpose();
  return g;
}

ContactKinematicsWorld contact_kinematics_world(const ContactKinematics& c, const ContactKinematicsDerivatives* d,
                                                const Pose& X_W1, const Pose& X_12) {
  ContactKinematicsWorld w;
  if (!c.valid) return w;
  const Mat3& R = X_W1.R;
  w.p1_W = R * c.p1_1 + X_W1.p;
  w.p2_W = R * c.p2_1 + X_W1.p;
  w.nhat_W = R * c.nhat_1;
  w.gap = c.gap;
  w.valid = true;
  if (d == nullptr || !d->valid) return w;
  // A body twist xi1 of X_W1 moves a body-1 point q_1 in the world by
  // R_W1 [-q_1~, I] xi1 and a body-1 direction by R_W1 [-n_1~, 0] xi1, and
  // moves X_12 by dxi = -Ad_{X_12^{-1}} xi1 (relative_twist_jacobians).
  const Mat6 M1 = -adjoint(X_12.inverse());
  auto point = [&](const Vec3& q_1, const Mat36& dq, Mat3x12& out) {
    out.leftCols<3>() = -R * skew(q_1);
    out.middleCols<3>(3) = R;
    out.leftCols<6>() += R * dq * M1;
    out.rightCols<6>() = R * dq;
  };
  point(c.p1_1, d->dp1_1_dxi, w.dp1_W);
  point(c.p2_1, d->dp2_1_dxi, w.dp2_W);
  w.dnhat_W.leftCols<3>() = -R * skew(c.nhat_1);
  w.dnhat_W.middleCols<3>(3).setZero();
  w.dnhat_W.leftCols<6>() += R * d->dnhat_1_dxi * M1;
  w.dnhat_W.rightCols<6>() = R * d->dnhat_1_dxi;
  w.dgap.leftCols<6>() = d->dgap_dxi * M1;
  w.dgap.rightCols<6>() = d->dgap_dxi;
  w.has_derivatives = true;
  return w;
}

void HertzModel::validate() const {
  auto bad = [](const char* field, double v, const char* expected) {
    std::ostringstream os;
    os << std::setprecision(17) << "HertzModel: field '" << field << "' must be " << expected << ", got " << v;
    throw std::invalid_argument(os.str());
  };
  if (!std::isfinite(stiffness) || !(stiffness > 0.0)) bad("stiffness", stiffness, "finite and > 0");
  if (!std::isfinite(exponent) || !(exponent >= 1.0)) bad("exponent", exponent, "finite and >= 1");
}

ContactWrench contact_wrench(const SolveResult& res, const HertzModel& model) {
  detail::reject_separated(res, "contact_wrench");
  ContactWrench w;
  if (res.status != SolveStatus::Converged) return w;
  w.valid = true;
  const ContactKinematics c = contact_kinematics(res);
  const double delta = -c.gap;
  if (!(delta > 0.0)) return w;
  w.active = true;
  w.f_n = model.stiffness * std::pow(delta, model.exponent);  // eq:contactmodel
  const Vec3 f_1 = -w.f_n * c.nhat_1;                          // eq:contact_wrench
  w.F1_1.head<3>() = res.x_1.cross(f_1);
  w.F1_1.tail<3>() = f_1;
  w.F2_2 = -detail::coadjoint_T(res.internal.R, res.internal.r, w.F1_1);  // Ad_{X_12}^T
  w.representable = std::isfinite(w.f_n) && w.F1_1.allFinite() && w.F2_2.allFinite();
  return w;
}

ContactWrenchDerivatives contact_wrench_derivatives(const SolveResult& res, const SolutionSensitivity& s,
                                                    const HertzModel& model) {
  detail::reject_separated(res, "contact_wrench_derivatives");
  ContactWrenchDerivatives out;
  if (res.status != SolveStatus::Converged || !s.valid) return out;
  out.valid = true;
  out.cond = s.cond;
  const ContactWrench w = contact_wrench(res, model);
  if (!w.active) return out;
  if (!w.representable) {  // beyond the double range: no derivative either
    out.cond.reliable = false;
    return out;
  }
  const ContactKinematicsDerivatives d = contact_kinematics_derivatives(res, s);
  const ContactKinematics c = contact_kinematics(res);
  const double delta = -c.gap;
  // d f_n = -k p delta^(p-1) d gap
  out.df_n_dxi = (-model.stiffness * model.exponent * std::pow(delta, model.exponent - 1.0)) * d.dgap_dxi;
  const Vec3 f_1 = w.F1_1.tail<3>();
  const Mat36 df = -c.nhat_1 * out.df_n_dxi - w.f_n * d.dnhat_1_dxi;  // eq:dfc_dq
  const Mat36 dx = s.dz_dxi.topRows<3>();
  out.dF1_1_dxi.topRows<3>() = -skew(f_1) * dx + skew(res.x_1) * df;  // eq:dFc1_dq
  out.dF1_1_dxi.bottomRows<3>() = df;
  // eq:dFc2_dq: F2 = -Ad_g^T F1 and d(Ad_g^T) = ad_xi^T Ad_g^T, so
  // dF2 = -Ad_g^T dF1 + ad_xi^T F2, and ad_xi^T F2 = [[m~, f~], [f~, 0]] xi
  // for F2 = (m, f), which is the paper's -adbar*_{F2} xi.
  for (int j = 0; j < 6; ++j)
    out.dF2_2_dxi.col(j) = -detail::coadjoint_T(res.internal.R, res.internal.r, out.dF1_1_dxi.col(j));
  const Vec3 m2 = w.F2_2.head<3>(), f2 = w.F2_2.tail<3>();
  out.dF2_2_dxi.topLeftCorner<3, 3>() += skew(m2);
  out.dF2_2_dxi.topRightCorner<3, 3>() += skew(f2);
  out.dF2_2_dxi.bottomLeftCorner<3, 3>() += skew(f2);
  return out;
}

// ---------------------------------------------------------------------------

double DerivativeCheckReport::agreement() const {
  const int n = converged - fd_failed;
  return n > 0 ? static_cast<double>(agree) / n : 0.0;
}

DerivativeCheckReport check_derivatives(const Shape& body1, const Shape& body2, const std::vector<Pose>& poses,
                                        const DerivativeCheckOptions& o) {
  DerivativeCheckReport rep;
  SolverOptions base = o.solver;  // the base solve keeps its factorisation; perturbed solves need none
  base.derivatives = true;
  const double L = radii(body1).outer + radii(body2).outer;
  // Dimensionless rows (x/L, alpha) and columns (w, v L).
  auto nondim = [L](const Eigen::Matrix<double, 4, 6>& D) {
    Eigen::Matrix<double, 4, 6> N = D;
    N.topRows<3>() /= L;
    N.rightCols<3>() *= L;
    return N;
  };
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose& X = poses[i];
    ++rep.poses;
    const SolveResult res = solve(body1, body2, X, base);
    if (!res.converged()) continue;
    ++rep.converged;
    const SolutionSensitivity s = solution_sensitivity(res);
    if (!s.cond.reliable) ++rep.flagged;
    // Richardson extrapolation of central differences at h and h/2:
    // truncation O(h^4), see DerivativeCheckOptions::h. Perturbed solves are
    // cold: they share no state with the base solve.
    auto finite_differences = [&](double h, Eigen::Matrix<double, 4, 6>& fd) {
      for (int j = 0; j < 6; ++j) {
        Eigen::Matrix<double, 4, 1> d[2];
        for (int k = 0; k < 2; ++k) {
          const double hj = (j < 3 ? h : h * L) / (1 + k);
          Vec6 xi = Vec6::Zero();
          xi[j] = hj;
          const SolveResult rp = solve(body1, body2, X * se3_exp(xi), o.solver);
          const SolveResult rm = solve(body1, body2, X * se3_exp(-xi), o.solver);
          if (!rp.converged() || !rm.converged()) return false;
          d[k].head<3>() = (rp.x_1 - rm.x_1) / (2.0 * hj);
          d[k][3] = (rp.alpha - rm.alpha) / (2.0 * hj);
        }
        fd.col(j) = (4.0 * d[1] - d[0]) / 3.0;
      }
      return true;
    };
    const Eigen::Matrix<double, 4, 6> ift = s.dz_dxi.topRows<4>();
    auto error_against = [&](const Eigen::Matrix<double, 4, 6>& fd) {
      const Eigen::Matrix<double, 4, 6> A = nondim(ift), B = nondim(fd);
      return (A - B).cwiseAbs().maxCoeff() / std::max(1.0, B.cwiseAbs().maxCoeff());
    };
    Eigen::Matrix<double, 4, 6> fd;
    if (!finite_differences(o.h, fd)) {
      ++rep.fd_failed;
      continue;
    }
    double err = error_against(fd);
    // A disagreement must survive steps 10, 100 and 1000 times finer: where
    // x* turns sharply (the flat faces of n = 8 bodies) or the geometry has a
    // scale far below L (a body 1e-6 times the size of the other, where a
    // step of h L is ten times the small body), the O(h^4) truncation at h
    // can itself exceed the tolerance, and finer differences move towards the
    // analytic value. Rounding grows as the step shrinks (~1e-13 / step), so
    // the finest step is the last one tried.
    for (double f = 0.1; !(err <= o.tolerance) && f >= 1e-3; f *= 0.1) {
      Eigen::Matrix<double, 4, 6> fine;
      if (finite_differences(f * o.h, fine)) err = std::min(err, error_against(fine));
    }
    detail::record_checked_pose(rep, i, X, res.alpha, s.cond, err, o.tolerance);
  }
  return rep;
}

}  // namespace idcol
