#include "idcol/shape_derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "../derivatives/derivative_check.hpp"

namespace idcol {
namespace {

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

/// The differentiated shape must reproduce the evaluation the solver stored
/// at y: the same phi and gradient (to rounding). `e` is its evaluation
/// there, which eval_params() makes anyway.
void require_same_shape(const Shape& s, const ShapeEval& e, const ShapeEval& stored, const char* which) {
  const double tol = 1e-9;
  const bool ok = std::abs(e.phi - stored.phi) <= tol * (1.0 + std::abs(stored.phi)) &&
                  (e.grad - stored.grad).norm() <= tol * stored.grad.norm() + 1e-300;
  if (!ok)
    throw std::invalid_argument(std::string("shape_sensitivity: '") + which + "' (" + family_name(s) +
                                ") is not the shape the result was solved with: phi at the contact is " + num(e.phi) +
                                ", the solve stored " + num(stored.phi));
}

}  // namespace

ShapeSensitivity shape_sensitivity(const SolveResult& res, const Shape& body1, const Shape& body2, int body) {
  detail::reject_separated(res, "shape_sensitivity");
  if (body != 1 && body != 2)
    throw std::invalid_argument("shape_sensitivity: field 'body' must be 1 or 2, got " + std::to_string(body));
  ShapeSensitivity s;
  s.body = body;
  if (res.status != SolveStatus::Converged) return s;
  s.cond = conditioning(res);  // throws without a stored factorisation
  const SolveResult::Internal& in = res.internal;
  const Shape& B = body == 1 ? body1 : body2;
  const Vec3& y = body == 1 ? in.y1 : in.y2;
  ShapeEval e;
  ShapeParamEval d;
  eval_params(B, y, e, d);
  // The other body enters only through the stored factorisation.
  require_same_shape(B, e, body == 1 ? in.e1 : in.e2, body == 1 ? "body1" : "body2");
  const int p = static_cast<int>(d.dphi.size());
  const double a = res.alpha, la = (body == 1 ? res.lambda1 : res.lambda2) / a;
  const int phi_row = body == 1 ? 0 : 1;
  const double kL = in.k * in.length;
  // Length powers are 0 or 1 (param_length_powers), so a column is made
  // dimensionless by L or not at all.
  const VecX pw = param_length_powers(B);
  s.dz_dtheta.resize(6, p);
  double sens = 0.0;
  // Columns in blocks of kB: the triangular solves of a block run side by
  // side (Lu6::solve_many), where one column at a time waits on each
  // dependent subtraction (measured: 4x faster for a polytope's 33).
  constexpr int kB = 8;
  for (int j0 = 0; j0 < p; j0 += kB) {
    const int nb = std::min(kB, p - j0);
    Eigen::Matrix<double, 6, kB> G = Eigen::Matrix<double, 6, kB>::Zero();
    for (int c = 0; c < nb; ++c) {
      // dF/dtheta_j of the unscaled residual (see the header), in body-1
      // coordinates, rows then scaled by D_r as the stored LU expects.
      const int j = j0 + c;
      const Vec3 dg = d.dgrad.col(j);
      Vec6 g = Vec6::Zero();
      g[phi_row] = d.dphi[j];
      g.segment<3>(2) = la * (body == 1 ? dg : Vec3(in.R * dg));
      g[5] = -la * y.dot(dg);
      G.col(c) = in.row_scale.cwiseProduct(g);
    }
    // T = -D_c^{-1} J_int^{-1} D_r G (derivatives.cpp, solution_sensitivity).
    const Eigen::Matrix<double, 6, kB> sol = -in.lu.solve_many<kB>(G);
    for (int c = 0; c < nb; ++c) {
      const int j = j0 + c;
      s.dz_dtheta.col(j).head<3>() = kL * sol.col(c).head<3>();
      s.dz_dtheta(3, j) = a * sol(3, c);  // d alpha = alpha ds
      s.dz_dtheta.col(j).tail<2>() = in.k * sol.col(c).tail<2>();
      // Dimensionless sensitivity: rows x / L and alpha, columns times L^power.
      const double cs = pw[j] != 0.0 ? in.length : 1.0;
      sens = std::max({sens, (s.dz_dtheta.col(j).head<3>() * (cs / in.length)).cwiseAbs().maxCoeff(),
                       std::abs(s.dz_dtheta(3, j) * cs)});
    }
  }
  if (body == 1)
    s.dgrad1_dtheta = std::move(d.dgrad);
  else
    s.dgrad1_dtheta.setZero(3, p);
  s.cond.sensitivity = sens;
  s.cond.reliable = s.cond.reliable && s.dz_dtheta.allFinite() && sens <= kReliableSensitivity;
  s.valid = true;
  return s;
}

ShapeSensitivity chain_params(const ShapeSensitivity& s, const Eigen::MatrixXd& D) {
  ShapeSensitivity c = s;
  if (!s.valid) return c;
  if (D.rows() != s.dz_dtheta.cols())
    throw std::invalid_argument("chain_params: field 'dtheta_dq' has " + std::to_string(D.rows()) + " rows, expected " +
                                std::to_string(s.dz_dtheta.cols()));
  c.dz_dtheta = s.dz_dtheta * D;
  c.dgrad1_dtheta = s.dgrad1_dtheta * D;
  c.cond.reliable = c.cond.reliable && c.dz_dtheta.allFinite();
  return c;
}

ShapeKinematicsDerivatives shape_kinematics_derivatives(const SolveResult& res, const ShapeSensitivity& s) {
  detail::reject_separated(res, "shape_kinematics_derivatives");
  ShapeKinematicsDerivatives d;
  if (res.status != SolveStatus::Converged || !s.valid) return d;
  const SolveResult::Internal& in = res.internal;
  const double a = res.alpha, ia = 1.0 / a, nr = in.r.stableNorm();
  // Blocks and expressions, not copies: each dynamic temporary allocates.
  const auto dx = s.dz_dtheta.topRows<3>();
  const auto da_a = ia * s.dz_dtheta.row(3);
  // eq:witness by the product rule, grouped as in contact_kinematics_derivatives.
  d.dp1_1 = ia * dx - in.y1 * da_a;  // = d y1
  const Mat3X& dy1 = d.dp1_1;
  d.dp2_1 = (in.r / a - res.x_1 / a) * da_a + ia * dx;
  d.dgap = (nr * ia) * da_a;  // eq:gap: d gap = |r|/alpha^2 d alpha
  // eq:unit_normal: n = grad phi1(y1) / |grad phi1|, whose change has the
  // part through y1 and, for body 1's parameters, the direct part.
  const double ng = in.e1.grad.stableNorm();
  const Vec3 n = in.e1.grad / ng;
  const Mat3 P = Mat3::Identity() - n * n.transpose();
  d.dnhat_1.noalias() = (P / ng) * (in.e1.hess * dy1 + s.dgrad1_dtheta);
  d.cond = s.cond;
  d.valid = true;
  return d;
}

ShapeWrenchDerivatives shape_wrench_derivatives(const SolveResult& res, const ShapeSensitivity& s,
                                                const HertzModel& model) {
  detail::reject_separated(res, "shape_wrench_derivatives");
  ShapeWrenchDerivatives out;
  if (res.status != SolveStatus::Converged || !s.valid) return out;
  const int p = static_cast<int>(s.dz_dtheta.cols());
  out.valid = true;
  out.cond = s.cond;
  out.df_n = RowX::Zero(p);
  out.dF1_1 = Mat6X::Zero(6, p);
  out.dF2_2 = Mat6X::Zero(6, p);
  const ContactWrench w = contact_wrench(res, model);
  if (!w.active) return out;
  if (!w.representable) {
    out.cond.reliable = false;
    return out;
  }
  const ShapeKinematicsDerivatives d = shape_kinematics_derivatives(res, s);
  const double delta = -contact_kinematics(res).gap;
  const Vec3 n = res.internal.e1.grad.stableNormalized();
  // eq:contactmodel: d f_n = -k p delta^(p-1) d gap.
  out.df_n = (-model.stiffness * model.exponent * std::pow(delta, model.exponent - 1.0)) * d.dgap;
  const Vec3 f_1 = w.F1_1.tail<3>();
  out.dF1_1.bottomRows<3>() = -n * out.df_n - w.f_n * d.dnhat_1;  // eq:dfc_dq, df
  const auto df = out.dF1_1.bottomRows<3>();
  const auto dx = s.dz_dtheta.topRows<3>();
  out.dF1_1.topRows<3>() = -skew(f_1) * dx + skew(res.x_1) * df;  // eq:dFc1_dq
  // F2_2 = -Ad_{X_12}^T F1_1 with the pose fixed.
  for (int j = 0; j < p; ++j) out.dF2_2.col(j) = -detail::coadjoint_T(res.internal.R, res.internal.r, out.dF1_1.col(j));
  return out;
}

// ---------------------------------------------------------------------------

// Long: the checker's loop over poses and parameters, with its central
// differences and its record of each pose, as check_derivatives reads.
DerivativeCheckReport check_shape_derivatives(const Shape& body1, const Shape& body2, int body,
                                              const std::vector<Pose>& poses, const ShapeDerivativeCheckOptions& o) {
  if (body != 1 && body != 2)
    throw std::invalid_argument("check_shape_derivatives: field 'body' must be 1 or 2, got " + std::to_string(body));
  DerivativeCheckReport rep;
  SolverOptions base = o.solver;
  base.derivatives = true;
  const Shape& B = body == 1 ? body1 : body2;
  const double L = radii(body1).outer + radii(body2).outer;
  const VecX theta = shape_params(B), pw = param_length_powers(B);
  const int p = static_cast<int>(theta.size());
  using Mat4X = Eigen::Matrix<double, 4, Eigen::Dynamic>;
  auto nondim = [&](const Mat4X& D) {
    Mat4X N = D;
    N.topRows<3>() /= L;
    for (int j = 0; j < p; ++j) N.col(j) *= std::pow(L, pw[j]);
    return N;
  };
  // The perturbed shapes do not depend on the pose: build them once. For
  // each parameter and step (h, h/2): central (theta +- h) or, where
  // theta - h leaves the valid range, forward (theta + h, theta + 2h).
  struct Step {
    bool central = true;
    double h = 0.0;
    std::vector<Shape> shapes;  // central: {+h, -h}; forward: {+h, +2h}
  };
  auto make_steps = [&](double h) {
    std::vector<Step> st(p);
    for (int j = 0; j < p; ++j) {
      Step& s = st[j];
      s.h = h * std::max(std::abs(theta[j]), std::pow(L, pw[j]));
      auto at = [&](double dt) {
        VecX t = theta;
        t[j] += dt;
        return shape_with_params(B, t);
      };
      try {
        s.shapes = {at(s.h), at(-s.h)};
      } catch (const std::invalid_argument&) {
        s.central = false;
        s.shapes = {at(s.h), at(2.0 * s.h)};
      }
    }
    return st;
  };
  const std::vector<Step> steps[2] = {make_steps(o.h), make_steps(o.h / 2.0)};
  Eigen::Matrix<double, 4, 1> z0;
  auto solve_with = [&](const Shape& s, const Pose& X, Eigen::Matrix<double, 4, 1>& v) {
    const SolveResult r = body == 1 ? solve(s, body2, X, o.solver) : solve(body1, s, X, o.solver);
    if (!r.converged()) return false;
    v << r.x_1, r.alpha;
    return true;
  };
  auto fd_at = [&](const std::vector<Step>& st, const Pose& X, Mat4X& D) {
    for (int j = 0; j < p; ++j) {
      Eigen::Matrix<double, 4, 1> v1, v2;
      if (!solve_with(st[j].shapes[0], X, v1) || !solve_with(st[j].shapes[1], X, v2)) return false;
      D.col(j) = st[j].central ? Eigen::Matrix<double, 4, 1>((v1 - v2) / (2.0 * st[j].h))
                               : Eigen::Matrix<double, 4, 1>((-3.0 * z0 + 4.0 * v1 - v2) / (2.0 * st[j].h));
    }
    return true;
  };
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose& X = poses[i];
    ++rep.poses;
    const SolveResult res = solve(body1, body2, X, base);
    if (!res.converged()) continue;
    ++rep.converged;
    z0 << res.x_1, res.alpha;
    const ShapeSensitivity s = shape_sensitivity(res, body1, body2, body);
    if (!s.cond.reliable) ++rep.flagged;
    Mat4X D0(4, p), D1(4, p);
    if (!fd_at(steps[0], X, D0) || !fd_at(steps[1], X, D1)) {
      ++rep.fd_failed;
      continue;
    }
    const Mat4X A = nondim(s.dz_dtheta.topRows<4>());
    auto error_against = [&](const Mat4X& d0, const Mat4X& d1) {
      const Mat4X Bf = nondim((4.0 * d1 - d0) / 3.0);  // Richardson
      return (A - Bf).cwiseAbs().maxCoeff() / std::max(1.0, Bf.cwiseAbs().maxCoeff());
    };
    double err = error_against(D0, D1);
    // As in check_derivatives(): a disagreement must survive steps 10, 100
    // and 1000 times finer, since where x* turns sharply (n = 8 faces, the
    // cone's rim) the truncation at h can itself exceed the tolerance.
    for (double f = 0.1; !(err <= o.tolerance) && f >= 1e-3; f *= 0.1) {
      const std::vector<Step> fine[2] = {make_steps(f * o.h), make_steps(f * o.h / 2.0)};
      if (fd_at(fine[0], X, D0) && fd_at(fine[1], X, D1)) err = std::min(err, error_against(D0, D1));
    }
    detail::record_checked_pose(rep, i, X, res.alpha, s.cond, err, o.tolerance);
  }
  return rep;
}

}  // namespace idcol
