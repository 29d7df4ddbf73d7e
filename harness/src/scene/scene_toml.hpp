// The TOML reading helpers of the scene loader, shared by parse_scene
// (studies/registry.cpp), the sections every kind shares (scene.cpp) and
// each kind's reader of its own (studies/<kind>/<kind>_scene.cpp). Include
// only where toml++ is needed: it is a heavy header.
#pragma once

#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "scene/scene.hpp"
#include "io/solver_options.hpp"
#include "io/text.hpp"
#include "referee/checks.hpp"

namespace idcol::harness {

inline std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    default: return "a date/time";
  }
}


/// A TOML basic string of `s` that a scene file may hold: ASCII only, so a
/// control character, and any character outside ASCII, is written as its
/// escape (\n, \u001B, \u202E).
inline std::string quote(const std::string& s) {
  std::string o = "\"";
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7F) {
      if (c == '"' || c == '\\') o += '\\';
      o += static_cast<char>(c);
      ++i;
    } else if (c == '\n' || c == '\t') {
      o += c == '\n' ? "\\n" : "\\t";
      ++i;
    } else {
      // toml++ hands out valid UTF-8 only; a stray byte is written as U+FFFD.
      const auto [cp, n] = c < 0x80 ? std::pair<char32_t, std::size_t>{c, 1} : utf8_at(s, i);
      o += cp > 0xFFFF ? format("\\U%08X", static_cast<unsigned>(cp)) : format("\\u%04X", static_cast<unsigned>(n ? cp : 0xFFFD));
      i += n ? n : 1;
    }
  }
  return o + "\"";
}

/// Reads one table of a scene, naming the file and the dotted field in errors
/// and rejecting keys it was not asked about.
class Reader {
 public:
  Reader(const toml::table& t, std::string file, std::string prefix)
      : t_(t), file_(std::move(file)), prefix_(std::move(prefix)) {}

  std::string field(const std::string& key) const { return prefix_.empty() ? key : prefix_ + "." + key; }
  [[noreturn]] void fail(const std::string& key, const std::string& msg) const { throw SceneError(file_, field(key), msg); }

