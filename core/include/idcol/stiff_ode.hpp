// A stiff ODE integrator: y' = f(t, y), variable step and variable order
// 1-5, with the Jacobian df/dy supplied by the caller (or formed by forward
// differences when none is given). It is the method of MATLAB's ode15s, the
// integrator of the paper's contact-physics examples: the numerical
// differentiation formulas (NDF, or plain BDF) in backward-difference form
// with quasi-constant step size (L. F. Shampine and M. W. Reichelt, "The
// MATLAB ODE Suite", SIAM J. Sci. Comput. 18(1), 1997), written here from
// that description:
//
//  - step n+1 of order k solves, for y = y_{n+1},
//      alpha_k (y - y_p) + sum_{j=1..k} gamma_j D_j = h f(t_{n+1}, y),
//    gamma_j = sum_{i<=j} 1/i, alpha_k = (1 - kappa_k) gamma_k, y_p =
//    sum_{j=0..k} D_j the predictor from the backward differences D_j of the
//    past solution (kappa_k = 0: BDF; the NDF's kappa_k otherwise);
//  - by a simplified Newton iteration with the matrix I - (h / alpha_k) J,
//    J = df/dy evaluated only when an iteration fails to converge with the
//    J it has (J is kept across steps, as ode15s keeps it), at most 4
//    iterations, stopped on a rate-based estimate of the remaining error;
//  - the local error is estimated as (kappa_k gamma_k + 1/(k + 1)) (y - y_p)
//    and the step accepted when its RMS norm, weighted by
//    atol + rtol |y|, is at most 1; the next step size and order (k - 1, k,
//    k + 1, tried after k + 1 steps of one size) are those that allow the
//    largest step;
//  - a change of step size interpolates the differences to the new spacing.
//
// test_stiff_ode.cpp checks it against closed forms (a linear system with
// eigenvalues -1 to -10^4, the Prothero-Robinson problem with lambda =
// -10^6) and against the reference solution of Robertson's chemical
// kinetics (Hairer and Wanner, Solving ODEs II, Sec. IV.1).
#pragma once

#include <functional>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

namespace idcol {

struct StiffOdeOptions {
  /// Error control: the local error estimate e of a step is accepted when
  /// sqrt(mean((e_i / (atol + rtol |y_i|))^2)) <= 1.
  double rtol = 1e-6;
  double atol = 1e-9;
  /// Highest order (1..5). ode15s's default is 5.
  int max_order = 5;
  /// NDF coefficients (ode15s's default) or plain BDF.
  bool ndf = true;
  /// First step; 0 chooses it from f and its change over a trial step.
  double initial_step = 0.0;
  double max_step = std::numeric_limits<double>::infinity();
  long max_steps = 1000000;
  /// Forward differences, when no Jacobian is given: column j is
  /// (f(y + d_j e_j) - f(y)) / d_j with d_j = sqrt(eps) max(|y_j|,
  /// fd_typical).
  double fd_typical = 1.0;
  /// Throws std::invalid_argument naming the field and the value.
  void validate() const;
};

enum class StiffOdeStatus {
  Success,
  /// The step size fell below 16 eps |t|: the solution cannot be continued
  /// to the tolerances asked for (or f is discontinuous there).
  StepTooSmall,
  /// StiffOdeOptions::max_steps accepted steps were taken.
  TooManySteps,
  /// f or the Jacobian reported failure (returned false) at every step size
  /// tried down to the smallest.
  FunctionFailed,
};

const char* to_string(StiffOdeStatus s);

/// The linear algebra of the Newton iterations: factorises I - c J and
/// solves with it. The default is a dense LU with partial pivoting; a
/// system whose Jacobian has structure supplies its own (e.g.
/// MultibodyNewtonSolver in rigid_body.hpp, by block elimination).
class NewtonSystemSolver {
 public:
  virtual ~NewtonSystemSolver() = default;
  /// Factorises I - c J.
  virtual void factorise(double c, const Eigen::MatrixXd& J) = 0;
  /// x = (I - c J)^{-1} b with the last factorisation.
  virtual void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const = 0;
};

/// The default: Eigen's PartialPivLU of the dense I - c J.
class DenseNewtonSolver : public NewtonSystemSolver {
 public:
  void factorise(double c, const Eigen::MatrixXd& J) override;
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const override;

