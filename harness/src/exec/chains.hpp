// How work is laid out over threads and processes: shards of a run, shares
// of a shard over threads (whole warm-start chains, so that the merge in
// order equals one thread), interrupts, CPU time and pinning. Every study
// runs its poses through here.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>

#include "scene/scene.hpp"

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

}  // namespace idcol::harness
