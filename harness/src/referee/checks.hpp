// Answer checks that do not trust the solver's status: any pass can check a
// converged answer with them (the stress suite checks every one).
//   surface:  both witness points on their surfaces, |phi| / |grad phi| of
//             the outer radius, phi from the baselines' independent geometry
//             (long double, written from the paper's formulas; built in
//             every configuration, so never the solver's own eval);
//   normals:  the two bodies' unit normals at x* opposite, |n1 + n2|;
//   oracle:   alpha* against an oracle that shares no code with the solver
//             (closed form for two spheres, Perram-Wertheim for exact
//             ellipsoids, the LP's smoothing bracket for two polytopes where
//             the build has GLPK (referee/lp_oracle.hpp), the
//             support-function bracket for any pair);
//   touching: alpha* = 1 + eps on a pose constructed so (scaling covariance).
#pragma once

#include <limits>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"

namespace idcol::harness {

/// The thresholds. The solver converges to a relative KKT residual of 1e-10
/// (options.hpp), so a genuine answer has its witness points within ~1e-10 of
/// the surfaces (in units of the body size) and opposite normals to ~1e-10;
/// each threshold leaves two orders of magnitude above that.
struct CheckTolerances {
  double surface = 1e-8;      // |phi| / |grad phi| / outer radius at each witness point
  double normal = 1e-6;       // |n1 + n2|
  double closed_form = 1e-9;  // sphere-sphere: |alpha / (|r| / (R1 + R2)) - 1|
  double pw = 1e-8;           // exact ellipsoids: |alpha / alpha_PW - 1|
  double bracket = 1e-9;      // LP and support function: alpha in [lo, hi], relative slack
  double touching = 1e-8;     // touching: |alpha / (1 + eps) - 1| (scaling covariance)
  nlohmann::json to_json() const;
};

enum class OracleChoice { Auto, None, ClosedForm, PerramWertheim, PolytopeLP, SupportFunction };
const char* to_string(OracleChoice o);  // "auto", "none", "closed_form", "pw", "lp", "support"

/// Whether the baselines' oracles and independent geometry were compiled in.

bool is_sphere(const Shape& s);
bool is_exact_ellipsoid(const Shape& s);  // sphere, or superellipsoid with n = 1
bool is_polytope(const Shape& s);

/// Where alpha* of the smooth pair lies, from an oracle independent of the
/// solver in every build (the baselines' Eigen-only oracles; never the
/// solver's own solve).
struct TouchReference {
  bool ok = false;
  double lo = 0.0, hi = 0.0;  // bracket on alpha*
  std::string method;
  std::string error;  // why !ok
};

/// What the checks found on one converged answer. Measures are NaN where a
/// check did not run.
struct AnswerCheck {
  double surface = 0.0, normal = 0.0;  // the measures above (1 and 2 when not finite)
  double surface_allowance = 0.0;      // the surface measure's change over the witness points' rounding (added to the tolerance)
  double normal_allowance = 0.0;       // the normals' turn over the witness points' rounding (added to the tolerance)
  bool surface_failed = false, normal_failed = false;
  double touching_error = std::numeric_limits<double>::quiet_NaN();
  bool touching_failed = false;
  bool oracle_checked = false, oracle_failed_to_answer = false, oracle_disagrees = false;
  double oracle_alpha = std::numeric_limits<double>::quiet_NaN();
  double oracle_error = std::numeric_limits<double>::quiet_NaN();        // closed form, PW: relative error
  double bracket_violation = std::numeric_limits<double>::quiet_NaN();   // LP, support function
  double bracket_width = std::numeric_limits<double>::quiet_NaN();       // hi / lo - 1, if bounded
  double alpha_error = 0.0;  // the largest of the touching and oracle errors
  std::string problem;       // each failed check, in words; empty when genuine
  bool genuine() const { return problem.empty(); }
};

/// The oracle's answer at one configuration, computed once and reusable by
/// the checks of every answer there: alpha* does not depend on which body is
/// named first, so the answer at X for (b1, b2) also judges (b2, b1) at
/// X^-1. `relative`: closed form and PW give alpha* itself (compared by
/// relative error); the LP and the support function give a bracket [lo, hi].
struct OracleVerdict {
  bool ok = false;
  OracleChoice oracle = OracleChoice::None;
  double alpha = std::numeric_limits<double>::quiet_NaN();
  double lo = std::numeric_limits<double>::quiet_NaN(), hi = std::numeric_limits<double>::quiet_NaN();
  std::string method;
};

/// The independent geometry and oracles of one pair, built once (polytope
/// vertices, support-oracle bodies) and read by every pose and thread.
class AnswerChecker {
 public:
  /// `oracle` must serve the pair (Auto is resolved by resolve_oracle).
  AnswerChecker(const Shape& b1, const Shape& b2, OracleChoice oracle, const SolverOptions& solver,
                CheckTolerances tol = {});
  ~AnswerChecker();
  AnswerChecker(const AnswerChecker&) = delete;
  AnswerChecker& operator=(const AnswerChecker&) = delete;

  /// The oracle "auto" stands for on this pair in this build.
  static OracleChoice resolve_oracle(const Shape& b1, const Shape& b2);

  /// alpha* of the pair at X from the independent oracle (closed form, PW,
  /// LP with its smoothing bracket, or the support-function bracket).
  TouchReference reference(const Pose& X) const;

  /// The oracle's answer at X (ok = false with oracle() None, or when it
  /// could not answer).
  OracleVerdict oracle_verdict(const Pose& X) const;

  /// Checks a converged answer r at X: surface and normals always; the
  /// oracle when `with_oracle` (its answer taken from *known when given, so
  /// that several answers at one configuration share one oracle call);
  /// alpha* = expected_alpha within `touch`'s bracket when expected_alpha is
  /// finite and touch.ok.
  AnswerCheck check(const Pose& X, const SolveResult& r, bool with_oracle, double expected_alpha = std::numeric_limits<double>::quiet_NaN(),
                    const TouchReference& touch = {}, const OracleVerdict* known = nullptr) const;

  const CheckTolerances& tolerances() const { return tol_; }

  /// The unit normal of body 1 or 2 at y (its own frame).
  Vec3 normal(int body, const Vec3& y) const;
  /// phi / |grad phi| / outer radius of body 1 or 2 at y: the signed
  /// distance to its surface that the surface check measures.
  double surface_distance(int body, const Vec3& y) const;
  /// The largest change of that measure when y moves by delta along any
  /// axis, times sqrt(3): how far rounding of y alone can move it.
  double surface_spread(int body, const Vec3& y, double delta) const;
  /// The largest turn of that normal when y moves by delta along any axis,
  /// times sqrt(3): how far rounding of y alone can turn it.
  double normal_spread(int body, const Vec3& y, double delta) const;
  OracleChoice oracle() const { return oracle_; }

 private:
  struct Independent;
  const Shape& b1_;
  const Shape& b2_;
  OracleChoice oracle_;
  SolverOptions solver_;
  CheckTolerances tol_;
  std::unique_ptr<Independent> ind_;
};

}  // namespace idcol::harness
