// The runner: drives the solver through a scene's sweep, running only the
// passes and recording only what the scene asks for.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/result.hpp"
#include "idcol/solver.hpp"
#include "idcol_harness/pass.hpp"
#include "idcol_harness/record.hpp"
#include "idcol_harness/scene.hpp"

namespace idcol::harness {

/// Set (e.g. by a SIGINT handler) to stop a run at the next pose; the run
/// then throws Interrupted and writes nothing.
std::atomic<bool>& interrupt_flag();
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

/// The poses a shard owns: whole warm-start chains [chain_lo, chain_hi),
/// i.e. poses [pose_lo, pose_hi). Shard i of n takes chains
/// [i C / n, (i + 1) C / n) of the C = ceil(poses / warm_chain) chains.
struct ShardRange {
  int index = 0, count = 1;
  std::uint64_t chain_lo = 0, chain_hi = 0, pose_lo = 0, pose_hi = 0;
};
ShardRange shard_range(const Scene& s, int index, int count);
/// Parses "i/N" (0 <= i < N); throws std::invalid_argument.
std::pair<int, int> parse_shard(const std::string& text);

/// Runs work(t, lo, hi) for t = 0..threads-1, share t being poses [lo, hi)
/// of [pose_lo, pose_hi) (pose_lo on a chain boundary): whole chains of
/// `chain` poses, in order, so that merging the shares in t order gives what
/// one thread gives. One thread runs on the calling thread; more are each
/// waited for before the first error (Interrupted included) is rethrown.
void run_in_chains(std::uint64_t pose_lo, std::uint64_t pose_hi, std::uint64_t chain, int threads,
                   const std::function<void(int, std::uint64_t, std::uint64_t)>& work);

/// Median cost of one pair of clock reads (ns), subtracted from each timed solve.
double measure_timer_overhead_ns();
/// CPU time of the calling thread (s).
double thread_cpu_seconds();
/// Pins the calling thread (and the threads it starts later) to one CPU;
/// throws std::runtime_error if the system refuses.
void pin_to_cpu(int cpu);

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

}  // namespace idcol::harness
