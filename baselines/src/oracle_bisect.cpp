// Bisection on alpha over a boolean test, and the smoothing bracket.
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
  const double d = std::max(smoothing_shrink(s1), smoothing_shrink(s2));
  return {alpha_exact, d < 1.0 ? alpha_exact / (1.0 - d) : std::numeric_limits<double>::infinity()};
}

}  // namespace idcol::baselines
