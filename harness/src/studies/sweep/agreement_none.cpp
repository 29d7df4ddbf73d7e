// A build without baselines: a scene that records them is refused when it is
// read (referee/methods_none.cpp), so these are reached only by a caller
// that skipped the scene reader, or by a failures file from another build.
#include <cstdio>
#include <stdexcept>

#include "studies/sweep/agreement.hpp"

namespace idcol::harness {

AgreementStats run_agreement(const Scene&, int, int, std::uint64_t, std::uint64_t, int, double, nlohmann::json&) {
  throw std::runtime_error("this build has no baselines (configured with -DIDCOL_BUILD_BASELINES=OFF)");
}

namespace detail {
int replay_baseline_disagreement(const Pose&, const Shape&, const Shape&, const SolverOptions&) {
  std::printf("this build has no baselines; cannot replay a baseline disagreement\n");
  return 2;
}
}  // namespace detail

}  // namespace idcol::harness
