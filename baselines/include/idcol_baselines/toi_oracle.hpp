// Time-of-impact oracle: the first time along a rigid motion at which two
// bodies touch, from the independent geometry alone (no core: neither its
// solver, nor its screw motion, nor its radii).
//
// Body 1 sits at the identity; body 2 moves from X0 (t = 0) to X1 (t = 1)
// along the screw motion X(t) = X0 exp(t xi^), xi = log(X0^-1 X1), written
// here from its definition (Rodrigues' formula and its inverse), and along
// X(t) = (R0, p0 + t (p1 - p0)) when R0 == R1 entry by entry.
//
// At each time the oracle has a certified bracket lo <= alpha* <= hi on the
// alpha* of the bodies the solver sees:
//   - two spheres: |r| / (R1 + R2), a closed form (lo = hi);
//   - two ellipsoids (spheres among them): Perram-Wertheim (lo = hi);
//   - any other pair: the support-function bracket (support_oracle.hpp),
//     whose outer and inner bodies hold the smoothing gap of a polytope or a
//     cone.
// Where |r| alone certifies alpha* > 1 (|r| / (R1_out + R2_out) > 1, the
// outer radii of geom::radii) the bracket is [|r| / (R1_out + R2_out), inf)
// and no oracle runs. It samples both ends of the bracket at `samples` + 1 evenly spaced times,
// and bisects the first sign change of lo - 1 and of hi - 1: the first
// contact lies in [t_lo, t_hi]. A motion whose sampled hi dips below
// 1 - graze is a clear hit; one whose sampled lo stays above 1 + graze a
// clear miss; the others (grazes, or a bracket too wide to tell) are left
// out of the verdicts. Between two samples alpha* can dip only by what the
// motion moves in that time, which `graze` is there to cover.
#pragma once

#include <array>
#include <string>

#include "idcol_baselines/geometry.hpp"
#include "idcol_baselines/support_oracle.hpp"

namespace idcol::baselines {

/// The motion from X0 to X1, from its own SE(3) log and exp.
class OracleMotion {
 public:
  OracleMotion(const geom::Pose& X0, const geom::Pose& X1);
  geom::Pose at(double t) const;
  bool translation() const { return translation_; }

 private:
  geom::Pose X0_, X1_;
  geom::Vec w_ = geom::Vec::Zero(), v_ = geom::Vec::Zero();  // body twist of X0^-1 X1
  bool translation_ = false;
};

struct ToiOracleOptions {
  int samples = 1000;    // evaluations of the bracket along the motion (plus t = 0)
  double graze = 1e-3;   // |alpha* - 1| below this at the deepest sample: neither a clear hit nor a clear miss
  int bisections = 60;   // per bracket end, between the samples that straddle 1
  void validate() const;  // throws std::invalid_argument naming the field
};

struct ToiOracleAnswer {
  bool clear_hit = false;    // sampled hi < 1 - graze somewhere: the bodies certainly meet
  bool clear_miss = false;   // sampled lo > 1 + graze everywhere: they do not (up to the sampling)
  bool initially_touching = false;  // lo(0) <= 1
  /// The first contact lies in [t_lo, t_hi] (a clear hit); 1 where that end never reaches 1.
  double t_lo = 1.0, t_hi = 1.0;
  double min_lo = 0.0, min_hi = 0.0;  // the smallest sampled bracket ends
  int evaluations = 0;
};

/// The oracle for one pair: its bracket method chosen once.
class ToiOracle {
 public:
  /// Throws std::invalid_argument for an invalid description or options.
  ToiOracle(const geom::Desc& body1, const geom::Desc& body2, ToiOracleOptions options = {});
  /// "closed_form", "perram_wertheim" or "support_function".
  const char* method() const;
  /// lo <= alpha* <= hi at X_12; {nan, nan} where the oracle has no answer.
  std::array<double, 2> bracket(const geom::Pose& X_12) const;
  ToiOracleAnswer first_contact(const geom::Pose& X0, const geom::Pose& X1) const;
  const ToiOracleOptions& options() const { return opt_; }

 private:
  enum class Method { ClosedForm, PerramWertheim, Support } method_ = Method::Support;
  geom::Vec axes1_ = geom::Vec::Ones(), axes2_ = geom::Vec::Ones();
  double radius_sum_ = 0.0;
  double outer_sum_ = 0.0;  // the outer bodies' certified outer radii: alpha* >= |r| / outer_sum_
  SupportOracle support_;
  ToiOracleOptions opt_;
};

}  // namespace idcol::baselines
