// Reading a JSON file the harness wrote, field by field: every reader of a
// results, failures or history file checks the fields it reads through
// these, so that a file that is not a valid one is refused with the file,
// the field (its JSON path: pairs[2].passes.cold.failures) and the value,
// never with the JSON library's bare message or a value taken as another.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace idcol::harness {

/// A file that is not a valid file of its kind: "FILE: FIELD: expected
/// WHAT, got VALUE", or "FILE: FIELD has no \"KEY\"".
struct FileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A place in a file: the file's name (a path, "OLD", "h.jsonl:3") and the
/// JSON path of a field in it ("" for the file's top level).
class JsonAt {
 public:
  explicit JsonAt(std::string file, std::string path = "") : file_(std::move(file)), path_(std::move(path)) {}
  /// A member: path.key (key itself may be a dotted path).
  JsonAt operator/(const std::string& key) const { return JsonAt(file_, path_.empty() ? key : path_ + "." + key); }
  /// An element: path[i].
  JsonAt operator[](std::size_t i) const { return JsonAt(file_, path_ + "[" + std::to_string(i) + "]"); }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  /// "FILE: PATH", or "FILE" at the top level.
  std::string where() const { return path_.empty() ? file_ : file_ + ": " + path_; }
  /// Throws FileError "FILE: PATH: expected `expected`, got VALUE".
  [[noreturn]] void fail(const std::string& expected, const nlohmann::json& got) const;
  /// Throws FileError "FILE: PATH: `what`" (what a check found, in words).
  [[noreturn]] void fail(const std::string& what) const;

 private:
  std::string file_, path_;
};

/// What a field holds.
enum class JsonType {
  Object,
  Array,
  String,
  Bool,
  Number,        // any JSON number
  NumberOrNull,  // a number, or null where the writer had none (not finite)
  Count,         // an integer in [0, 2^64): not negative, not 2.5, not 2^64 written as a float
};

/// The words of errors for `t` ("a count (an integer in [0, 2^64))").
const char* json_type_words(JsonType t);
/// Whether `j` is a `t`.
bool is_json_type(const nlohmann::json& j, JsonType t);

/// `j`, checked to be a `t`: FileError at `at` otherwise.
const nlohmann::json& expect_type(const nlohmann::json& j, JsonType t, const JsonAt& at);
/// Member `key` of the object `obj` (at `at`), checked to be a `t`:
/// FileError "AT has no \"KEY\"" where it is missing.
const nlohmann::json& member(const nlohmann::json& obj, const std::string& key, JsonType t, const JsonAt& at);
/// The same where present: nullptr where `obj` has no `key`.
const nlohmann::json* optional_member(const nlohmann::json& obj, const std::string& key, JsonType t, const JsonAt& at);
/// An array of exactly `n` elements, each a `t`.
const nlohmann::json& expect_array_of(const nlohmann::json& j, std::size_t n, JsonType t, const JsonAt& at);

/// The file's `schema_version`: the integer `version` exactly. A reader
/// reads one version; 2, 2^32 + 1 (which an int would wrap to 1), 1e10,
/// 1.0, true and "1" are refused, naming the value.
void expect_version(const nlohmann::json& file, int version, const JsonAt& top);

/// A value as an error shows it: its JSON, non-ASCII and control characters
/// escaped, shortened past 80 characters.
std::string shown(const nlohmann::json& v);

}  // namespace idcol::harness
