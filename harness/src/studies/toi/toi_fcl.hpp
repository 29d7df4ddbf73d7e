// FCL's continuousCollide on the study's motions, where this build has FCL:
// toi_baselines.cpp with it, toi_none.cpp (no pair supported) without; CMake
// picks the file, the sources never test what the build has.
#pragma once

#include <memory>
#include <string>

#include "idcol/shapes.hpp"
#include "idcol/types.hpp"

namespace idcol::harness {

/// One FCL answer on a motion: `supported` false where FCL has no such
/// query for the pair.
struct FclToiAnswer {
  bool supported = true;
  bool hit = false;
  double t = 1.0;
};

/// FCL's geometry of one pair (its exact bodies: a smooth polytope becomes
/// the polytope it smooths), built once.
class FclToi {
 public:
  virtual ~FclToi() = default;
  /// method: "naive" (steps poses) or "conservative_advancement"; screw:
  /// FCL's screw motion (CCDM_SCREW), else its translation (CCDM_TRANS).
  virtual FclToiAnswer query(const std::string& method, const Pose& X0, const Pose& X1, bool screw, int steps) const = 0;
};

/// The pair's FCL geometry, or nullptr with `why` set where this build has
/// no FCL or FCL cannot represent a body exactly.
std::unique_ptr<FclToi> make_fcl_toi(const Shape& body1, const Shape& body2, std::string& why);

}  // namespace idcol::harness
