#include "studies/entry_shards.hpp"

#include <map>
#include <stdexcept>

#include "stats/stats.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

/// The pattern of `path` around the decimal `index` (digits of its own, not
/// part of a longer number) in its file name: (before, after) for each
/// place it occurs, last first.
std::vector<std::pair<std::string, std::string>> index_patterns(const std::string& path, int index) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::string digits = std::to_string(index);
  const std::size_t name = path.rfind('/') == std::string::npos ? 0 : path.rfind('/') + 1;
  const auto digit = [&](std::size_t i) { return i < path.size() && path[i] >= '0' && path[i] <= '9'; };
  for (std::size_t at = path.rfind(digits); at != std::string::npos && at >= name; at = at ? path.rfind(digits, at - 1) : std::string::npos) {
    if ((at > name && digit(at - 1)) || digit(at + digits.size())) continue;
    out.emplace_back(path.substr(0, at), path.substr(at + digits.size()));
    if (at == 0) break;
  }
  return out;
}

}  // namespace

std::string rerun_missing_shards(const std::string& scene_path, const std::vector<std::string>& names,
                                 const std::vector<int>& index, const std::vector<int>& missing, int count) {
  // A pattern of the first input's name that gives every input's name from its index.
  std::pair<std::string, std::string> pattern;
  bool found = false;
  if (!names.empty() && names.size() == index.size())
    for (const auto& p : index_patterns(names[0], index[0])) {
      found = true;
      for (std::size_t k = 1; k < names.size() && found; ++k) found = names[k] == p.first + std::to_string(index[k]) + p.second;
      if (found) {
        pattern = p;
        break;
      }
    }
  const std::string n = std::to_string(count), run = "idcol_harness run " + scene_path;
  if (!found || missing.empty())
    return "; rerun each missing shard i (with the options the others ran with) as `" + run + " -o SHARD_i.json --shard i/" + n +
           "` (SHARD_i.json: where shard i's results go), then merge again";
  const std::string first = std::to_string(missing.front());
  return "; rerun each missing shard i (with the options the others ran with) as `" + run + " -o " + pattern.first + "<i>" + pattern.second + " --shard i/" + n + "`" +
         (missing.size() > 1 ? ", e.g. `" : ", here `") + run + " -o " + pattern.first + first + pattern.second + " --shard " + first +
         "/" + n + "`, then merge again";
}

json entry_shard_json(int index, int count, const std::vector<std::size_t>& entries) {
  return {{"index", index}, {"count", count}, {"entries", entries}};
}

json merge_entry_shards(const std::vector<json>& shards, const json& metadata, const std::vector<std::string>& names,
                        const char* schema, const char* entries_key, const char* count_key) {
  if (shards.empty()) throw std::invalid_argument("merge: no results files given");
  auto input_name = [&](std::size_t k) { return k < names.size() ? names[k] : "results file " + std::to_string(k) + " (counting from 0)"; };
  const json& first = shards.front();
  int n = 0;
  std::vector<int> seen;
  std::map<std::size_t, json> entries;  // by the scene's index: the scene's order
  json merged_from = json::array();
  double wall = 0.0;
  std::uint64_t records = 0;
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const json& r = shards[k];
    try {
      if (!r.is_object() || r.value("schema", std::string()) != schema)
        throw std::invalid_argument("is not a " + std::string(schema) + " results file");
      if (r.at("scene").at("content") != first.at("scene").at("content") || r.value("solver", json()) != first.value("solver", json()))
        throw std::invalid_argument("comes from a different scene or solver than " + input_name(0));
      if (!r.contains("shard"))
        throw std::invalid_argument("is a whole run, not a shard (run each shard with --shard i/N)");
      const json& sh = r.at("shard");
      const int index = sh.at("index").get<int>(), count = sh.at("count").get<int>();
      if (k == 0) {
        n = count;
        seen.assign(static_cast<std::size_t>(n), -1);
      }
      if (count != n || index < 0 || index >= n)
        throw std::invalid_argument("is shard " + std::to_string(index) + "/" + std::to_string(count) + ", but " + input_name(0) +
                                    " is one of " + std::to_string(n) + " shards");
      if (seen[index] >= 0)
        throw std::invalid_argument("is shard " + std::to_string(index) + "/" + std::to_string(n) + ", as is " + input_name(seen[index]));
      seen[index] = static_cast<int>(k);
      const json& es = r.at(entries_key);
      const json& at = sh.at("entries");
      if (!es.is_array() || !at.is_array() || es.size() != at.size())
        throw std::invalid_argument("lists " + std::to_string(at.size()) + " entries in shard.entries but has " +
                                    std::to_string(es.size()) + " " + entries_key);
      for (std::size_t e = 0; e < es.size(); ++e)
        if (!entries.emplace(count_from_json(at[e], "shard.entries[" + std::to_string(e) + "]"), es[e]).second)
          throw std::invalid_argument("repeats entry " + at[e].dump() + " of the scene");
      wall += r.at("wall_seconds").get<double>();
      records = add_counts(records, count_from_json(r.at(count_key), count_key), count_key);
      merged_from.push_back({{"shard", sh}, {"metadata", r.at("metadata")}, {"wall_seconds", r.at("wall_seconds")}});
    } catch (const json::exception& e) {
      throw std::invalid_argument("merge: " + input_name(k) + " is a damaged results file: " + e.what());
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("merge: " + input_name(k) + " " + e.what());
    }
  }
  std::string missing;
  std::vector<int> lost, given(shards.size(), 0);
  for (int i = 0; i < n; ++i) {
    if (seen[i] >= 0) given[static_cast<std::size_t>(seen[i])] = i;
    if (seen[i] >= 0) continue;
    missing += (missing.empty() ? "" : ", ") + std::to_string(i) + "/" + std::to_string(n);
    lost.push_back(i);
  }
  if (!missing.empty())
    throw std::invalid_argument("merge: shard(s) " + missing + " missing" +
                                rerun_missing_shards(first.at("scene").value("path", std::string("SCENE")), names, given, lost, n));
  std::size_t expect = 0;
  json all = json::array();
  for (auto& [i, e] : entries) {
    if (i != expect++) throw std::invalid_argument("merge: entry " + std::to_string(expect - 1) + " of the scene is in no shard");
    all.push_back(std::move(e));
  }
  json merged = first;
  merged["metadata"] = metadata;
  merged[entries_key] = std::move(all);
  merged[count_key] = records;
  merged["wall_seconds"] = wall;
  merged["shard"] = {{"index", 0}, {"count", 1}, {"merged_from", merged_from}};
  return merged;
}

}  // namespace idcol::harness
