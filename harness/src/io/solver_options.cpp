#include "io/solver_options.hpp"

#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "io/text.hpp"

namespace idcol::harness {

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
    // An integer option fits an int: 2^32 + 10 is refused, not wrapped to 10.
    if (f->integer && (v.is_number_unsigned() ? v.get<std::uint64_t>() > INT_MAX
                                              : v.get<std::int64_t>() < INT_MIN || v.get<std::int64_t>() > INT_MAX))
      throw std::invalid_argument("solver." + key + ": expected an integer in [-2^31, 2^31), got " + v.dump());
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
