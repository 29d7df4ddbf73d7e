// Where the SIMD batch lanes hand a cold row back to the scalar solver
// mid-run (PairSolver::newton_run, solve_pair_resumed).
#pragma once

#include "idcol/types.hpp"

namespace idcol::detail {

/// Where the SIMD batch lanes left a cold row's first Newton run: at an LM
/// step (which the first cold lanes do not make), iteration `it` of the run, with its
/// point z (for it > 0; at it = 0 the run's start, support_guess's), the
/// Newton steps made before this one, the stall count, and the chord flags
/// after this step's chord attempt. The lanes' steps are the scalar
/// solver's to the bit, so the scalar solver goes on from there with the
/// answer, iterations included, that it would reach alone
/// (solve_pair_resumed), without making again the run's earlier steps and
/// the failed line search (21 trials by default) that the lanes made.
struct ColdResume {
  Vec6 z = Vec6::Zero();
  int it = 0;
  int iterations = 0;
  int stalls = 0;
  bool chord_ok = false, chord_tried = false;
};

}  // namespace idcol::detail