 private:
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

struct StiffOdeStats {
  long steps = 0;              // accepted
  long error_failures = 0;     // steps rejected by the error test
  long newton_failures = 0;    // step attempts whose Newton iteration failed with a fresh J
  long function_failures = 0;  // attempts where f or J returned false
  long rhs_evaluations = 0;    // calls of f (finite-difference columns included)
  long jacobian_evaluations = 0;
  double jacobian_seconds = 0.0;  // wall time forming them (the caller's J, or the differences)
  long lu_decompositions = 0;
  long newton_iterations = 0;
  long restarts = 0;           // rechart hook changed the state: restart at order 1
  int max_order_used = 0;
};

class StiffOdeSolver {
 public:
  using Vector = Eigen::VectorXd;
  using Matrix = Eigen::MatrixXd;
  /// f(t, y) into `f`; false when it cannot be evaluated at (t, y) (the
  /// step is then retried at half the size).
  using Rhs = std::function<bool(double t, const Vector& y, Vector& f)>;
  /// df/dy at (t, y) into `J` (sized n x n by the solver); false as above.
  using Jacobian = std::function<bool(double t, const Vector& y, Matrix& J)>;
  /// Called after every accepted step with (t, y): for output.
  using Observer = std::function<void(double t, const Vector& y)>;
  /// Called after every accepted step; may change y to another chart of
  /// the same point (e.g. a rotation vector of length > pi to the shorter
  /// one) and then returns true: the history no longer applies, and the
  /// integration restarts at order 1 from the new y.
  using Rechart = std::function<bool(double t, Vector& y)>;

  /// `jacobian` may be empty: forward differences then (StiffOdeOptions::fd_typical).
  StiffOdeSolver(Rhs f, Jacobian jacobian, StiffOdeOptions options = {});

  /// The Newton systems' solver (not owned; it must outlive the
  /// integration); null: DenseNewtonSolver.
  void set_newton_solver(NewtonSystemSolver* s) { newton_ = s; }

  /// Integrates from (t0, y) to t_end (> t0) and leaves y(t_end) in y.
  /// `outputs` (increasing, in (t0, t_end]) are reported to `at_output` by
  /// interpolating the step that covers them; every accepted step is
  /// reported to `each_step`. Either may be empty.
  StiffOdeStatus integrate(double t0, double t_end, Vector& y, const std::vector<double>& outputs = {},
                           const Observer& at_output = {}, const Observer& each_step = {},
                           const Rechart& rechart = {});

  const StiffOdeStats& stats() const { return stats_; }
  /// Where the last integrate() stopped (t_end on success).
  double t() const { return t_; }
  /// The step size and order of the last accepted step.
  double last_step() const { return h_last_; }
  int last_order() const { return k_last_; }

 private:
  bool evaluate(double t, const Vector& y, Vector& f);
  bool form_jacobian(double t, const Vector& y, const Vector& fy);
  bool factorise(double c);
  void rescale(double factor);
  void start(double t, const Vector& y, const Vector& fy, double h);
  double initial_step(double t0, double t_end, const Vector& y0, const Vector& f0);
  double norm(const Vector& v, const Vector& scale) const;
  void interpolate(double t, Vector& y) const;
  enum class Attempt { Accepted, Retry, Failed };
  Attempt attempt_step(double t_end, StiffOdeStatus& status);
  void choose_next_step(const Vector& scale, double err);

  Rhs f_;
  Jacobian jac_;
  StiffOdeOptions opt_;
  StiffOdeStats stats_;
  int n_ = 0;
  double t_ = 0.0, h_ = 0.0, h_last_ = 0.0;
  int k_ = 1, k_last_ = 1;
  int equal_steps_ = 0;
  Matrix D_;  // backward differences, n x (max_order + 3)
  Matrix J_;
  bool jac_current_ = false;  // J_ was formed at the current point (a failure will not be cured by a new one)
  DenseNewtonSolver dense_;
  NewtonSystemSolver* newton_ = nullptr;
  double lu_c_ = 0.0;
  bool lu_valid_ = false;
  Vector y_, d_, f_tmp_, dy_, rhs_tmp_, scale_, ypred_, psi_;
  double kappa_[6] = {0, 0, 0, 0, 0, 0};
  double gamma_[7] = {0, 0, 0, 0, 0, 0, 0};
  double alpha_[6] = {0, 0, 0, 0, 0, 0};
  double err_const_[7] = {0, 0, 0, 0, 0, 0, 0};
  double newton_tol_ = 0.03;
  double err_last_ = 0.0;  // the error norm of the last accepted step
};

}  // namespace idcol
