// The stress suite's checks and statistics of one (case, pass), shared by
// stress.cpp and the case kinds whose runner lives outside it
// (random_bodies_stress.cpp): the same checks, the same statistics and the
// same failure records for every stress case. Internal to the harness library.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "referee/checks.hpp"
#include "io/record.hpp"
#include "stats/stats.hpp"
#include "studies/stress/stress.hpp"

namespace idcol::harness {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Statistics of one (case, pass). Counts, sums, maxima and minima only, so
/// that the shares of threads merge exactly (times aside). What a sweep's
/// pass also counts is counted by its PassStats (statuses, iterations,
/// restarts) and CheckCounts (the answer checks); the rest is the suite's own.
struct StressTally {
  PassStats pass = with_iterations();
  CheckCounts checks;  // every converged answer but at r = 0
  std::uint64_t genuine = 0;
  std::uint64_t concentric_expected = 0, concentric_wrong = 0;
  std::uint64_t false_touch = 0, reference_failed = 0, oracle_checked = 0;
  double worst_residual = 0.0, worst_surface_allowance = 0.0, worst_normal_allowance = 0.0;
  double worst_oracle_error = 0.0, worst_bracket_violation = 0.0, max_bracket_width = 0.0, worst_touch_error = 0.0;
  std::uint64_t iter_sum_converged = 0;
  double min_pivot = 1.0, max_sensitivity = 0.0;
  std::uint64_t unreliable = 0;
  std::map<int, std::uint64_t> pivot_decades;  // floor(log10 pivot ratio) -> count
  double solve_seconds = 0.0;                  // sum of per-solve wall times
  std::uint64_t worst_alpha_k = 0;             // where checks.worst_alpha_error occurred (lowest k of ties)

  static PassStats with_iterations() {
    PassStats p;
    p.has_iterations = true;
    return p;
  }
  /// Checks solve r of pose k at X as every stress case is checked (status;
  /// unless it did not converge: witness points on the surfaces, opposite
  /// normals, the oracle when `with_oracle`, alpha* = expected_alpha when
  /// finite), counts it, and returns the check (problem empty when the
  /// answer is genuine). `checker` is that of the pair solved. With `memo`,
  /// the oracle's answer is read from it, or computed and kept there: the
  /// answers at one configuration (either body order) share one oracle call.
  AnswerCheck check(const AnswerChecker& checker, const Pose& X, const SolveResult& r, std::uint64_t k, bool with_oracle,
                    double expected_alpha = kNaN, const TouchReference& touch = {},
                    std::optional<OracleVerdict>* memo = nullptr);
  void merge(const StressTally& o);
  /// The pass's statistics as every stress pass writes them.
  nlohmann::json to_json() const;
};

/// The failure record of one solve, as every stress case writes it, at the
/// site given (its shapes' describe() text makes the record replayable); r
/// is null where no solve ran (a touching pose whose reference failed).
nlohmann::json stress_failure_record(const StressCase& c, const FailureSite& site, const Pose& X, const SolveResult* r,
                                     const WarmStart* before, const std::string& problem, double oracle_alpha,
                                     double expected_alpha = kNaN);

/// One thread's share of a case: per pass, its tally, its failure records
/// (at most StudyOptions::max_failures, in pose order) and its CPU time.
struct StressShare {
  explicit StressShare(std::size_t passes = 0) : tallies(passes), fails(passes), cpu(passes, 0.0) {}
  std::vector<StressTally> tallies;
  std::vector<std::vector<nlohmann::json>> fails;
  std::vector<double> cpu;
};

/// Runs run_range(lo, hi, share) over a case's poses on `threads` threads,
/// each taking whole chains of `chain` poses (run_in_chains), then writes
/// pass i's entry to cj["passes"][names[i]]: the shares' tallies merged in
/// order, their CPU time, and the first opt.max_failures records in pose
/// order, which are appended to `failures`.
void run_case_passes(const StressCase& c, const std::vector<std::string>& names, std::uint64_t chain, int threads,
                     const StudyOptions& opt, const std::function<void(std::uint64_t, std::uint64_t, StressShare&)>& run_range,
                     nlohmann::json& cj, nlohmann::json& failures);

/// Runs one kind = "random_bodies" case (random_bodies_stress.cpp): the case's
/// JSON, and its failure records appended to `failures` (indexed, with their
/// replay commands).
nlohmann::json run_random_bodies_case(const Scene& s, const StressCase& c, const StudyOptions& opt,
                                      nlohmann::json& failures);

}  // namespace idcol::harness
