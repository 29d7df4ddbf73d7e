#include "io/text.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <utility>

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

std::pair<char32_t, std::size_t> utf8_at(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(i);
  const std::size_t n = b >= 0xF0 && b <= 0xF4 ? 4 : b >= 0xE0 ? 3 : b >= 0xC2 && b <= 0xDF ? 2 : 0;
  if (n == 0 || b > 0xF4 || i + n > s.size()) return {0, 0};
  char32_t cp = b & (0x7F >> n);
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return {0, 0};
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  const char32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < least[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return {0, 0};
  return {cp, n};
}

namespace {

/// Characters that print nothing themselves but break a line or a table, or
/// change how the text around them shows: C1 controls, the soft hyphen, the
/// Arabic letter mark, zero-width and joiner characters, the bidirectional
/// marks, embeddings, overrides and isolates, the line and paragraph
/// separators, invisible operators, the byte order mark, interlinear
/// annotations and tags.
bool hides_text(char32_t c) {
  return (c >= 0x80 && c <= 0x9F) || c == 0xAD || c == 0x61C || c == 0x180E || (c >= 0x200B && c <= 0x200F) ||
         (c >= 0x2028 && c <= 0x202E) || (c >= 0x2060 && c <= 0x206F) || c == 0xFEFF || (c >= 0xFFF9 && c <= 0xFFFB) ||
         (c >= 0xE0000 && c <= 0xE007F);
}

enum class Into { Terminal, Markdown, MarkdownCode };

std::string escape_for(const std::string& s, Into into) {
  std::string o;
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char b = static_cast<unsigned char>(s[i]);
    if (b >= 0x80) {
      const auto [cp, n] = utf8_at(s, i);
      if (n == 0) o += format("\\x%02X", b);
      else if (hides_text(cp)) o += cp > 0xFFFF ? format("\\U%08X", static_cast<unsigned>(cp)) : format("\\u%04X", static_cast<unsigned>(cp));
      else o.append(s, i, n);
      i += n ? n : 1;
      continue;
    }
    ++i;
    if (b == '\n') o += "\\n";
    else if (b == '\t') o += "\\t";
    else if (b == '\r') o += "\\r";
    else if (b < 0x20 || b == 0x7F) o += format("\\x%02X", b);
    else if (b == '\\' && into != Into::MarkdownCode) o += "\\\\";
    else if (b == '|' && into != Into::Terminal) o += "\\|";
    else if (b == '<' && into == Into::Markdown && i < s.size() && (std::isalpha(static_cast<unsigned char>(s[i])) || s[i] == '/' ||
                                                                   s[i] == '!' || s[i] == '?'))
      o += "&lt;";  // where it would open an HTML tag, comment or declaration
    else o += static_cast<char>(b);
  }
  return o;
}

}  // namespace

std::string escaped(const std::string& s) { return escape_for(s, Into::Terminal); }

std::string md_text(const std::string& s) { return escape_for(s, Into::Markdown); }

std::string md_code(const std::string& s) {
  const std::string body = escape_for(s, Into::MarkdownCode);
  std::size_t run = 0, longest = 0;
  for (char c : body) longest = std::max(longest, run = c == '`' ? run + 1 : 0);
  const std::string fence(longest + 1, '`');
  // A space inside the fence where the text starts or ends with a backtick.
  const bool pad = !body.empty() && (body.front() == '`' || body.back() == '`');
  return fence + (pad ? " " : "") + body + (pad ? " " : "") + fence;
}

}  // namespace idcol::harness
