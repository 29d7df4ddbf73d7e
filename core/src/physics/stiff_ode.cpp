#include "idcol/stiff_ode.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace idcol {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
/// Newton iterations per step attempt (ode15s: 4).
constexpr int kMaxNewton = 4;
/// The largest growth of the step size at one change.
constexpr double kMaxGrowth = 10.0;
/// The smallest shrink after a rejected step.
constexpr double kMinShrink = 0.2;
/// A step size change below this growth is not made (it would cost an LU
/// decomposition and buy little).
constexpr double kMinGrowth = 1.2;
/// Safety factor on the step size the error estimate allows.
constexpr double kSafety = 0.9;

[[noreturn]] void bad(const std::string& field, double v, const std::string& why) {
  throw std::invalid_argument("StiffOdeOptions: field '" + field + "' " + why + ", got " + std::to_string(v));
}

/// s (s + 1) ... (s + j - 1) / j!: the Newton backward-difference basis.
double backward_basis(double s, int j) {
  double p = 1.0;
  for (int l = 0; l < j; ++l) p *= (s + l) / (l + 1);
  return p;
}

double binomial(int n, int k) {
  double b = 1.0;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

}  // namespace

void StiffOdeOptions::validate() const {
  if (!(rtol > 0.0) || !std::isfinite(rtol)) bad("rtol", rtol, "must be finite and > 0");
  if (rtol < 100 * kEps) bad("rtol", rtol, "must be >= 100 eps (2.2e-14)");
  if (!(atol > 0.0) || !std::isfinite(atol)) bad("atol", atol, "must be finite and > 0");
  if (max_order < 1 || max_order > 5) bad("max_order", max_order, "must be in 1..5");
  if (!(initial_step >= 0.0) || !std::isfinite(initial_step)) bad("initial_step", initial_step, "must be finite and >= 0");
  if (!(max_step > 0.0)) bad("max_step", max_step, "must be > 0");
  if (max_steps < 1) bad("max_steps", static_cast<double>(max_steps), "must be >= 1");
  if (!(fd_typical > 0.0) || !std::isfinite(fd_typical)) bad("fd_typical", fd_typical, "must be finite and > 0");
}

const char* to_string(StiffOdeStatus s) {
  switch (s) {
    case StiffOdeStatus::Success: return "success";
    case StiffOdeStatus::StepTooSmall: return "step_too_small";
    case StiffOdeStatus::TooManySteps: return "too_many_steps";
    case StiffOdeStatus::FunctionFailed: return "function_failed";
  }
  return "unknown";
}

StiffOdeSolver::StiffOdeSolver(Rhs f, Jacobian jacobian, StiffOdeOptions options)
    : f_(std::move(f)), jac_(std::move(jacobian)), opt_(options) {
  opt_.validate();
  if (!f_) throw std::invalid_argument("StiffOdeSolver: no right-hand side f");
  // NDF coefficients kappa_k (Shampine and Reichelt, Table 1); 0 is BDF.
  const double ndf[6] = {0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0};
  for (int k = 0; k <= 6; ++k) gamma_[k] = k == 0 ? 0.0 : gamma_[k - 1] + 1.0 / k;
  for (int k = 0; k <= 5; ++k) {
    kappa_[k] = opt_.ndf ? ndf[k] : 0.0;
    alpha_[k] = (1.0 - kappa_[k]) * gamma_[k];
  }
  for (int k = 0; k <= 6; ++k) err_const_[k] = (k <= 5 ? kappa_[k] : 0.0) * gamma_[k] + 1.0 / (k + 1);
}

double StiffOdeSolver::norm(const Vector& v, const Vector& scale) const {
  return std::sqrt((v.array() / scale.array()).square().mean());
}

bool StiffOdeSolver::evaluate(double t, const Vector& y, Vector& f) {
  ++stats_.rhs_evaluations;
  f.resize(n_);
  return f_(t, y, f) && f.allFinite();
}

