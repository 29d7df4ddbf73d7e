// Mergeable statistics of one pass over one pair. Everything kept is a count,
// an integer sum, a max or a fixed-binned histogram, so the statistics of
// shards merge into exactly those of the unsharded run (timing aside: times
// are measurements and differ from run to run). Percentiles are read from the
// histograms, so they are the same whether computed before or after a merge.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "idcol/result.hpp"
#include "referee/checks.hpp"

namespace idcol::harness {

/// Fixed log-spaced histogram: bin i covers [10^(e0 + i/d), 10^(e0 + (i+1)/d)),
/// d bins per decade; values below 10^e0 (including 0 and negatives) go to
/// `under`, values >= the top edge to `over`, NaN/Inf to `nonfinite`.
/// A percentile is reported as the geometric centre of its bin, so its
/// relative resolution is 10^(1/d) (d = 100 for times: 2.3%).
class LogHistogram {
 public:
  /// keep_sum: also keep the sum (for a mean); a floating-point sum depends on
  /// the order of addition, so it is kept only for times, never for data a
  /// merge must reproduce bit for bit.
  LogHistogram(int e0 = 0, int decades = 10, int per_decade = 100, bool keep_sum = true);
  void add(double v);
  /// Throws std::invalid_argument if the binning differs.
  void merge(const LogHistogram& o);

  std::uint64_t count() const { return count_; }
  double max() const { return max_; }  // largest finite value added (-inf if none)
  double mean() const;
  /// Value at quantile q in [0, 1]: the bin holding the ceil(q n)-th smallest
  /// value; under -> its lower edge as 0, over -> max(). NaN if empty.
  double quantile(double q) const;

  nlohmann::json to_json() const;  // binning, counts (sparse), max, sum
  static LogHistogram from_json(const nlohmann::json& j);
  bool same_counts(const LogHistogram& o) const;

 private:
  int e0_, decades_, per_decade_;
  bool keep_sum_;
  std::vector<std::uint64_t> bins_;
  std::uint64_t under_ = 0, over_ = 0, nonfinite_ = 0, count_ = 0;
  double max_ = -std::numeric_limits<double>::infinity();
  double sum_ = 0.0;
};

/// A struct's fields as the results files name them: (key, member). One
/// list drives a struct's merge and its JSON both ways, so that each field
/// is named once.
template <class S, class V = std::uint64_t>
using Fields = std::initializer_list<std::pair<const char*, V S::*>>;
/// A count of a results file that is not a count: negative, fractional, or
/// 2^64 or more (which JSON readers turn into a float), or a sum of shards'
/// counts past 2^64 - 1. Never wrapped.
struct BadCount : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};
/// `j` as a count: a JSON integer in [0, 2^64); else BadCount naming `key`
/// and the value.
std::uint64_t count_from_json(const nlohmann::json& j, const std::string& key);
/// a + b, or BadCount naming `key` if the sum passes 2^64 - 1.
std::uint64_t add_counts(std::uint64_t a, std::uint64_t b, const std::string& key);

template <class S, class V>
void add_fields(S& to, const S& from, Fields<S, V> fields) {
  for (const auto& [key, m] : fields) {
    if constexpr (std::is_same_v<V, std::uint64_t>) to.*m = add_counts(to.*m, from.*m, key);
    else to.*m += from.*m;
  }
}
template <class S, class V>
void max_fields(S& to, const S& from, Fields<S, V> fields) {
  for (const auto& [key, m] : fields) to.*m = std::max(to.*m, from.*m);
}
template <class S, class V>
void write_fields(const S& s, nlohmann::json& j, Fields<S, V> fields) {
  for (const auto& [key, m] : fields) j[key] = s.*m;
}
/// A field read_fields did not find: the file was written before the field
/// existed. Nothing stands in for it: 0 would claim a count nobody made.
struct MissingField : std::runtime_error {
  explicit MissingField(const std::string& key)
      : std::runtime_error("no \"" + key + "\": the file predates that field (an older harness wrote it); rerun it with this one") {}
};
template <class S, class V>
void read_fields(S& s, const nlohmann::json& j, Fields<S, V> fields) {
  for (const auto& [key, m] : fields) {
    if (!j.is_object() || !j.contains(key)) throw MissingField(key);
    if constexpr (std::is_same_v<V, std::uint64_t>) s.*m = count_from_json(j.at(key), key);
    else s.*m = j.at(key).template get<V>();
  }
}

