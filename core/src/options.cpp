#include "idcol/options.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>

namespace idcol {

namespace {
[[noreturn]] void bad_option(const char* field, double v, const char* expected) {
  std::ostringstream os;
  os << std::setprecision(17) << "SolverOptions: field '" << field << "' must be " << expected << ", got " << v;
  throw std::invalid_argument(os.str());
}
void positive(const char* f, double v) {
  if (!std::isfinite(v) || !(v > 0.0)) bad_option(f, v, "finite and > 0");
}
void in_open_unit(const char* f, double v) {
  if (!std::isfinite(v) || !(v > 0.0 && v < 1.0)) bad_option(f, v, "in (0, 1)");
}
void at_least(const char* f, double v, double lo) {
  if (!std::isfinite(v) || !(v >= lo)) bad_option(f, v, (">= " + std::to_string(lo)).c_str());
}
/// An iteration count: at least lo and at most hi, so that a solve's work
/// stays bounded (SolverOptions, "Work").
void count_in(const char* f, int v, int lo, int hi) {
  if (v < lo || v > hi)
    bad_option(f, v, ("an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]").c_str());
}
}  // namespace

void SolverOptions::validate() const {
  positive("tolerance", tolerance);
  count_in("max_iterations", max_iterations, 1, kMaxIterationCount);
  count_in("max_restarts", max_restarts, 0, kMaxIterationCount);
  count_in("max_iterations_extended", max_iterations_extended, max_iterations, kMaxIterationCount);
  if (!std::isfinite(extension_residual) || !(extension_residual >= 0.0)) bad_option("extension_residual", extension_residual, "finite and >= 0");
  at_least("surrogate_factor", surrogate_factor, 1.0);
  if (!std::isfinite(armijo_c) || !(armijo_c > 0.0 && armijo_c < 0.5)) bad_option("armijo_c", armijo_c, "in (0, 0.5)");
  in_open_unit("backtrack_factor", backtrack_factor);
  count_in("max_backtracks", max_backtracks, 0, kMaxTrialCount);
  positive("max_step_s", max_step_s);
  positive("max_step_x", max_step_x);
  in_open_unit("lambda_fraction_to_boundary", lambda_fraction_to_boundary);
  in_open_unit("lambda_fraction_to_boundary_restart", lambda_fraction_to_boundary_restart);
  if (!std::isfinite(min_pivot_ratio) || !(min_pivot_ratio >= 0.0 && min_pivot_ratio < 1.0))
    bad_option("min_pivot_ratio", min_pivot_ratio, "in [0, 1)");
  positive("lm_initial_damping", lm_initial_damping);
  count_in("lm_max_trials", lm_max_trials, 1, kMaxTrialCount);
  count_in("lm_stall_limit", lm_stall_limit, 0, kMaxIterationCount);
  if (!std::isfinite(lm_min_progress) || !(lm_min_progress >= 0.0 && lm_min_progress < 1.0))
    bad_option("lm_min_progress", lm_min_progress, "in [0, 1)");
  if (!std::isfinite(bound_margin) || !(bound_margin >= 0.0)) bad_option("bound_margin", bound_margin, "finite and >= 0");
  if (!std::isfinite(continuation_ratio) || !(continuation_ratio >= kMinContinuationRatio))
    bad_option("continuation_ratio", continuation_ratio, "finite and >= 1.01");
  if (!std::isfinite(barrier_growth) || !(barrier_growth > 1.0)) bad_option("barrier_growth", barrier_growth, "finite and > 1");
  count_in("barrier_max_stages", barrier_max_stages, 1, kMaxTrialCount);
  count_in("barrier_max_newton", barrier_max_newton, 1, kMaxIterationCount);
  positive("barrier_max_step_x", barrier_max_step_x);
  in_open_unit("barrier_handover", barrier_handover);
  if (warm_predictor_order < 0 || warm_predictor_order > 2) bad_option("warm_predictor_order", warm_predictor_order, "0, 1 or 2");
  if (std::isnan(alpha_max) || !(alpha_max > 0.0)) bad_option("alpha_max", alpha_max, "> 0 (+inf switches the early exit off)");
}

}  // namespace idcol