/// J at (t, y), whose f is fy: the caller's, or forward differences.
bool StiffOdeSolver::form_jacobian(double t, const Vector& y, const Vector& fy) {
  ++stats_.jacobian_evaluations;
  const auto t0 = std::chrono::steady_clock::now();
  J_.resize(n_, n_);
  lu_valid_ = false;
  jac_current_ = true;
  bool ok = true;
  if (jac_) {
    ok = jac_(t, y, J_) && J_.allFinite();
  } else {
    Vector yp = y, fp(n_);
    for (int j = 0; j < n_ && ok; ++j) {
      const double d = std::sqrt(kEps) * std::max(std::abs(y[j]), opt_.fd_typical);
      yp[j] = y[j] + d;
      const double dj = yp[j] - y[j];  // the step as represented
      ok = evaluate(t, yp, fp);
      J_.col(j) = (fp - fy) / dj;
      yp[j] = y[j];
    }
  }
  stats_.jacobian_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return ok;
}

void DenseNewtonSolver::factorise(double c, const Eigen::MatrixXd& J) {
  lu_.compute(Eigen::MatrixXd::Identity(J.rows(), J.cols()) - c * J);
}

void DenseNewtonSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const { x = lu_.solve(b); }

bool StiffOdeSolver::factorise(double c) {
  ++stats_.lu_decompositions;
  (newton_ ? newton_ : &dense_)->factorise(c, J_);
  lu_c_ = c;
  lu_valid_ = true;
  return true;
}

/// The backward differences D_0..D_k re-spaced from h to factor * h: the
/// interpolating polynomial of the past solution evaluated at the new
/// spacing, D'_i = sum_{m=0..i} (-1)^m C(i, m) p(t_n - m factor h).
void StiffOdeSolver::rescale(double factor) {
  if (factor == 1.0) return;
  const int k = k_;
  Matrix T = Matrix::Zero(k + 1, k + 1);
  for (int i = 0; i <= k; ++i)
    for (int j = 0; j <= k; ++j) {
      double s = 0.0;
      for (int m = 0; m <= i; ++m) s += ((m % 2) ? -1.0 : 1.0) * binomial(i, m) * backward_basis(-m * factor, j);
      T(i, j) = s;
    }
  D_.leftCols(k + 1) = D_.leftCols(k + 1) * T.transpose();
  h_ *= factor;
  lu_valid_ = false;
  equal_steps_ = 0;
}

void StiffOdeSolver::start(double t, const Vector& y, const Vector& fy, double h) {
  t_ = t;
  h_ = h;
  k_ = 1;
  equal_steps_ = 0;
  D_.setZero(n_, opt_.max_order + 3);
  D_.col(0) = y;
  D_.col(1) = h * fy;
  lu_valid_ = false;
}

/// The first step: from |f| and the change of f over a trial Euler step,
/// the step whose local error of order 1 is about 0.01 of the tolerance.
double StiffOdeSolver::initial_step(double t0, double t_end, const Vector& y0, const Vector& f0) {
  const Vector scale = opt_.atol + opt_.rtol * y0.array().abs();
  const double d0 = norm(y0, scale), d1 = norm(f0, scale);
  double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0 = std::min(h0, t_end - t0);
  Vector y1 = y0 + h0 * f0, f1(n_);
  if (!evaluate(t0 + h0, y1, f1)) return h0 * 1e-3;
  const double d2 = norm(f1 - f0, scale) / h0;
  const double dm = std::max(d1, d2);
  const double h1 = dm <= 1e-15 ? std::max(1e-6, h0 * 1e-3) : std::sqrt(0.01 / dm);
  return std::min({100.0 * h0, h1, opt_.max_step, t_end - t0});
}

/// y at t, in [t_n - k h, t_n], from the backward differences of the
/// accepted steps (Newton's backward-difference formula).
void StiffOdeSolver::interpolate(double t, Vector& y) const {
  const double s = (t - t_) / h_;
  y = D_.col(0);
  for (int j = 1; j <= k_; ++j) y += backward_basis(s, j) * D_.col(j);
}

