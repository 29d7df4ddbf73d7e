// What is the same with and without baselines: names in report order, the
// list of names for messages, and the refusal of a name this build lacks.
#include "referee/methods.hpp"

#include <algorithm>

namespace idcol::harness {

std::vector<std::string> in_report_order(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const auto& m : boolean_methods())
    if (std::find(names.begin(), names.end(), m) != names.end()) out.push_back(m);
  for (const auto& m : names)
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  return out;
}

std::string known_methods() {
  std::string t;
  for (const auto& m : boolean_methods()) t += m + ", ";
  return t + "oracle";
}

namespace detail {
// The build's answer for a known name (methods_baselines.cpp or methods_none.cpp).
bool build_serves(const std::string& m, const Shape& b1, const Shape& b2, std::string* why);
}  // namespace detail

bool baseline_serves(const std::string& m, const Shape& b1, const Shape& b2, std::string* why) {
  const std::vector<std::string>& names = boolean_methods();
  if (m != "oracle" && std::find(names.begin(), names.end(), m) == names.end()) {
    if (why) *why = "unknown method (expected one of: " + known_methods() + ")";
    return false;
  }
  return detail::build_serves(m, b1, b2, why);
}

}  // namespace idcol::harness
