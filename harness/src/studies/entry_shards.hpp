// Shards of the kinds whose results are a list of independent entries (the
// stress suite's cases, the smoothing study's grid points): shard i of N
// runs entries i, i + N, i + 2N, ... of the scene (round robin, since
// entries differ in cost by orders of magnitude), and the merge puts every
// entry back at its place, so that it equals the single run in every figure
// but the times. (A sweep shards its poses instead: studies/sweep.)
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace idcol::harness {

/// Whether entry i of the scene belongs to shard `index` of `count`.
inline bool in_shard(std::size_t i, int index, int count) {
  return count <= 1 || i % static_cast<std::size_t>(count) == static_cast<std::size_t>(index);
}

/// The "shard" member of a sharded results file: its index and count, and
/// the scene's index of each of its entries, in the order written.
nlohmann::json entry_shard_json(int index, int count, const std::vector<std::size_t>& entries);

/// What merge's error for missing shards ends with: how to rerun each, then
/// merge again. `names` are the paths of the shards given (names[k] is
/// shard index[k]); where they follow one pattern with the shard's index in
/// it (out/shards/0.json, 1.json, 3.json), the rerun writes the missing
/// shard where that pattern puts it (-o out/shards/2.json), else to a path
/// the message asks for.
std::string rerun_missing_shards(const std::string& scene_path, const std::vector<std::string>& names,
                                 const std::vector<int>& index, const std::vector<int>& missing, int count);

/// Merges the shards 0..N-1 of one scene: the entries (under `entries_key`)
/// in the scene's order, `count_key` (the failure records) and the wall
/// time summed, the shards' own shard members and metadata under
/// shard.merged_from. Throws std::invalid_argument naming the input (names[k]
/// where given) that is not a results file of `schema`, comes from another
/// scene or solver, repeats a shard or leaves one out.
nlohmann::json merge_entry_shards(const std::vector<nlohmann::json>& shards, const nlohmann::json& metadata,
                                  const std::vector<std::string>& names, const char* schema, const char* entries_key,
                                  const char* count_key);

}  // namespace idcol::harness