StiffOdeSolver::Attempt StiffOdeSolver::attempt_step(double t_end, StiffOdeStatus& status) {
  const double hmin = 16.0 * kEps * std::max(std::abs(t_), 1e-300);
  if (h_ < hmin) {
    status = StiffOdeStatus::StepTooSmall;
    return Attempt::Failed;
  }
  if (t_ + h_ > t_end) rescale((t_end - t_) / h_);
  const double t_new = t_ + h_ >= t_end ? t_end : t_ + h_;
  const int k = k_;
  ypred_ = D_.leftCols(k + 1).rowwise().sum();
  psi_ = Vector::Zero(n_);
  for (int j = 1; j <= k; ++j) psi_ += gamma_[j] * D_.col(j);
  psi_ /= alpha_[k];
  const double c = h_ / alpha_[k];
  scale_ = opt_.atol + opt_.rtol * ypred_.array().abs();
  if (!lu_valid_ || lu_c_ != c) factorise(c);

  y_ = ypred_;
  d_ = Vector::Zero(n_);
  bool converged = false, function_failed = false;
  double dy_norm_old = -1.0, rate = 0.0;
  for (int it = 0; it < kMaxNewton; ++it) {
    ++stats_.newton_iterations;
    if (!evaluate(t_new, y_, f_tmp_)) {
      function_failed = true;
      break;
    }
    rhs_tmp_ = c * f_tmp_ - psi_ - d_;
    (newton_ ? newton_ : &dense_)->solve(rhs_tmp_, dy_);
    const double dy_norm = norm(dy_, scale_);
    // A correction a thousandth of the tolerance ends the iteration whatever
    // the rate: corrections at the level of rounding (a body in free
    // flight, whose predictor is exact) have no meaningful rate.
    const bool negligible = dy_norm <= 1e-3 * newton_tol_;
    if (it > 0 && !negligible) {
      rate = dy_norm / dy_norm_old;
      if (rate >= 1.0 || std::pow(rate, kMaxNewton - it) / (1.0 - rate) * dy_norm > newton_tol_) break;
    }
    y_ += dy_;
    d_ += dy_;
    if (negligible || (it > 0 && rate / (1.0 - rate) * dy_norm < newton_tol_)) {
      converged = true;
      break;
    }
    dy_norm_old = dy_norm;
  }
  if (function_failed) {
    ++stats_.function_failures;
    rescale(0.5);
    equal_steps_ = 0;
    if (h_ < hmin) {
      status = StiffOdeStatus::FunctionFailed;
      return Attempt::Failed;
    }
    return Attempt::Retry;
  }
  if (!converged) {
    if (!jac_current_) {  // a fresh J at the last accepted point, then the same step again
      Vector fy(n_);
      const Vector yn = D_.col(0);
      if (!evaluate(t_, yn, fy) || !form_jacobian(t_, yn, fy)) {
        ++stats_.function_failures;
        status = StiffOdeStatus::FunctionFailed;
        return Attempt::Failed;
      }
      return Attempt::Retry;
    }
    ++stats_.newton_failures;
    rescale(0.5);
    equal_steps_ = 0;
    return Attempt::Retry;
  }

  scale_ = opt_.atol + opt_.rtol * y_.array().abs();
  const double err = err_const_[k] * norm(d_, scale_);
  if (err > 1.0) {
    ++stats_.error_failures;
    rescale(std::max(kMinShrink, kSafety * std::pow(err, -1.0 / (k + 1))));
    equal_steps_ = 0;
    return Attempt::Retry;
  }
  // Accepted: the differences of the new point (D_{k+1} = y - y_pred).
  D_.col(k + 2) = d_ - D_.col(k + 1);
  D_.col(k + 1) = d_;
  for (int j = k; j >= 0; --j) D_.col(j) += D_.col(j + 1);
  t_ = t_new;
  h_last_ = h_;
  k_last_ = k;
  ++equal_steps_;
  ++stats_.steps;
  stats_.max_order_used = std::max(stats_.max_order_used, k);
  jac_current_ = false;
  err_last_ = err;
  return Attempt::Accepted;
}

