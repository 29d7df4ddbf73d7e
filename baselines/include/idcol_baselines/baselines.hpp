// The per-pose API the harness calls: given two idcol shapes and a pose,
// each competitor's answer (registry.hpp) and the exact oracle's alpha*.
//
//   BaselinePair pair(body1, body2);          // throws if the pair is unsupported
//   for (const Competitor* c : pair.competitors()) auto a = pair.run(*c, X_12);
//   OracleAnswer o = pair.oracle(X_12);       // alpha* of the exact geometry
//   auto [lo, hi] = pair.smoothing_bracket(o.alpha);  // where iDCOL's alpha* must lie
//
// Which pairs are served: spheres, exact ellipsoids (Superellipsoid with
// n = 1) and smooth polytopes (as their exact polytopes), in any combination;
// nothing else (superellipsoids with n != 1, cylinders, cones have no exact
// counterpart). Each competitor says which of these it serves
// (Competitor::serves). The oracle is Perram-Wertheim for Ellip-Ellip, the
// GLPK LP for Poly-Poly, and the support-function bracket
// (support_oracle.hpp) for Ellip-Poly and Poly-Ellip; none of them calls a
// competitor's library.
//
// Frames: body 1 at the identity, body 2 at X_12 (body-2 coordinates to
// body-1 coordinates), exactly as idcol::solve.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "idcol/shapes.hpp"
#include "idcol_baselines/answer.hpp"
#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/exact_shape.hpp"
#include "idcol_baselines/oracles.hpp"
#include "idcol_baselines/registry.hpp"

namespace idcol::baselines {

/// Whether `c` serves the pair; if not, `why` is "<name> cannot serve the
/// pair <pair>: <reason>".
bool can_serve(const Competitor& c, const Shape& body1, const Shape& body2, std::string* why = nullptr);
/// The competitors that serve the pair, in table order (empty if none does).
std::vector<const Competitor*> competitors_for(const Shape& body1, const Shape& body2);
/// The oracle used for the pair (None if unsupported).
OracleMethod oracle_for(const Shape& body1, const Shape& body2);

/// alpha* of two exact bodies (exact_shape.hpp) at X_12, by the pair's
/// exact oracle: Perram-Wertheim for spheres and ellipsoids, GLPK's LP for
/// two polytopes, the support-function bracket for a polytope with an
/// ellipsoid or a sphere (built for the call: BaselinePair keeps one per pair).
OracleAnswer exact_oracle(const ExactShape& e1, const ExactShape& e2, const Pose& X_12);

/// Both bodies' exact geometry and the prepared state of every competitor
/// that serves the pair, built once per pair; per-pose queries are const.
class BaselinePair {
 public:
  /// Throws std::invalid_argument naming the pair if either body has no
  /// exact counterpart (serves_exact_bodies).
  BaselinePair(const Shape& body1, const Shape& body2);

  PairKind kind() const { return kind_; }
  const std::string& name() const { return name_; }
  /// The competitors prepared for this pair, in table order.
  std::vector<const Competitor*> competitors() const;

  /// The prepared state of `c` (resolve once, then call run() per pose).
  /// Throws std::invalid_argument if `c` does not serve this pair.
  const PreparedPair& prepared(const Competitor& c) const;
  /// One competitor at one pose. Never throws for a competitor that serves
  /// the pair: library exceptions come back as answer.threw.
  BaselineAnswer run(const Competitor& c, const Pose& X_12) const { return prepared(c).run(X_12); }
  /// The same by name; an unknown name throws, naming the known ones.
  BaselineAnswer run(std::string_view name, const Pose& X_12) const { return run(competitor(name), X_12); }
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

 private:
  PairKind kind_;
  std::string name_;
  ExactShape e1_, e2_;
  std::vector<std::pair<const Competitor*, std::unique_ptr<PreparedPair>>> prepared_;
  SupportOracle support_;  // of the exact bodies (beta -> inf)
};

}  // namespace idcol::baselines