/// Wall minus thread CPU time of a loop, clamped at 0: the two clocks are read
/// at slightly different instants, so an undisturbed loop can come out a few
/// microseconds negative, which tables printed as "-0.00".
/// The exact percentile of a sample that is kept whole (the smoothing
/// study's few thousand values): the element of rank round(q (n - 1)); NaN
/// for an empty sample. A run too long to keep its values uses
/// LogHistogram::quantile, whose shards merge.
double percentile(std::vector<double> v, double q);

inline double descheduled_seconds(double wall_s, double cpu_s) { return wall_s > cpu_s ? wall_s - cpu_s : 0.0; }

/// What the answer checks (checks.hpp) found on a pass's converged solves,
/// when the scene records "checks": mergeable counts and maxima.
struct CheckCounts {
  std::uint64_t checked = 0;                              // converged solves checked
  std::uint64_t false_surface = 0, false_normal = 0;      // a witness point off its surface; normals not opposite
  std::uint64_t false_oracle = 0, oracle_failed = 0;      // alpha* against the oracle; oracle without an answer
  std::uint64_t false_total = 0;                          // solves failing any check
  double worst_surface = 0.0, worst_normal = 0.0, worst_alpha_error = 0.0;
  void add(const AnswerCheck& c);
  void merge(const CheckCounts& o);
  nlohmann::json to_json() const;
  static CheckCounts from_json(const nlohmann::json& j);
};

struct PassStats {
  bool has_timing = false, has_iterations = false, has_residuals = false, has_checks = false;
  CheckCounts checks;  // has_checks

  std::uint64_t solves = 0;
  std::array<std::uint64_t, kNumSolveStatuses> by_status{};
  std::uint64_t chain_starts = 0;      // warm pass: poses solved without a warm start (chain heads)
  std::uint64_t warm_fell_back = 0;    // warm start failed, cold strategy ran
  std::uint64_t used_continuation = 0;
  std::uint64_t restarts = 0;          // sum over solves

  std::uint64_t iter_sum = 0;
  int iter_max = 0;
  std::map<int, std::uint64_t> iter_hist;

  LogHistogram residual_all{-20, 25, 20, false}, residual_converged{-20, 25, 20, false};
  LogHistogram time_all{0, 10, 100}, time_converged{0, 10, 100};  // nanoseconds, timer overhead subtracted

  /// Of the pass loop (timing only): wall and thread CPU seconds, and the
  /// involuntary context switches the thread suffered. Wall minus CPU is the
  /// time the thread was descheduled; it lands in some per-solve times (and
  /// in their mean and max), which is why it is reported.
  double loop_wall_s = 0.0, loop_cpu_s = 0.0;
  std::uint64_t involuntary_switches = 0;

  void add(const SolveResult& r, bool chain_start, double time_ns);
  void merge(const PassStats& o);
  std::uint64_t converged() const { return by_status[static_cast<int>(SolveStatus::Converged)]; }
  double convergence_rate() const { return solves ? static_cast<double>(converged()) / solves : 0.0; }

  /// Summaries (rates, means, percentiles) plus the raw mergeable data.
  nlohmann::json to_json() const;
  /// Reads back the raw data written by to_json.
  static PassStats from_json(const nlohmann::json& j);
};

/// The parts of a results "pairs" entry that a merge must reproduce exactly:
/// everything except measured times.
nlohmann::json without_timing(nlohmann::json pairs);

}  // namespace idcol::harness
