// The per-pose API the harness calls: given two idcol shapes and a pose,
// every baseline's answer and the exact oracle's alpha*.
//
//   BaselinePair pair(body1, body2);          // throws if the pair is unsupported
//   for (Baseline b : pair.baselines()) auto a = pair.run(b, X_12);
//   OracleAnswer o = pair.oracle(X_12);       // alpha* of the exact geometry
//   auto [lo, hi] = pair.smoothing_bracket(o.alpha);  // where iDCOL's alpha* must lie
//
// Which pairs are served: every baseline serves spheres, exact ellipsoids
// (Superellipsoid with n = 1) and smooth polytopes (as their exact
// polytopes), in any combination; nothing else (superellipsoids with n != 1,
// cylinders, cones have no exact FCL/libccd counterpart). The oracle is
// Perram-Wertheim for Ellip-Ellip, the GLPK LP for Poly-Poly, and the
// support-function bracket (support_oracle.hpp) for Ellip-Poly and
// Poly-Ellip; none of them calls FCL or libccd.
//
// Frames: body 1 at the identity, body 2 at X_12 (body-2 coordinates to
// body-1 coordinates), exactly as idcol::solve.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "idcol/shapes.hpp"
#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/ccd_adapter.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/exact_shape.hpp"
#include "idcol_baselines/fcl_adapter.hpp"
#include "idcol_baselines/oracles.hpp"

namespace idcol::baselines {

/// Every baseline, in a fixed order.
const std::vector<Baseline>& all_baselines();

/// Whether `b` can serve the pair; if not, `why` names the pair and the reason.
bool can_serve(Baseline b, const Shape& body1, const Shape& body2, std::string* why = nullptr);
/// The baselines that can serve the pair (empty if none can).
std::vector<Baseline> baselines_for(const Shape& body1, const Shape& body2);
/// The oracle used for the pair (None if unsupported).
OracleMethod oracle_for(const Shape& body1, const Shape& body2);

/// Both bodies' exact geometry and each competitor's prepared state, built
/// once per pair; per-pose queries are const.
class BaselinePair {
 public:
  /// Throws std::invalid_argument naming the pair if no baseline serves it.
  BaselinePair(const Shape& body1, const Shape& body2, FclOptions fcl = {}, CcdOptions ccd = {});

  PairKind kind() const { return kind_; }
  const std::string& name() const { return name_; }
  std::vector<Baseline> baselines() const { return all_baselines(); }

  /// One baseline at one pose. Never throws for a served baseline: library
  /// exceptions come back as answer.threw.
  BaselineAnswer run(Baseline b, const Pose& X_12) const;
  /// Every baseline at one pose, in all_baselines() order.
  std::vector<BaselineAnswer> run_all(const Pose& X_12) const;
  /// Exact-geometry alpha* (see oracle_for).
  OracleAnswer oracle(const Pose& X_12) const;
  /// [alpha_exact, alpha_exact / (1 - delta_max)]: where the smooth pair's
  /// alpha* (iDCOL's) lies; see oracles.hpp.
  std::array<double, 2> smoothing_bracket(double alpha_exact) const {
    return baselines::smoothing_bracket(e1_, e2_, alpha_exact);
  }
  /// The same from an oracle answer's bracket [alpha_lo, alpha_hi].
  std::array<double, 2> smoothing_bracket(const OracleAnswer& o) const {
    return baselines::smoothing_bracket(e1_, e2_, o.alpha_lo, o.alpha_hi);
  }
  const ExactShape& exact1() const { return e1_; }
  const ExactShape& exact2() const { return e2_; }
  const FclPair& fcl() const { return fcl_; }
  const CcdPair& ccd() const { return ccd_; }

 private:
  PairKind kind_;
  std::string name_;
  ExactShape e1_, e2_;
  FclPair fcl_;
  CcdPair ccd_;
  SupportOracle support_;  // of the exact bodies (beta -> inf)
};

}  // namespace idcol::baselines
