#include "io/text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace idcol::harness {

std::string format(const char* fmt, ...) {
  va_list ap, again;
  va_start(ap, fmt);
  va_copy(again, ap);
  std::string s(static_cast<std::size_t>(std::max(0, std::vsnprintf(nullptr, 0, fmt, ap))), '\0');
  va_end(ap);
  std::vsnprintf(s.data(), s.size() + 1, fmt, again);
  va_end(again);
  return s;
}

std::string fmt17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  std::string s(buf);
  if (s == "inf") return "inf";
  if (s == "-inf") return "-inf";
  if (s == "nan" || s == "-nan") return "nan";
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";  // keep it a TOML float
  return s;
}

std::string sci(double v, int digits) { return std::isfinite(v) ? format("%.*e", digits - 1, v) : kMissing; }

std::string sci(const nlohmann::json& v, int digits) { return v.is_number() ? sci(v.get<double>(), digits) : kMissing; }

std::string fixed(double v, int digits) { return std::isfinite(v) ? format("%.*f", digits, v) : kMissing; }

}  // namespace idcol::harness
