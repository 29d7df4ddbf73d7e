// The methods the referee can call besides the solver: the competitors of
// the baselines' table (FCL, libccd) and the exact oracle. What a build has
// is fixed by the files CMake compiled: methods_baselines.cpp where the
// baselines were built, methods_none.cpp where they were not; this header
// and every caller are the same in both builds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "idcol/shapes.hpp"

namespace idcol::harness {

/// Whether this build has the baselines (FCL, libccd, the GLPK oracles).
bool baselines_available();

/// Baseline queries whose library aborted on an internal assertion (FCL's
/// EPA near touching contact), trapped and counted as failed queries; 0
/// without baselines.
std::uint64_t baseline_aborts_trapped();

/// The competitors a [baselines] table can name, in report order: the names
/// of the competitor table this build compiled (baselines/registry.hpp;
/// empty without baselines); "oracle" is the exact oracle besides them.
/// Every list of names in messages and tables comes from here.
const std::vector<std::string>& boolean_methods();
/// "fcl_collide, fcl_distance, ..., oracle".
std::string known_methods();
/// A method's row label in tables (the registry's); the name itself for a
/// method this build does not know (a results file from another build).
std::string method_label(const std::string& m);
/// Whether a method answers the gap when separated (the registry's
/// Answers::signed_distance), so that it agrees by the gap's sign; false for
/// a method this build does not know.
bool answers_gap(const std::string& m);
/// `names` in report order, each once: those boolean_methods() knows in its order, then
/// the others as given.
std::vector<std::string> in_report_order(const std::vector<std::string>& names);

/// Whether method m ("fcl_collide", ..., "oracle") serves the pair; if not,
/// `why` says why. Unknown names are not served ("unknown method", with the
/// known ones).
bool baseline_serves(const std::string& m, const Shape& b1, const Shape& b2, std::string* why);

}  // namespace idcol::harness
