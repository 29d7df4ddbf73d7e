// FCL's continuousCollide for the time-of-impact study (a build with FCL).
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/fcl_adapter.hpp"
#include "studies/toi/toi_fcl.hpp"

namespace idcol::harness {

namespace {
class FclToiPair : public FclToi {
 public:
  FclToiPair(const Shape& b1, const Shape& b2) : pair_(baselines::to_exact(b1), baselines::to_exact(b2)) {}
  FclToiAnswer query(const std::string& method, const Pose& X0, const Pose& X1, bool screw, int steps) const override {
    const auto m = method == "naive" ? baselines::FclContinuousMethod::Naive : baselines::FclContinuousMethod::ConservativeAdvancement;
    const baselines::FclContinuousAnswer a = pair_.continuous(X0, X1, m, screw, steps);
    return {a.supported, a.hit, a.t};
  }

 private:
  baselines::FclPair pair_;
};
}  // namespace

std::unique_ptr<FclToi> make_fcl_toi(const Shape& body1, const Shape& body2, std::string& why) {
  std::string w1, w2;
  if (!baselines::representable(body1, &w1) || !baselines::representable(body2, &w2)) {
    why = "not run: " + (w1.empty() ? w2 : w1);
    return nullptr;
  }
  return std::make_unique<FclToiPair>(body1, body2);
}

}  // namespace idcol::harness
