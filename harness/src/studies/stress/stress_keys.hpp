// The keys only a stress suite's results file has (io/keys.hpp explains
// why keys are constants).
#pragma once

#include "io/keys.hpp"

namespace idcol::harness::key {

inline constexpr char genuine_rate[] = "genuine_rate";                      // genuine answers / solves
inline constexpr char concentric[] = "concentric";                          // poses with r = 0 ...
inline constexpr char reference_solve_failed[] = "reference_solve_failed";  // touching poses whose reference failed
inline constexpr char oracle[] = "oracle";                                  // the pass's answers against the case's oracle ...
inline constexpr char worst_relative_error[] = "worst_relative_error";      // ... closed form or Perram-Wertheim
inline constexpr char worst_bracket_violation[] = "worst_bracket_violation";  // ... LP or support-function bracket
inline constexpr char worst_residual[] = "worst_residual";
inline constexpr char conditioning[] = "conditioning";  // the KKT system's conditioning ...
inline constexpr char unreliable[] = "unreliable";      // ... solves it reports unreliable
inline constexpr char worst_error_unflagged[] = "worst_error_unflagged";  // derivatives: the largest error not flagged unreliable

}  // namespace idcol::harness::key
