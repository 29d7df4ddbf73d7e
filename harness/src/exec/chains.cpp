#include "exec/chains.hpp"

#include <sched.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstring>
#include <future>
#include <memory>
#include <vector>

namespace idcol::harness {

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

std::atomic<bool>& interrupt_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}

ShardRange shard_range(const Scene& s, int index, int count) {
  ShardRange r;
  r.index = index;
  r.count = count;
  // poses and warm_chain are below 2^63 (TOML integers), so neither the
  // chain count nor a chain's first pose overflows; chains x i / N is taken
  // as (chains / N) i + (chains % N) i / N, exact where chains x i would
  // pass 2^64.
  const std::uint64_t chains = s.poses / s.warm_chain + (s.poses % s.warm_chain ? 1 : 0);
  const auto share = [&](std::uint64_t i) {
    const std::uint64_t n = static_cast<std::uint64_t>(count);
    return chains / n * i + chains % n * i / n;
  };
  r.chain_lo = share(static_cast<std::uint64_t>(index));
  r.chain_hi = share(static_cast<std::uint64_t>(index) + 1);
  r.pose_lo = r.chain_lo >= chains ? s.poses : std::min(s.poses, r.chain_lo * s.warm_chain);
  r.pose_hi = r.chain_hi >= chains ? s.poses : std::min(s.poses, r.chain_hi * s.warm_chain);
  return r;
}

void run_in_chains(std::uint64_t pose_lo, std::uint64_t pose_hi, std::uint64_t chain, int threads,
                   const std::function<void(int, std::uint64_t, std::uint64_t)>& work) {
  if (threads <= 1) return work(0, pose_lo, pose_hi);
  const std::uint64_t chains = (pose_hi - pose_lo) / chain + ((pose_hi - pose_lo) % chain ? 1 : 0);
  // The first pose of share t, as shard_range splits chains (no product past 2^64).
  const auto first = [&](std::uint64_t t) {
    const std::uint64_t n = static_cast<std::uint64_t>(threads), c = chains / n * t + chains % n * t / n;
    return c >= chains ? pose_hi : std::min(pose_hi, pose_lo + c * chain);
  };
  std::vector<std::future<void>> jobs;
  for (int t = 0; t < threads; ++t) {
    const std::uint64_t lo = first(static_cast<std::uint64_t>(t));
    const std::uint64_t hi = first(static_cast<std::uint64_t>(t) + 1);
    jobs.push_back(std::async(std::launch::async, [&work, t, lo, hi] { work(t, lo, hi); }));
  }
  for (auto& j : jobs) j.wait();
  for (auto& j : jobs) j.get();
}

std::pair<int, int> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    std::size_t a = 0, b = 0;
    const int i = std::stoi(text.substr(0, slash), &a);
    const int n = std::stoi(text.substr(slash + 1), &b);
    if (a != slash || b != text.size() - slash - 1 || n < 1 || i < 0 || i >= n) throw std::invalid_argument("");
    return {i, n};
  } catch (const std::exception&) {
    throw std::invalid_argument("--shard expects i/N with 0 <= i < N, got \"" + text + "\"");
  }
}

double measure_timer_overhead_ns() {
  std::vector<double> d(20001);
  for (auto& x : d) {
    const auto t0 = Clock::now();
    const auto t1 = Clock::now();
    x = std::chrono::duration<double, std::nano>(t1 - t0).count();
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof set, &set) != 0)
    throw std::runtime_error("cannot pin to CPU " + std::to_string(cpu) + ": " + std::strerror(errno));
}

}  // namespace idcol::harness
