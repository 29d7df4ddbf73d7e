// The exact oracle of two polytopes (an LP, solved by GLPK) where the build
// has it. Which file answers is a choice of the build: lp_oracle_glpk.cpp
// with the baselines, lp_oracle_none.cpp without (then the polytope pairs are
// checked by the support-function bracket, which needs only Eigen).
#pragma once

#include "idcol_baselines/exact_shape.hpp"
#include "idcol_baselines/oracles.hpp"

namespace idcol::harness {

/// Whether this build has the LP oracle.
bool have_polytope_lp();

/// alpha* of two exact polytopes at X_12 by the LP (baselines' polytope_lp);
/// ok = false, with the reason, where the build has no LP oracle.
baselines::OracleAnswer polytope_lp_answer(const baselines::ExactPolytope& P1, const baselines::ExactPolytope& P2,
                                           const baselines::geom::Pose& X_12);

}  // namespace idcol::harness