  const toml::node* get(const std::string& key, bool required, const std::string& expected) {
    known_.insert(key);
    const toml::node* n = t_.get(key);
    if (!n && required) fail(key, "missing; expected " + expected);
    return n;
  }
  /// The node at `key` as a T (toml++'s as<T>), nullptr if absent and not
  /// required; `expected` is the form named in errors ("an array of strings").
  template <class T>
  auto typed(const std::string& key, bool required, const std::string& expected) {
    const toml::node* n = get(key, required, expected);
    const auto* v = n ? n->as<T>() : nullptr;
    if (n && !v) fail(key, "expected " + expected + ", got " + type_name(*n));
    return v;
  }
  double number(const std::string& key, bool required = true, double def = 0.0) {
    const toml::node* n = get(key, required, "a number");
    return n ? as_number(*n, key) : def;
  }
  double as_number(const toml::node& n, const std::string& key) const {
    if (auto v = n.as_floating_point()) return v->get();
    if (auto v = n.as_integer()) return static_cast<double>(v->get());
    fail(key, "expected a number, got " + type_name(n));
  }
  std::uint64_t count(const std::string& key, bool required, std::uint64_t def, bool allow_zero) {
    const auto* v = typed<std::int64_t>(key, required, "a positive integer");
    if (!v) return def;
    if (v->get() < 0 || (!allow_zero && v->get() == 0))
      fail(key, "expected a " + std::string(allow_zero ? "non-negative" : "positive") + " integer, got " +
                    std::to_string(v->get()));
    return static_cast<std::uint64_t>(v->get());
  }
  /// An integer in [lo, hi], as an int: a value out of the range (one that
  /// an int cannot hold included) is refused with the range and the value,
  /// never wrapped.
  int bounded_int(const std::string& key, bool required, int def, std::int64_t lo, std::int64_t hi) {
    const auto* v = typed<std::int64_t>(key, required, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    if (!v) return def;
    if (v->get() < lo || v->get() > hi)
      fail(key, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + std::to_string(v->get()));
    return static_cast<int>(v->get());
  }
  std::string string(const std::string& key, bool required = true, const std::string& def = "") {
    const auto* v = typed<std::string>(key, required, "a string");
    return v ? v->get() : def;
  }
  bool boolean(const std::string& key, bool def) {
    const auto* v = typed<bool>(key, false, "a boolean");
    return v ? v->get() : def;
  }
  const toml::table* table(const std::string& key, bool required) { return typed<toml::table>(key, required, "a table"); }
  const toml::array* array(const std::string& key, bool required, const std::string& what) {
    return typed<toml::array>(key, required, what);
  }
  std::vector<std::string> strings(const std::string& key, bool required) {
    std::vector<std::string> out;
    if (const toml::array* a = array(key, required, "an array of strings"))
      for (const auto& e : *a) {
        auto s = e.as_string();
        if (!s) fail(key, "expected an array of strings, found " + type_name(e) + " in it");
        out.push_back(s->get());
      }
    return out;
  }
  std::vector<double> numbers(const std::string& key) {
    std::vector<double> out;
    for (const auto& e : *array(key, true, "an array of numbers")) out.push_back(as_number(e, key));
    return out;
  }
  std::vector<Vec3> vec3s(const std::string& key) {
    std::vector<Vec3> out;
    for (const auto& e : *array(key, true, "an array of [x, y, z] arrays")) {
      auto row = e.as_array();
      if (!row || row->size() != 3) fail(key, "expected an array of [x, y, z] arrays (3 numbers each)");
      out.emplace_back(as_number(*row->get(0), key), as_number(*row->get(1), key), as_number(*row->get(2), key));
    }
    return out;
  }
  /// Every key of the table must have been asked for.
  void finish() const {
    for (const auto& [k, v] : t_) {
      const std::string key(k.str());
      if (!known_.count(key)) {
        std::string allowed;
        for (const auto& a : known_) allowed += (allowed.empty() ? "" : ", ") + a;
        fail(key, "unknown key (expected one of: " + allowed + ")");
      }
    }
  }

 private:
  const toml::table& t_;
  std::string file_, prefix_;
  std::set<std::string> known_;
};

/// The optional [solver] table of a scene or stress scene, read through the
/// scene's top-level Reader: any field of SolverOptions
/// (solver_option_fields()), validated (SolverOptions::validate()'s message
/// names the field and value).
inline void read_solver_table(Reader& top, const std::string& file, SolverOptions& o) {
  const toml::table* sv = top.table("solver", false);
  if (!sv) return;
  Reader t(*sv, file, "solver");
  for (const auto& f : solver_option_fields()) {
    if (f.real) o.*f.real = t.number(f.name, false, o.*f.real);
    else if (f.flag) o.*f.flag = t.boolean(f.name, o.*f.flag);
    else if (const auto* v = t.typed<std::int64_t>(f.name, false, "an integer")) {
      if (v->get() < -1000000000 || v->get() > 1000000000) t.fail(f.name, "out of range, got " + std::to_string(v->get()));
      o.*f.integer = static_cast<int>(v->get());
    }
  }
  t.finish();
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw SceneError(file, "solver", e.what());
  }
}

