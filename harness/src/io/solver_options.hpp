// Every SolverOptions field, listed once: the scene reader ([solver] table),
// the results and failure files ("solver") and the scene writer all go
// through this list, so a scene can set any option and a results file says
// how it was made. A new option is added here and nowhere else in the harness.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"

namespace idcol::harness {

/// One field of SolverOptions: its name in scenes and results files and
/// where it lives (exactly one of the three member pointers is set).
struct SolverOptionField {
  const char* name;
  double SolverOptions::*real = nullptr;
  int SolverOptions::*integer = nullptr;
  bool SolverOptions::*flag = nullptr;
};

/// Every field of SolverOptions, in the order of options.hpp.
const std::vector<SolverOptionField>& solver_option_fields();

/// All options as a JSON object, one key per field.
nlohmann::json solver_json(const SolverOptions& o);
/// The inverse of solver_json; a key missing (files written before an option
/// existed) keeps the option's default. Throws std::invalid_argument naming
/// an unknown key or a value of the wrong type.
SolverOptions solver_from_json(const nlohmann::json& j);
/// A [solver] TOML table holding every option (numbers at 17 digits).
std::string solver_toml(const SolverOptions& o);

}  // namespace idcol::harness
