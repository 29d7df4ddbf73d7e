// Perram-Wertheim contact function for two ellipsoids (see oracles.hpp).
#include <cmath>

#include <Eigen/Cholesky>

#include "idcol_baselines/oracles.hpp"

namespace idcol::baselines {

const char* to_string(OracleMethod m) {
  switch (m) {
    case OracleMethod::PerramWertheim: return "perram_wertheim";
    case OracleMethod::PolytopeLP: return "polytope_lp";
    case OracleMethod::SupportFunction: return "support_function";
    case OracleMethod::Bisection: return "bisection";
    case OracleMethod::None: return "none";
  }
  return "unknown";
}

OracleAnswer perram_wertheim(const Vec3& axes1, const Vec3& axes2, const geom::Pose& X_12) {
  OracleAnswer out;
  out.method = OracleMethod::PerramWertheim;
  const Vec3& r = X_12.p;
  if (r.squaredNorm() == 0.0) {  // concentric: alpha* = 0
    out.ok = true;
    out.has_x = true;
    return out;
  }
  const Mat3 S1 = axes1.array().square().matrix().asDiagonal();
  const Mat3 S2 = X_12.R * axes2.array().square().matrix().asDiagonal() * X_12.R.transpose();
  const Mat3 D = S2 - S1;

  // F'(l) = (1 - 2l) r^T u - l (1 - l) u^T D u, u = C(l)^{-1} r;
  // F''(l) = -2 r^T u - 2 (1 - 2l) u^T D u + 2 l (1 - l) u^T D C^{-1} D u <= 0.
  struct Eval {
    double F, dF, ddF;
    Vec3 u;
  };
  auto eval = [&](double l) {
    const Eigen::LLT<Mat3> C((1.0 - l) * S1 + l * S2);
    Eval e;
    e.u = C.solve(r);
    const Vec3 Du = D * e.u;
    const double g = r.dot(e.u), h = e.u.dot(Du);
    e.F = l * (1.0 - l) * g;
    e.dF = (1.0 - 2.0 * l) * g - l * (1.0 - l) * h;
    e.ddF = -2.0 * g - 2.0 * (1.0 - 2.0 * l) * h + 2.0 * l * (1.0 - l) * Du.dot(C.solve(Du));
    return e;
  };

  // F'(0) = r^T S1^-1 r > 0 and F'(1) = -r^T S2^-1 r < 0: the root is inside.
  double lo = 0.0, hi = 1.0, l = 0.5;
  Eval e = eval(l);
  int it = 0;
  for (; it < 200; ++it) {
    if (e.dF > 0.0) lo = l; else hi = l;
    if (e.dF == 0.0 || hi - lo <= 4.0 * std::numeric_limits<double>::epsilon()) break;
    double next = (e.ddF < 0.0) ? l - e.dF / e.ddF : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double step = std::abs(next - l);
    l = next;
    e = eval(l);
    // Newton converges quadratically; once the step is at rounding level
    // F has its maximum to machine precision (F is flat there).
    if (step <= 1e-15) break;
  }
  out.iterations = it + 1;
  out.lambda = l;
  out.alpha = std::sqrt(e.F);
  out.alpha_lo = out.alpha_hi = out.alpha;
  out.ok = std::isfinite(out.alpha) && out.alpha > 0.0;
  if (!out.ok) {
    out.error = "Perram-Wertheim produced a non-finite alpha";
    return out;
  }
  // Stationary point of l x^T S1^-1 x + (1-l)(x-r)^T S2^-1 (x-r): x = (1-l) S1 u;
  // at the maximiser both quadratic forms equal F = alpha^2.
  out.x_1 = (1.0 - l) * (S1 * e.u);
  out.has_x = true;
  // Envelope theorem: d(alpha^2)/dr = dF/dr at fixed l = 2 l (1-l) u.
  out.dalpha_dr = l * (1.0 - l) * e.u / out.alpha;
  out.has_gradient = true;
  return out;
}

}  // namespace idcol::baselines
