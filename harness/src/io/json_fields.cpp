#include "io/json_fields.hpp"

#include <cstdint>

namespace idcol::harness {

using nlohmann::json;

void JsonAt::fail(const std::string& expected, const json& got) const {
  throw FileError(where() + ": expected " + expected + ", got " + shown(got));
}

void JsonAt::fail(const std::string& what) const { throw FileError(where() + ": " + what); }

const char* json_type_words(JsonType t) {
  switch (t) {
    case JsonType::Object: return "an object";
    case JsonType::Array: return "an array";
    case JsonType::String: return "a string";
    case JsonType::Bool: return "true or false";
    case JsonType::Number: return "a number";
    case JsonType::NumberOrNull: return "a number or null";
    case JsonType::Count: return "a count (an integer in [0, 2^64))";
  }
  return "?";
}

bool is_json_type(const json& j, JsonType t) {
  switch (t) {
    case JsonType::Object: return j.is_object();
    case JsonType::Array: return j.is_array();
    case JsonType::String: return j.is_string();
    case JsonType::Bool: return j.is_boolean();
    case JsonType::Number: return j.is_number();
    case JsonType::NumberOrNull: return j.is_number() || j.is_null();
    // nlohmann reads a non-negative integer as unsigned, a negative one as
    // signed, and one of 2^64 or more (or 2.0) as a float.
    case JsonType::Count: return j.is_number_unsigned() || (j.is_number_integer() && j.get<std::int64_t>() >= 0);
  }
  return false;
}

const json& expect_type(const json& j, JsonType t, const JsonAt& at) {
  if (!is_json_type(j, t)) at.fail(json_type_words(t), j);
  return j;
}

const json& member(const json& obj, const std::string& key, JsonType t, const JsonAt& at) {
  expect_type(obj, JsonType::Object, at);
  const auto it = obj.find(key);
  if (it == obj.end()) throw FileError(at.where() + " has no \"" + key + "\"");
  return expect_type(*it, t, at / key);
}

const json* optional_member(const json& obj, const std::string& key, JsonType t, const JsonAt& at) {
  expect_type(obj, JsonType::Object, at);
  const auto it = obj.find(key);
  return it == obj.end() ? nullptr : &expect_type(*it, t, at / key);
}

const json& expect_array_of(const json& j, std::size_t n, JsonType t, const JsonAt& at) {
  if (!j.is_array() || j.size() != n) at.fail("an array of " + std::to_string(n) + " (" + json_type_words(t) + ")", j);
  for (std::size_t i = 0; i < n; ++i) expect_type(j[i], t, at[i]);
  return j;
}

void expect_version(const json& file, int version, const JsonAt& top) {
  expect_type(file, JsonType::Object, top);
  const auto it = file.find("schema_version");
  if (it == file.end()) throw FileError(top.where() + " has no \"schema_version\"");
  if (!is_json_type(*it, JsonType::Count) || it->get<std::uint64_t>() != static_cast<std::uint64_t>(version))
    (top / "schema_version").fail(std::to_string(version) + " (the one version this harness reads)", *it);
}

std::string shown(const json& v) {
  const std::string s = v.dump(-1, ' ', true, json::error_handler_t::replace);
  return s.size() <= 80 ? s : s.substr(0, 70) + "...(" + std::to_string(s.size()) + " chars)";
}

}  // namespace idcol::harness