/// Rejects, before toml++ 3.3 sees the text, the inputs on which fuzz_scene
/// (harness/fuzz/fuzz_scene.cpp) found toml++ asserting (and, in release
/// builds, assuming: undefined behaviour with clang) instead of reporting an
/// error:
///  - any byte >= 0x80: toml++'s Unicode whitespace test reaches
///    TOML_UNREACHABLE for every code point in U+00A1..U+0499 (Greek letters
///    included) wherever its own reading of malformed text puts one outside a
///    string, which no outside scan can predict; so scene files are ASCII;
///  - a table header '[' or '[[' not followed by a key or ']' ("[#");
///  - '}' where an array expects a value or ']' ("[1, }", found after 42905
///    inputs);
///  - tables nested so deep that toml++'s recursion overflows the stack (a
///    dotted key of 40,000 parts): see kMaxKeyDots and kMaxOpen below.
/// The text is scanned with strings, comments and nesting tracked. Each is
/// reported as any other TOML error: "<file>: line L, column C: ...".
inline void prescan_toml(const std::string& t, const std::string& file) {
  const std::size_t n = t.size();
  std::size_t i = 0, line_begin = 0;
  int line = 1;
  bool line_start = true;
  std::vector<char> open;    // the brackets open at i, innermost last
  bool array_value = false;  // i is where an array expects a value or ']'
  // The depth of the tables a text can make is bounded before toml++ builds
  // them (it recurses once per level, and 40,000 levels overflow the stack):
  // a dotted key (or header) has at most kMaxKeyDots + 1 parts, and arrays
  // and inline tables nest at most kMaxOpen deep, so no table is deeper than
  // about 16 + 32 x 17 levels. `dots` counts the dots outside strings and
  // comments since the last '=', ',', bracket, brace or line end: a key's
  // separators (a float value has one).
  constexpr std::size_t kMaxKeyDots = 15, kMaxOpen = 32;
  std::size_t dots = 0;
  auto key_start = [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '"' ||
           c == '\'' || c == ']';
  };
  auto blank = [&](std::size_t j) { return j < n && (t[j] == ' ' || t[j] == '\t'); };
  auto at = [&](std::size_t j) { return "line " + std::to_string(line) + ", column " + std::to_string(j - line_begin + 1); };
  for (std::size_t j = 0; j < n; ++j) {
    if (t[j] == '\n') {
      ++line;
      line_begin = j + 1;
    } else if (static_cast<unsigned char>(t[j]) >= 0x80) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(t[j])));
      throw SceneError(file, at(j), std::string("scene files must be ASCII, found byte ") + hex +
                                        " (write symbols such as beta in ASCII, also in comments and strings)");
    }
  }
  line = 1;
  line_begin = 0;
  while (i < n) {
    const char c = t[i];
    if (c == '\n') {
      ++line;
      line_begin = ++i;
      line_start = true;
      dots = 0;
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\r') {
      ++i;
      continue;
    }
    if (c == '#') {
      while (i < n && t[i] != '\n') ++i;
      continue;
    }
    if (c == '"' || c == '\'') {
      const std::string triple(3, c);
      const bool multi = t.compare(i, 3, triple) == 0;
      i += multi ? 3 : 1;
      while (i < n) {
        if (c == '"' && t[i] == '\\') {
          i += 2;
          continue;
        }
        if (t[i] == '\n') {
          if (!multi) break;  // unterminated: toml++ reports it
          ++line;
          line_begin = i + 1;
        }
        if (multi ? t.compare(i, 3, triple) == 0 : t[i] == c) {
          i += multi ? 3 : 1;
          break;
        }
        ++i;
      }
      line_start = false;
      continue;
    }
    if (c == '[' && open.empty() && line_start) {  // a table header
      std::size_t j = i + 1;
      const bool ws = blank(j);
      while (blank(j)) ++j;
      bool ok = j >= n || key_start(t[j]);
      if (j < n && t[j] == '[') {
        ok = ws;  // "[ [" is reported by toml++ itself
        if (!ws) {
          ++j;
          while (blank(j)) ++j;
          ok = j >= n || key_start(t[j]);
        }
      }
      if (!ok)
        throw SceneError(file, at(j), "not valid TOML: expected a table name (a bare or quoted key) after '['");
    }
    if (array_value && c == '}')
      throw SceneError(file, at(i), "not valid TOML: expected a value or ']' in an array, found '}'");
    array_value = c == '[' || (c == ',' && !open.empty() && open.back() == '[');
    if (c == '.' && ++dots > kMaxKeyDots)
      throw SceneError(file, at(i), "a dotted key of more than " + std::to_string(kMaxKeyDots + 1) +
                                        " parts (a scene nests a few levels deep; toml++ would recurse once per part)");
    if (c == '=' || c == ',' || c == '[' || c == ']' || c == '{' || c == '}') dots = 0;
    if (c == '[' || c == '{') {
      open.push_back(c);
      if (open.size() > kMaxOpen)
        throw SceneError(file, at(i), "arrays and inline tables nested more than " + std::to_string(kMaxOpen) +
                                          " deep (a scene nests a few levels deep)");
    } else if ((c == ']' || c == '}') && !open.empty()) {
      open.pop_back();
    }
    line_start = false;
    ++i;
  }
}

