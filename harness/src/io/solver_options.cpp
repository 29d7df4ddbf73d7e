#include "io/solver_options.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "io/text.hpp"

namespace idcol::harness {

namespace {
SolverOptionField real(const char* n, double SolverOptions::*m) { return {n, m, nullptr, nullptr}; }
SolverOptionField integer(const char* n, int SolverOptions::*m) { return {n, nullptr, m, nullptr}; }
SolverOptionField flag(const char* n, bool SolverOptions::*m) { return {n, nullptr, nullptr, m}; }
}  // namespace

const std::vector<SolverOptionField>& solver_option_fields() {
  using O = SolverOptions;
  static const std::vector<SolverOptionField> fields = {
      real("tolerance", &O::tolerance),
      integer("max_iterations", &O::max_iterations),
      integer("max_iterations_extended", &O::max_iterations_extended),
      real("extension_residual", &O::extension_residual),
      integer("max_restarts", &O::max_restarts),
      real("surrogate_factor", &O::surrogate_factor),
      real("armijo_c", &O::armijo_c),
      real("backtrack_factor", &O::backtrack_factor),
      integer("max_backtracks", &O::max_backtracks),
      real("max_step_s", &O::max_step_s),
      real("max_step_x", &O::max_step_x),
      real("lambda_fraction_to_boundary", &O::lambda_fraction_to_boundary),
      real("lambda_fraction_to_boundary_restart", &O::lambda_fraction_to_boundary_restart),
      real("min_pivot_ratio", &O::min_pivot_ratio),
      real("lm_initial_damping", &O::lm_initial_damping),
      integer("lm_max_trials", &O::lm_max_trials),
      integer("lm_stall_limit", &O::lm_stall_limit),
      real("lm_min_progress", &O::lm_min_progress),
      real("bound_margin", &O::bound_margin),
      flag("continuation", &O::continuation),
      real("continuation_ratio", &O::continuation_ratio),
      flag("rounding_continuation", &O::rounding_continuation),
      flag("support_guess", &O::support_guess),
      flag("barrier", &O::barrier),
      real("barrier_growth", &O::barrier_growth),
      integer("barrier_max_stages", &O::barrier_max_stages),
      integer("barrier_max_newton", &O::barrier_max_newton),
      real("barrier_max_step_x", &O::barrier_max_step_x),
      real("barrier_handover", &O::barrier_handover),
      flag("warm_fallback_to_cold", &O::warm_fallback_to_cold),
      integer("warm_predictor_order", &O::warm_predictor_order),
      real("alpha_max", &O::alpha_max),
      flag("derivatives", &O::derivatives),
  };
  return fields;
}

nlohmann::json solver_json(const SolverOptions& o) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& f : solver_option_fields()) {
    // JSON has no infinity: alpha_max's default (+inf, the early exit off) is written "inf".
    if (f.real) j[f.name] = std::isinf(o.*f.real) ? nlohmann::json(o.*f.real > 0 ? "inf" : "-inf") : nlohmann::json(o.*f.real);
    else if (f.integer) j[f.name] = o.*f.integer;
    else j[f.name] = o.*f.flag;
  }
  return j;
}

SolverOptions solver_from_json(const nlohmann::json& j) {
  SolverOptions o;
  if (!j.is_object()) throw std::invalid_argument("solver: expected an object of solver options, got " + j.dump());
  for (const auto& [key, v] : j.items()) {
    const SolverOptionField* f = nullptr;
    for (const auto& c : solver_option_fields())
      if (key == c.name) f = &c;
    if (!f) throw std::invalid_argument("solver." + key + ": unknown solver option");
    if (f->real && v.is_string() && (v == "inf" || v == "-inf")) {
      o.*f->real = v == "inf" ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
      continue;
    }
    const bool ok = f->real ? v.is_number() : f->integer ? v.is_number_integer() : v.is_boolean();
    if (!ok) throw std::invalid_argument("solver." + key + ": wrong type, got " + v.dump());
    if (f->real) o.*f->real = v.get<double>();
    else if (f->integer) o.*f->integer = v.get<int>();
    else o.*f->flag = v.get<bool>();
  }
  return o;
}

std::string solver_toml(const SolverOptions& o) {
  std::ostringstream s;
  s << "[solver]\n";
  for (const auto& f : solver_option_fields()) {
    s << f.name << " = ";
    if (f.real) s << fmt17(o.*f.real);
    else if (f.integer) s << o.*f.integer;
    else s << (o.*f.flag ? "true" : "false");
    s << "\n";
  }
  return s.str();
}

}  // namespace idcol::harness
