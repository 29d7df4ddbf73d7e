// The methods of a build with baselines: the competitor table's rows and the
// baselines' exact oracles (compiled where the idcol_baselines target exists).
#include "idcol_baselines/baselines.hpp"
#include "referee/methods.hpp"

namespace idcol::harness {

bool baselines_available() { return true; }

std::uint64_t baseline_aborts_trapped() { return baselines::trapped_aborts(); }

const std::vector<std::string>& boolean_methods() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const baselines::Competitor* c : baselines::competitors()) n.emplace_back(c->name);
    return n;
  }();
  return names;
}

std::string method_label(const std::string& m) {
  if (const baselines::Competitor* c = baselines::find_competitor(m)) return c->label;
  return m;
}

bool answers_gap(const std::string& m) {
  if (const baselines::Competitor* c = baselines::find_competitor(m)) return c->answers.signed_distance;
  return false;
}

namespace detail {
bool build_serves(const std::string& m, const Shape& b1, const Shape& b2, std::string* why) {
  if (m == "oracle") {
    if (baselines::oracle_for(b1, b2) != baselines::OracleMethod::None) return true;
    if (why) *why = "no exact oracle for " + describe(b1) + " with " + describe(b2) + " (exact ellipsoids and polytopes only)";
    return false;
  }
  return baselines::can_serve(baselines::competitor(m), b1, b2, why);
}
}  // namespace detail

}  // namespace idcol::harness