/// Parses TOML text after prescan_toml; a syntax error is a SceneError
/// naming the file, line and column.
toml::table parse_toml(const std::string& text, const std::string& file);
/// The keys of a table in the order the file writes them.
std::vector<std::string> keys_in_file_order(const toml::table& t);

/// One shape from its TOML table (the [shapes] entry form); throws SceneError.
ShapeSpec read_shape(const toml::table& t, const std::string& file, const std::string& field, const std::string& name);

// The names of a scene's choices, each list written once for reading and
// writing: a kind's reader keeps the lists of its own choices beside it.
template <class E>
using Names = std::initializer_list<std::pair<const char*, E>>;
template <class E>
const char* name_of(Names<E> names, E v) {
  for (const auto& [n, e] : names)
    if (e == v) return n;
  return "?";
}
/// The value that `text` names; else fails with `unknown <what> "<text>" (expected "a", "b" or "c")`.
template <class E>
E named(const Reader& r, const std::string& key, const std::string& text, Names<E> names, const char* what = nullptr) {
  std::string known;
  std::size_t i = 0;
  for (const auto& [n, e] : names) {
    if (text == n) return e;
    known += std::string(i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + "\"" + n + "\"";
    ++i;
  }
  r.fail(key, "unknown " + (what ? std::string(what) : key) + " \"" + text + "\" (expected " + known + ")");
}
/// The oracle `text` names at `key` (the names to_string(OracleChoice) writes).
OracleChoice oracle_named(const Reader& r, const std::string& key, const std::string& text);

/// The most samples a scene may ask for where each is kept in memory or
/// costs several solves: derivative_samples, hausdorff_directions,
/// oracle_check_poses (500 times the default hausdorff_directions).
constexpr std::int64_t kMaxSamples = 10000000;

/// What a name names, which decides the characters it may hold.
enum class NameOf { Shape, Case, Scene };
/// Names that tables, CSV rows, failure records, `info` and the history's
/// series keys print as they are. A shape's: 1 to 64 of A-Z a-z 0-9 _ - . +
/// (what a bare TOML key allows, with '.' and '+'). A case's or a scene's: 1
/// to 128 printable ASCII characters (space included) other than '|', not
/// starting or ending with a space. None may hold '|' (a Markdown table's
/// column), a newline, a tab, NUL or any byte outside ASCII (a TOML escape
/// such as \u202E, which shows the text after it reversed). The name is
/// shown escaped in the error (io/text.hpp: escaped).
void require_safe_name(const std::string& file, const std::string& field, const std::string& name, NameOf of);

// The sections and fields more than one kind of scene has, each read as
// every kind reads it.
/// The scene's `name` (`def` where it may be left out), checked as above.
std::string read_scene_name(Reader& top, const std::string& file, const char* def = nullptr);
/// [shapes], in file order; `required` unless the kind can do without.
/// The generated polytopes, where a few bytes ask for many half-spaces, are
/// bounded in all as one is alone (kMaxFacets half-spaces, a vertex costing
/// kMaxFacets / kMaxVertices), before any is built, so that no scene takes
/// long to read.
void read_shapes(Reader& top, const std::string& file, Scene& s, bool required);
/// [sweep]: all of it for a sweep; a smoothing grid's is optional, and
/// always the paper's trajectory.
void read_sweep_table(Reader& top, const std::string& file, Scene& s, bool sweep);
/// The index in [shapes] of the shape `name` given at `key`.
int shape_index(const Scene& s, const Reader& r, const std::string& key, const std::string& name);
/// `key`: the string `word` (then true), or an array of [name, name] arrays
/// naming shapes of [shapes], read into `out` (then false); `bad_entry` is
/// the message for an entry of another form. Absent and not required: true.
bool read_pair_list(const Scene& s, Reader& r, const std::string& key, const std::string& word, bool required,
                    const std::string& bad_entry, std::vector<std::pair<int, int>>& out);
/// "passes": some of "cold", "warm", each once.
std::vector<Pass> read_passes(Reader& r);

}  // namespace idcol::harness
