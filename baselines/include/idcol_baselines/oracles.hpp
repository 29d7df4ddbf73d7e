// Exact oracles for alpha*, the smallest uniform scaling at which two bodies
// touch, sharing no code with the iDCOL solver (no KKT system, no Newton on
// the surrogate). Body 1 sits at the identity, body 2 at X_12 = (R, r).
//
//  - Perram-Wertheim (exact ellipsoids): alpha*^2 = max_{lambda in [0,1]}
//      F(lambda) = lambda (1 - lambda) r^T C(lambda)^{-1} r,
//      C(lambda) = (1 - lambda) S1 + lambda S2,  S_i = R_i diag(axes_i)^2 R_i^T.
//    F is concave; its maximiser is found by safeguarded Newton on F'
//    (bisection bracket kept), to machine precision.
//  - Polytope LP (exact polytopes): min alpha s.t. A1 x <= alpha b1,
//      A2 R^T (x - r) <= alpha b2, by GLPK's primal simplex, then polished by
//      solving the 4x4 system of the active constraints in double.
//  - Support-function bracket (support_oracle.hpp): any pair of families;
//    a certified [lo, hi] from support functions and gauges. It serves
//    Ellip-Poly and Poly-Ellip here (it replaced bisection over FCL's
//    boolean, which made those pairs FCL checking FCL).
//  - Bisection over any boolean test: bodies scaled by alpha at translation r
//    touch iff the unscaled bodies at r / alpha do, and intersection at
//    r / alpha is monotone in alpha. Kept for tests that compare a library's
//    boolean with the oracles; no oracle answer is built on it.
//
// Nothing here includes core: poses are geom::Pose (which converts from
// idcol::Pose), vectors Eigen's.
#pragma once

#include <array>
#include <functional>
#include <string>

#include "idcol_baselines/exact_shape.hpp"
#include "idcol_baselines/support_oracle.hpp"

namespace idcol::baselines {

enum class OracleMethod { PerramWertheim, PolytopeLP, SupportFunction, Bisection, None };
const char* to_string(OracleMethod m);

/// An oracle's alpha*. Invariants when ok:
///  - x_1 (if has_x) lies on the surface of both bodies scaled by alpha
///    (body 2's copy placed at r): x_1 / alpha on body 1, R^T (x_1 - r) / alpha
///    on body 2;
///  - dalpha_dr (if has_gradient) is d alpha* / d r at fixed R, body-1 frame.
struct OracleAnswer {
  OracleMethod method = OracleMethod::None;
  bool ok = false;
  double alpha = 0.0;
  /// A bracket on alpha* of the exact bodies: alpha_lo <= alpha* <= alpha_hi.
  /// PW and LP give alpha_lo = alpha_hi = alpha (they are exact to rounding);
  /// the support-function oracle gives its certified bracket, with alpha its
  /// midpoint.
  double alpha_lo = 0.0, alpha_hi = 0.0;
  bool has_x = false;
  Vec3 x_1 = Vec3::Zero();
  bool has_gradient = false;
  Vec3 dalpha_dr = Vec3::Zero();
  double lambda = 0.0;  // PW: the maximiser of F
  int iterations = 0;   // PW: Newton/bisection steps; LP: simplex iterations; bisection: boolean calls
  std::string error;    // why !ok
};

/// Perram-Wertheim for two ellipsoids (axes in their own frames).
OracleAnswer perram_wertheim(const Vec3& axes1, const Vec3& axes2, const geom::Pose& X_12);

/// GLPK simplex LP (then a double-precision polish) for two exact polytopes.
OracleAnswer polytope_lp(const ExactPolytope& P1, const ExactPolytope& P2, const geom::Pose& X_12);

/// Bisection on alpha in [lo, hi] over `intersects(r_scaled)`, which must
/// report whether body 1 at the identity and body 2 at (R, r_scaled)
/// intersect. Stops when hi - lo <= rel_tol * hi. Returns the midpoint.
OracleAnswer bisect_alpha(const std::function<bool(const Vec3& r_scaled)>& intersects, const Vec3& r, double lo,
                          double hi, double rel_tol = 1e-12);

/// The smoothed polytope lies inside its exact polytope P and contains
/// (1 - delta) P, delta = L log(m) / (beta b_min) (SmoothPolytope's
/// documented bound). Hence, for a pair with exact-geometry alpha* = a_exact,
/// the smooth pair's alpha* lies in [a_exact, a_exact / (1 - delta_max)],
/// delta_max the larger shrink of the polytopes in the pair (0 for exact
/// ellipsoids). Returns {lo, hi}; hi is +inf if delta_max >= 1.
double smoothing_shrink(const ExactShape& s);
std::array<double, 2> smoothing_bracket(const ExactShape& s1, const ExactShape& s2, double alpha_exact);
/// The same for a bracket [lo, hi] of the exact alpha*: [lo, hi / (1 - delta_max)].
std::array<double, 2> smoothing_bracket(const ExactShape& s1, const ExactShape& s2, double alpha_lo, double alpha_hi);

/// The support-function oracle's answer as an OracleAnswer (alpha the
/// bracket's midpoint, alpha_lo/alpha_hi the bracket).
OracleAnswer support_function_oracle(const SupportOracle& oracle, const geom::Pose& X_12);

}  // namespace idcol::baselines
