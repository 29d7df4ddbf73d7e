// The stress suite's checks and statistics of one (case, pass), for case
// kinds whose runner lives outside stress.cpp (random_bodies_stress.cpp):
// the same checks, the same statistics and the same failure records as
// every other stress case. Internal to the harness library.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "idcol_harness/checks.hpp"
#include "idcol_harness/record.hpp"
#include "idcol_harness/stress.hpp"

namespace idcol::harness {

class StressTally {
 public:
  explicit StressTally(const StressCase& c);
  StressTally(StressTally&&) noexcept;
  StressTally& operator=(StressTally&&) noexcept;
  ~StressTally();

  /// Checks one solve of b1 against b2 at X_12 as every stress case is
  /// checked (status, witness points on the surfaces, opposite normals, the
  /// case's oracle at X_12), counts it, and returns "" when it is genuine,
  /// else the problem. oracle_alpha receives the oracle's alpha (NaN if none).
  /// `checker` is that of the pair solved. With `memo`, the oracle's answer
  /// is read from it, or computed and stored there: answers at one
  /// configuration (either body order) share one oracle call.
  std::string check(const AnswerChecker& checker, const Pose& X_12, const SolveResult& r, std::uint64_t k, double* oracle_alpha,
                    std::optional<OracleVerdict>* memo = nullptr);
  void add_solve_seconds(double seconds);
  void merge(const StressTally& o);
  /// The pass's statistics as every stress pass writes them.
  nlohmann::json to_json() const;

 private:
  struct Impl;
  const StressCase* c_;
  std::unique_ptr<Impl> impl_;
};

/// The failure record of one solve, as every stress case writes it, at the
/// site given (its shapes' describe() text makes the record replayable).
nlohmann::json stress_failure_record(const StressCase& c, const FailureSite& site, const Pose& X, const SolveResult& r,
                                     const WarmStart* before, const std::string& problem, double oracle_alpha);

/// Runs one kind = "random_bodies" case (random_bodies_stress.cpp): the case's
/// JSON, and its failure records appended to `failures` (indexed, with their
/// replay commands).
nlohmann::json run_random_bodies_case(const Scene& s, const StressCase& c, const StressOptions& opt,
                                      nlohmann::json& failures);

}  // namespace idcol::harness
