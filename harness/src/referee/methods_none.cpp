// The methods of a build without baselines (-DIDCOL_BUILD_BASELINES=OFF):
// none, so that a scene asking for one is refused when it is read.
#include "referee/methods.hpp"

namespace idcol::harness {

bool baselines_available() { return false; }

std::uint64_t baseline_aborts_trapped() { return 0; }

const std::vector<std::string>& boolean_methods() {
  static const std::vector<std::string> none;
  return none;
}

std::string method_label(const std::string& m) { return m; }

bool answers_gap(const std::string&) { return false; }

namespace detail {
bool build_serves(const std::string&, const Shape&, const Shape&, std::string* why) {
  if (why) *why = "this build has no baselines (configured with -DIDCOL_BUILD_BASELINES=OFF)";
  return false;
}
}  // namespace detail

}  // namespace idcol::harness
