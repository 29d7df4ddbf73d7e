#include "referee/lp_oracle.hpp"

namespace idcol::harness {

bool have_polytope_lp() { return false; }

baselines::OracleAnswer polytope_lp_answer(const baselines::ExactPolytope&, const baselines::ExactPolytope&,
                                           const baselines::geom::Pose&) {
  baselines::OracleAnswer a;
  a.error = "this build has no LP oracle (GLPK; configure with -DIDCOL_BUILD_BASELINES=ON)";
  return a;
}

}  // namespace idcol::harness
