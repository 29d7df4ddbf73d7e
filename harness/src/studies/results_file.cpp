#include "studies/results_file.hpp"

#include <map>

#include "io/files.hpp"
#include "io/json_fields.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

const StudyKind& kind_of_schema(const json& r, const JsonAt& top) {
  const json& schema = member(r, "schema", JsonType::String, top);
  if (const StudyKind* k = study_kind_of_schema(schema.get<std::string>())) return *k;
  std::string expected = "the schema of a results file (";
  for (std::size_t i = 0; i < study_kinds().size(); ++i)
    expected += std::string(i == 0 ? "" : ", ") + "\"" + study_kinds()[i].get().schema + "\"";
  (top / "schema").fail(expected + ")", schema);
}

void check_entry(const StudyKind& k, const json& e, const JsonAt& at) {
  expect_type(e, JsonType::Object, at);
  for (const StudyKind::Member& m : k.entry_members) member(e, m.name, m.type, at);
  for_each_metric_value(k.metrics(), e, [&](const Metric& m, const std::string& path, const json& v) {
    if (!metric_value_ok(m, v)) (at / path).fail(metric_value_expected(m), v);
  });
}

}  // namespace

const StudyKind& check_results(const json& r, const std::string& file) {
  const JsonAt top(file);
  expect_type(r, JsonType::Object, top);
  const StudyKind& k = kind_of_schema(r, top);
  check_header(r, top);
  for (const StudyKind::Member& m : k.top_members) member(r, m.name, m.type, top);
  const json& entries = member(r, k.entries, JsonType::Array, top);
  std::map<std::string, std::size_t> first;  // entry key -> its index
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const JsonAt at = (top / k.entries)[i];
    check_entry(k, entries[i], at);
    // compare and merge match entries by their key: a second entry of the
    // same key would be compared in place of the first, or merged beside it.
    const std::string key = k.entry_key(r, entries[i]);
    const auto [it, added] = first.emplace(key, i);
    if (!added)
      at.fail(std::string("the ") + k.entry_word + " " + shown(key) + " again, as in " + k.entries + "[" + std::to_string(it->second) +
              "]: each " + k.entry_word + " is listed once");
  }
  return k;
}

json read_results_file(const std::string& path) {
  json r = read_json_file(path);
  check_results(r, path);
  return r;
}

}  // namespace idcol::harness
