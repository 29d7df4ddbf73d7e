// Bisection on alpha over a boolean test, the smoothing bracket, and the
// support-function oracle as an OracleAnswer.
#include <algorithm>
#include <cmath>
#include <limits>

#include "idcol_baselines/oracles.hpp"

namespace idcol::baselines {

OracleAnswer bisect_alpha(const std::function<bool(const Vec3& r_scaled)>& intersects, const Vec3& r, double lo,
                          double hi, double rel_tol) {
  OracleAnswer out;
  out.method = OracleMethod::Bisection;
  // Invariant: the unscaled bodies intersect at r / hi and not at r / lo.
  // Widen the bracket if the boolean disagrees with the certified bounds (it
  // may, within its own tolerance).
  int calls = 0;
  for (int k = 0; k < 8 && !intersects(r / hi); ++k, ++calls) hi *= 1.01;
  for (int k = 0; k < 8 && intersects(r / lo); ++k, ++calls) lo /= 1.01;
  calls += 2;
  while (hi - lo > rel_tol * hi && calls < 400) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if (intersects(r / mid)) hi = mid; else lo = mid;
    ++calls;
  }
  out.iterations = calls;
  out.alpha = 0.5 * (lo + hi);
  out.ok = std::isfinite(out.alpha) && out.alpha > 0.0;
  if (!out.ok) out.error = "bisection produced a non-finite alpha";
  return out;
}

double smoothing_shrink(const ExactShape& s) {
  const auto* p = std::get_if<ExactPolytope>(&s);
  if (!p || p->beta <= 0.0) return 0.0;
  const double bmin = *std::min_element(p->offsets.begin(), p->offsets.end());
  return p->L * std::log(static_cast<double>(p->offsets.size())) / (p->beta * bmin);
}

std::array<double, 2> smoothing_bracket(const ExactShape& s1, const ExactShape& s2, double alpha_exact) {
  return smoothing_bracket(s1, s2, alpha_exact, alpha_exact);
}

std::array<double, 2> smoothing_bracket(const ExactShape& s1, const ExactShape& s2, double alpha_lo, double alpha_hi) {
  const double d = std::max(smoothing_shrink(s1), smoothing_shrink(s2));
  return {alpha_lo, d < 1.0 ? alpha_hi / (1.0 - d) : std::numeric_limits<double>::infinity()};
}

OracleAnswer support_function_oracle(const SupportOracle& oracle, const geom::Pose& X_12) {
  OracleAnswer out;
  out.method = OracleMethod::SupportFunction;
  const AlphaBracket b = oracle.bracket(X_12);
  out.ok = b.ok;
  out.error = b.error;
  out.alpha_lo = b.lo;
  out.alpha_hi = b.hi;
  out.alpha = b.mid();
  out.iterations = b.evaluations;
  return out;
}

}  // namespace idcol::baselines
