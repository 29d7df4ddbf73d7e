// Every SolverOptions field, listed once in core (idcol/options_fields.hpp):
// the scene reader ([solver] table), the results and failure files
// ("solver") and the scene writer all walk that list, so a scene can set any
// option and a results file says how it was made. A new option needs nothing
// here.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "idcol/options_fields.hpp"

namespace idcol::harness {


/// All options as a JSON object, one key per field.
nlohmann::json solver_json(const SolverOptions& o);
/// The inverse of solver_json; a key missing (files written before an option
/// existed) keeps the option's default. Throws std::invalid_argument naming
/// an unknown key or a value of the wrong type.
SolverOptions solver_from_json(const nlohmann::json& j);
/// A [solver] TOML table holding every option (numbers at 17 digits).
std::string solver_toml(const SolverOptions& o);

}  // namespace idcol::harness
