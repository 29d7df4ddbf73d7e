// The sweep study: drives the solver through a scene's pose sweep, running
// only the passes and recording only what the scene asks for; its results
// file, the merge of its shards and its Markdown report.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/result.hpp"
#include "idcol/solver.hpp"
#include "exec/chains.hpp"
#include "studies/study.hpp"
#include "io/record.hpp"
#include "scene/scene.hpp"
#include "studies/sweep/sweep_spec.hpp"

namespace idcol::harness {

struct RunOutput {
  ShardRange shard;
  double timer_overhead_ns = 0.0;
  double wall_seconds = 0.0;
  nlohmann::json pairs = nlohmann::json::array();
  nlohmann::json failures = nlohmann::json::array();
};

/// Runs the scene's passes over the shard's poses. Throws Interrupted if
/// interrupt_flag() is raised.
RunOutput run_scene(const Scene& scene, const StudyOptions& opt);

/// Header line of the per-pose CSV.
const char* per_pose_csv_header();

/// A complete results file: schema, metadata, scene, sweep, shard, pairs.
nlohmann::json make_results(const Scene& scene, const RunOutput& out, const nlohmann::json& metadata);
/// Merges the results files of the shards of one sweep. Throws
/// std::invalid_argument unless they are shards 0..N-1 of the same scene; the
/// message names the input it cannot use (names[k], the path of shards[k],
/// when given) and, when shards are missing, which ones. Shards of different
/// git revisions (or, for a scene that records timing, of different CPUs,
/// compilers, flags or build types) are refused unless `allow_mixed`; then
/// metadata.mixed_shards names the fields that differ, and every shard's
/// metadata stays under shard.merged_from.
nlohmann::json merge_results(const std::vector<nlohmann::json>& shards, const nlohmann::json& metadata,
                             const std::vector<std::string>& names = {}, bool allow_mixed = false);

/// The paper's Table 1 layout from a results file: body 1 by body 2, each
/// cell "cold / **warm**" mean time per solve (us), then the same layout for
/// convergence rate, median time and mean iterations.
std::string markdown_table(const nlohmann::json& results, const std::string& results_path);

}  // namespace idcol::harness
