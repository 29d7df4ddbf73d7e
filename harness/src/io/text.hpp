// Numbers as text, the same way in every file the harness writes: printf
// into a string, the 17-digit form that reads back exactly, the short
// scientific form of the reports, and the one marker of a missing value.
#pragma once

#include <string>
#include <utility>

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

/// The code point of the UTF-8 sequence that starts at s[i], and its length
/// in bytes; length 0 where the bytes there are not one (a stray
/// continuation byte, a truncated or overlong sequence, a surrogate, past
/// U+10FFFF).
std::pair<char32_t, std::size_t> utf8_at(const std::string& s, std::size_t i);

/// Text that came from a file or a command line, as a terminal or an error
/// message shows it: printable ASCII and printable UTF-8 as they are, a
/// backslash doubled, and what would move the cursor, end the line or hide
/// text shown as an escape instead: "\n", "\t", "\r", other control
/// characters and bytes that are not UTF-8 as "\x1B", the C1 controls, the
/// line and paragraph separators and the invisible and bidirectional
/// formatting characters (U+202E, which shows what follows reversed) as
/// "\u202E".
std::string escaped(const std::string& s);
/// The same text as it goes into Markdown prose or a table cell (a name
/// from a results file, which may have been edited by hand): escaped as
/// above, and '|' as "\\|" (it would end the cell) and '<' as "&lt;" where
/// a letter, '/', '!' or '?' follows (it would open an HTML tag; "x < 1"
/// stays as it is).
std::string md_text(const std::string& s);
/// The same text as a Markdown code span: its characters as they are but
/// for the escapes above and '|' as "\|", between more backticks than any
/// run of backticks in it.
std::string md_code(const std::string& s);

}  // namespace idcol::harness
