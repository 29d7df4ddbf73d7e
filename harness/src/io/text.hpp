// Numbers as text, the same way in every file the harness writes: printf
// into a string, the 17-digit form that reads back exactly, the short
// scientific form of the reports, and the one marker of a missing value.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace idcol::harness {

/// printf into a std::string.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

/// %.17g, which reads back as the same double; a float stays a TOML float
/// ("1.0", not "1"), and the non-finite values are written as TOML writes
/// them (inf, -inf, nan).
std::string fmt17(double v);

/// What a report prints where a value is missing or not finite. One marker
/// for every table, so that a reader (or a script) looks for one string.
constexpr const char* kMissing = "n/a";

/// v in scientific notation with `digits` significant digits ("1.2e-09"),
/// or kMissing when v is not finite.
std::string sci(double v, int digits = 3);
/// The same for a JSON value: kMissing unless it is a number.
std::string sci(const nlohmann::json& v, int digits = 3);

/// v with `digits` decimals, or kMissing when v is not finite.
std::string fixed(double v, int digits);

}  // namespace idcol::harness
