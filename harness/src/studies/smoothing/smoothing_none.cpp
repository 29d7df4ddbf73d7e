// A build without the baselines has no exact oracles to measure smoothing
// against: a smoothing scene is refused when it is loaded.
#include "studies/smoothing/smoothing.hpp"

namespace idcol::harness {

std::unique_ptr<Study> make_smoothing_study(Scene s) {
  throw SceneError(s.path, "grid", "a smoothing grid needs the exact oracles, and this build has none (configure with -DIDCOL_BUILD_BASELINES=ON)");
}

}  // namespace idcol::harness
