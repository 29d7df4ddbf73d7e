#include "idcol/solver.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>

#include "solver_impl.hpp"

namespace idcol {

const char* to_string(SolveStatus s) {
  switch (s) {
    case SolveStatus::Converged: return "converged";
    case SolveStatus::Concentric: return "concentric";
    case SolveStatus::IterationLimit: return "iteration_limit";
    case SolveStatus::LineSearchFailed: return "line_search_failed";
    case SolveStatus::NumericalFailure: return "numerical_failure";
    case SolveStatus::SpuriousRoot: return "spurious_root";
    case SolveStatus::InvalidInput: return "invalid_input";
    case SolveStatus::Separated: return "separated";
  }
  return "unknown";
}

SolveResult solve(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options, WarmStart* warm,
                  TraceSink* trace) {
  return std::visit([&](const auto& a, const auto& b) { return detail::solve_pair(a, b, X_12, options, warm, trace); }, body1, body2);
}

ContactPair::ContactPair(Shape body1, Shape body2, SolverOptions options)
    : b1_(std::move(body1)), b2_(std::move(body2)), opt_(options) {
  opt_.validate();
}

SolveResult ContactPair::solve(const Pose& X_12) { return idcol::solve(b1_, b2_, X_12, opt_, &warm_); }

SolveResult ContactPair::solve_cold(const Pose& X_12) const { return idcol::solve(b1_, b2_, X_12, opt_, nullptr); }

namespace detail {

SolveResult solve_cold_resumed(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options,
                               const ColdResume& resume) {
  return std::visit([&](const auto& a, const auto& b) { return solve_pair_resumed(a, b, X_12, options, resume); }, body1, body2);
}

bool separated_bound(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options,
                     double& lower) {
  return std::visit([&](const auto& a, const auto& b) { return pair_separated_at_start(a, b, X_12, options, lower); },
                    body1, body2);
}

SolveResult solve_finished(const Shape& body1, const Shape& body2, const Pose& X_12, const SolverOptions& options,
                           const Vec6& z, int iterations) {
  return std::visit([&](const auto& a, const auto& b) { return solve_pair_finished(a, b, X_12, options, z, iterations); },
                    body1, body2);
}

// PairSolver::lm_step's linear algebra (lm_system.hpp), which the batch
// lanes call too. Each works on local copies, as lm_step did when it held
// the code: the same sums in the same order.
void lm_normal_equations(const double* J, const double* F, double initial_damping, double* JtJ, double* g, double* mu) {
  const Mat6 Jc = Eigen::Map<const Mat6r>(J);  // column-major, as the step's sums have always been formed
  const Vec6 Fv = Eigen::Map<const Vec6>(F);
  const Mat6 A = Jc.transpose() * Jc;
  const Vec6 b = Jc.transpose() * Fv;
  Eigen::Map<Mat6>{JtJ} = A;
  Eigen::Map<Vec6>{g} = b;
  *mu = initial_damping * std::max(A.diagonal().maxCoeff(), 1e-300);
}

bool lm_direction(const double* JtJ, const double* g, double mu, double* dz) {
  Mat6 A = Eigen::Map<const Mat6>(JtJ);
  const Vec6 b = Eigen::Map<const Vec6>(g);
  A.diagonal().array() += mu;
  const Vec6 d = A.llt().solve(-b);
  Eigen::Map<Vec6>{dz} = d;
  return d.allFinite();
}

}  // namespace detail
}  // namespace idcol
