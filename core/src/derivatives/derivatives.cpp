#include "idcol/derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "idcol/detail/formulas/derivatives.hpp"
#include "idcol/detail/scalar_num.hpp"
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

namespace F = detail::formulas;
using SN = detail::ScalarNum;
using Point = F::DerivPoint<double>;

/// What the derivatives' formulas (formulas/derivatives.hpp) read of a
/// converged result: its scalars, and its vectors and matrices in place
/// (Eigen stores a Mat3 by columns, as the formulas read it).
Point deriv_point(const SolveResult& res) {
  const SolveResult::Internal& in = res.internal;
  Point q;
  q.alpha = res.alpha;
  q.k = in.k;
  q.lambda2 = res.lambda2;
  q.L = in.length;
  for (int i = 0; i < 6; ++i) q.rs[i] = in.row_scale[i];
  q.x1 = res.x_1.data();
  q.r = in.r.data();
  q.y1 = in.y1.data();
  q.y2 = in.y2.data();
  q.g1 = in.e1.grad.data();
  q.g2 = in.e2.grad.data();
  q.R = in.R.data();
  q.H1 = in.e1.hess.data();
  q.H2 = in.e2.hess.data();
  return q;
}

/// dz/dxi of s as the formulas' array.
void dz_of(const SolutionSensitivity& s, double (&dz)[6][6]) {
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) dz[i][j] = s.dz_dxi(i, j);
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
  const Point q = deriv_point(res);
  double G[5][6], dz[6][6];
  F::g_matrix<SN>(q, G);
  F::sensitivity<SN>(q, G, in.lu, dz);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) s.dz_dxi(i, j) = dz[i][j];
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
  const Point q = deriv_point(res);
  double G[5][6], g[6];
  F::g_matrix<SN>(q, G);
  F::alpha_gradient<SN>(q, G, res.internal.lu, g);
  return Eigen::Map<const Row6>(g);
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
  double dz[6][6];
  dz_of(s, dz);
  F::KinematicsDerivs<double> k;
  F::kinematics_derivatives<SN>(deriv_point(res), dz, k);
  for (int j = 0; j < 6; ++j) {
    d.dgap_dxi[j] = k.dgap[j];
    for (int i = 0; i < 3; ++i) {
      d.dp1_1_dxi(i, j) = k.dp1[i][j];
      d.dp2_1_dxi(i, j) = k.dp2[i][j];
      d.dnhat_1_dxi(i, j) = k.dn[i][j];
    }
  }
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

namespace {
/// The formulas' wrench of a converged result (its kinematics as
/// contact_kinematics() forms them).
F::Wrench<SN> wrench_of(const Point& q, const ContactKinematics& c, const HertzModel& model) {
  F::Wrench<SN> w;
  const double n[3] = {c.nhat_1[0], c.nhat_1[1], c.nhat_1[2]};
  F::contact_wrench<SN>(q, c.gap, n, model.stiffness, model.exponent, w);
  return w;
}
}  // namespace

ContactWrench contact_wrench(const SolveResult& res, const HertzModel& model) {
  detail::reject_separated(res, "contact_wrench");
  ContactWrench w;
  if (res.status != SolveStatus::Converged) return w;
  w.valid = true;
  const F::Wrench<SN> f = wrench_of(deriv_point(res), contact_kinematics(res), model);
  if (!f.active) return w;
  w.active = true;
  w.f_n = f.f_n;  // eq:contactmodel
  for (int i = 0; i < 6; ++i) {  // eq:contact_wrench
    w.F1_1[i] = f.F1[i];
    w.F2_2[i] = f.F2[i];  // -Ad_{X_12}^T F1
  }
  w.representable = f.representable;
  return w;
}

ContactWrenchDerivatives contact_wrench_derivatives(const SolveResult& res, const SolutionSensitivity& s,
                                                    const HertzModel& model) {
  detail::reject_separated(res, "contact_wrench_derivatives");
  ContactWrenchDerivatives out;
  if (res.status != SolveStatus::Converged || !s.valid) return out;
  out.valid = true;
  out.cond = s.cond;
  const Point q = deriv_point(res);
  const ContactKinematics c = contact_kinematics(res);
  const F::Wrench<SN> w = wrench_of(q, c, model);
  if (!w.active) return out;
  if (!w.representable) {  // beyond the double range: no derivative either
    out.cond.reliable = false;
    return out;
  }
  double dz[6][6];
  dz_of(s, dz);
  F::KinematicsDerivs<double> k;
  F::kinematics_derivatives<SN>(q, dz, k);
  const double n[3] = {c.nhat_1[0], c.nhat_1[1], c.nhat_1[2]};
  F::WrenchDerivs<double> d;
  F::wrench_derivatives<SN>(q, dz, n, k, w, model.stiffness, model.exponent, d);
  for (int j = 0; j < 6; ++j) {
    out.df_n_dxi[j] = d.df_n[j];
    for (int i = 0; i < 6; ++i) {
      out.dF1_1_dxi(i, j) = d.dF1[i][j];
      out.dF2_2_dxi(i, j) = d.dF2[i][j];
    }
  }
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
