// A build without FCL: the time-of-impact study runs idcol against its
// oracle alone, and says so in each entry.
#include "studies/toi/toi_fcl.hpp"

namespace idcol::harness {

std::unique_ptr<FclToi> make_fcl_toi(const Shape&, const Shape&, std::string& why) {
  why = "this build has no FCL (configure with FCL installed and -DIDCOL_BUILD_BASELINES=ON)";
  return nullptr;
}

}  // namespace idcol::harness
