// SolverOptions' fields, listed once: name, type and the values each one
// accepts. SolverOptions::validate(), the harness's scene reader and results
// files, and the Python module all expand this list, so an option added to
// SolverOptions (options.hpp, with its reason) is added here, in the same
// place of the order, and everything else follows. options.cpp refuses to
// compile if the list and the struct disagree (a member missing from the
// list, a listed name in another place or with another type).
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <string>

#include "idcol/options.hpp"

namespace idcol {

/// The values an option accepts, for validate() and its message. A real is
/// in [lo, hi] (either end open), finite unless +inf is accepted; an
/// integer in [lo, hi], lo raised to another option's value where one is
/// named; a flag accepts both values.
struct OptionRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  /// +inf is a value (alpha_max: the early exit off). NaN never is.
  bool infinity_ok = false;
  /// A lower bound that is another option's value (max_iterations_extended
  /// >= max_iterations), with that option's name for the message.
  int SolverOptions::*lo_option = nullptr;
  const char* lo_option_name = nullptr;
  /// Appended to the message in parentheses.
  const char* note = nullptr;
};

/// The vocabulary of the list below (each returns an OptionRange).
namespace option_range {
/// Any value of the type (flags).
constexpr OptionRange any() { return {}; }
/// Finite and > 0.
constexpr OptionRange positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
/// Finite and >= lo.
constexpr OptionRange at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
/// Finite and > lo.
constexpr OptionRange above(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, false}; }
/// In (lo, hi).
constexpr OptionRange open(double lo, double hi) { return {lo, hi, true, true}; }
/// In [lo, hi).
constexpr OptionRange closed_open(double lo, double hi) { return {lo, hi, false, true}; }
/// An integer in [lo, hi].
constexpr OptionRange count(int lo, int hi) { return {double(lo), double(hi), false, false}; }
/// An integer in [the option `from`, hi].
constexpr OptionRange count_from(int SolverOptions::*from, const char* from_name, int hi) {
  OptionRange r = count(0, hi);
  r.lo_option = from;
  r.lo_option_name = from_name;
  return r;
}
/// > 0, +inf included, with a note on what +inf means.
constexpr OptionRange positive_or_inf(const char* note) {
  OptionRange r = positive();
  r.infinity_ok = true;
  r.note = note;
  return r;
}
}  // namespace option_range

// X(type, name, range): every field of SolverOptions in the order of
// options.hpp; `range` is a call into option_range (expanded as
// option_range::range, so constants are written SolverOptions::k...).
// Checked, in this order, by validate().
#define IDCOL_SOLVER_OPTION_FIELDS(X)                                                                           \
  X(double, tolerance, positive())                                                                              \
  X(int, max_iterations, count(1, SolverOptions::kMaxIterationCount))                                           \
  X(int, max_iterations_extended,                                                                               \
    count_from(&SolverOptions::max_iterations, "max_iterations", SolverOptions::kMaxIterationCount))            \
  X(double, extension_residual, at_least(0.0))                                                                  \
  X(int, max_restarts, count(0, SolverOptions::kMaxIterationCount))                                             \
  X(double, surrogate_factor, at_least(1.0))                                                                    \
  X(double, armijo_c, open(0.0, 0.5))                                                                           \
  X(double, backtrack_factor, open(0.0, 1.0))                                                                   \
  X(int, max_backtracks, count(0, SolverOptions::kMaxTrialCount))                                               \
  X(double, max_step_s, positive())                                                                             \
  X(double, max_step_x, positive())                                                                             \
  X(double, lambda_fraction_to_boundary, open(0.0, 1.0))                                                        \
  X(double, lambda_fraction_to_boundary_restart, open(0.0, 1.0))                                                \
  X(double, min_pivot_ratio, closed_open(0.0, 1.0))                                                             \
  X(double, lm_initial_damping, positive())                                                                     \
  X(int, lm_max_trials, count(1, SolverOptions::kMaxTrialCount))                                                \
  X(int, lm_stall_limit, count(0, SolverOptions::kMaxIterationCount))                                           \
  X(double, lm_min_progress, closed_open(0.0, 1.0))                                                             \
  X(double, bound_margin, at_least(0.0))                                                                        \
  X(bool, continuation, any())                                                                                  \
  X(double, continuation_ratio, at_least(SolverOptions::kMinContinuationRatio))                                 \
  X(bool, rounding_continuation, any())                                                                         \
  X(bool, support_guess, any())                                                                                 \
  X(bool, barrier, any())                                                                                       \
  X(double, barrier_growth, above(1.0))                                                                         \
  X(int, barrier_max_stages, count(1, SolverOptions::kMaxTrialCount))                                           \
  X(int, barrier_max_newton, count(1, SolverOptions::kMaxIterationCount))                                       \
  X(double, barrier_max_step_x, positive())                                                                     \
  X(double, barrier_handover, open(0.0, 1.0))                                                                   \
  X(bool, warm_fallback_to_cold, any())                                                                         \
  X(int, warm_predictor_order, count(0, 2))                                                                     \
  X(bool, derivatives, any())                                                                                   \
  X(double, alpha_max, positive_or_inf("+inf switches the early exit off"))

/// One field of SolverOptions, for code that walks the list at run time:
/// its name (in scenes, results files and Python), where it lives (exactly
/// one of the three member pointers is set) and the values it accepts.
struct SolverOptionField {
  const char* name = nullptr;
  double SolverOptions::*real = nullptr;
  int SolverOptions::*integer = nullptr;
  bool SolverOptions::*flag = nullptr;
  OptionRange range;

  /// What the field must be, as validate()'s messages say it: "finite and
  /// > 0", "in (0, 1)", "an integer in [max_iterations = 25, 10000]" (the
  /// bound another option sets is read from `o`), "true or false".
  std::string expected(const SolverOptions& o = SolverOptions{}) const;
  /// Whether the field's value in `o` is one it accepts.
  bool accepts(const SolverOptions& o) const;
};

namespace detail {
constexpr SolverOptionField option_field(const char* n, double SolverOptions::*m, OptionRange r) {
  return {n, m, nullptr, nullptr, r};
}
constexpr SolverOptionField option_field(const char* n, int SolverOptions::*m, OptionRange r) {
  return {n, nullptr, m, nullptr, r};
}
constexpr SolverOptionField option_field(const char* n, bool SolverOptions::*m, OptionRange r) {
  return {n, nullptr, nullptr, m, r};
}
#define IDCOL_DETAIL_OPTION_FIELD(T, name, range) \
  option_field(#name, &SolverOptions::name, option_range::range),
inline constexpr std::array kSolverOptionFields{IDCOL_SOLVER_OPTION_FIELDS(IDCOL_DETAIL_OPTION_FIELD)};
#undef IDCOL_DETAIL_OPTION_FIELD
}  // namespace detail

/// Every field of SolverOptions, in the order of options.hpp.
constexpr const auto& solver_option_fields() { return detail::kSolverOptionFields; }
inline constexpr std::size_t kSolverOptionFieldCount = detail::kSolverOptionFields.size();

}  // namespace idcol
