#include "referee/lp_oracle.hpp"

namespace idcol::harness {

bool have_polytope_lp() { return true; }

baselines::OracleAnswer polytope_lp_answer(const baselines::ExactPolytope& P1, const baselines::ExactPolytope& P2,
                                           const baselines::geom::Pose& X_12) {
  return baselines::polytope_lp(P1, P2, X_12);
}

}  // namespace idcol::harness