/// After k + 1 steps of one size: the order among k - 1, k, k + 1 whose
/// error estimate allows the largest next step, and that step.
void StiffOdeSolver::choose_next_step(const Vector& scale, double err) {
  const int k = k_;
  if (equal_steps_ < k + 1) return;
  auto factor_for = [](double e, int order) { return e > 0.0 ? std::pow(e, -1.0 / (order + 1)) : kMaxGrowth / kSafety; };
  double best = factor_for(err, k);
  int best_k = k;
  if (k > 1) {
    const double f = factor_for(err_const_[k - 1] * norm(D_.col(k), scale), k - 1);
    if (f > best) best = f, best_k = k - 1;
  }
  if (k < opt_.max_order) {
    const double f = factor_for(err_const_[k + 1] * norm(D_.col(k + 2), scale), k + 1);
    if (f > best) best = f, best_k = k + 1;
  }
  double factor = std::min(kMaxGrowth, kSafety * best);
  factor = std::min(factor, opt_.max_step / h_);
  if (best_k == k && factor >= 1.0 && factor < kMinGrowth) return;
  k_ = best_k;
  equal_steps_ = 0;
  rescale(factor);
}

StiffOdeStatus StiffOdeSolver::integrate(double t0, double t_end, Vector& y, const std::vector<double>& outputs,
                                         const Observer& at_output, const Observer& each_step, const Rechart& rechart) {
  if (!(t_end > t0) || !std::isfinite(t0) || !std::isfinite(t_end))
    throw std::invalid_argument("StiffOdeSolver::integrate: need finite t0 < t_end, got t0 = " + std::to_string(t0) +
                                ", t_end = " + std::to_string(t_end));
  for (std::size_t i = 0; i < outputs.size(); ++i)
    if (!(outputs[i] > t0 && outputs[i] <= t_end) || (i > 0 && !(outputs[i] > outputs[i - 1])))
      throw std::invalid_argument("StiffOdeSolver::integrate: outputs[" + std::to_string(i) + "] = " +
                                  std::to_string(outputs[i]) + " is not increasing inside (t0, t_end]");
  if (!y.allFinite()) throw std::invalid_argument("StiffOdeSolver::integrate: y0 has a NaN or Inf entry");
  n_ = static_cast<int>(y.size());
  stats_ = StiffOdeStats{};
  t_ = t0;
  Vector f0(n_);
  if (!evaluate(t0, y, f0)) return StiffOdeStatus::FunctionFailed;
  const double h0 = opt_.initial_step > 0.0 ? std::min(opt_.initial_step, t_end - t0)
                                            : initial_step(t0, t_end, y, f0);
  start(t0, y, f0, std::min(h0, opt_.max_step));
  if (!form_jacobian(t0, y, f0)) return StiffOdeStatus::FunctionFailed;
  std::size_t next_out = 0;
  Vector yo(n_);
  StiffOdeStatus status = StiffOdeStatus::Success;
  while (t_ < t_end) {
    if (stats_.steps >= opt_.max_steps) {
      status = StiffOdeStatus::TooManySteps;
      break;
    }
    const Attempt a = attempt_step(t_end, status);
    if (a == Attempt::Failed) break;
    if (a == Attempt::Retry) continue;
    // Outputs inside the accepted step, from the interpolant through the
    // new point and the k before it; then the next step's size and order.
    for (; next_out < outputs.size() && outputs[next_out] <= t_; ++next_out) {
      interpolate(outputs[next_out], yo);
      if (at_output) at_output(outputs[next_out], yo);
    }
    choose_next_step(scale_, err_last_);
    if (each_step) each_step(t_, D_.col(0));
    if (rechart) {
      Vector yr = D_.col(0);
      if (rechart(t_, yr)) {
        ++stats_.restarts;
        Vector fr(n_);
        if (!evaluate(t_, yr, fr) || !form_jacobian(t_, yr, fr)) {
          status = StiffOdeStatus::FunctionFailed;
          break;
        }
        start(t_, yr, fr, h_);
      }
    }
  }
  y = D_.col(0);
  return status;
}

}  // namespace idcol
