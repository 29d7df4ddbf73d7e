// Support-function oracle (see support_oracle.hpp).
#include "idcol_baselines/support_oracle.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace idcol::baselines {

using geom::Mat;
using geom::Vec;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kGolden = 0.6180339887498949;

// Minimise f over R^D by Nelder-Mead from x0 with an initial simplex of
// edge `size`; stops when the simplex is smaller than `tol` or after
// `budget` evaluations (f counts them itself).
template <int D, class F>
Eigen::Matrix<double, D, 1> nelder_mead(const F& f, const Eigen::Matrix<double, D, 1>& x0, double size, double tol, int budget) {
  using V = Eigen::Matrix<double, D, 1>;
  std::array<V, D + 1> p;
  std::array<double, D + 1> fp;
  p[0] = x0;
  for (int i = 0; i < D; ++i) p[i + 1] = x0 + size * V::Unit(i);
  for (int i = 0; i <= D; ++i) fp[i] = f(p[i]);
  int used = D + 1;
  while (used < budget) {
    // Order: best first, worst last.
    for (int i = 1; i <= D; ++i)
      for (int j = i; j > 0 && fp[j] < fp[j - 1]; --j) std::swap(p[j], p[j - 1]), std::swap(fp[j], fp[j - 1]);
    double diam = 0.0;
    for (int i = 1; i <= D; ++i) diam = std::max(diam, (p[i] - p[0]).norm());
    if (diam < tol) break;
    V c = V::Zero();
    for (int i = 0; i < D; ++i) c += p[i];
    c /= D;
    const V xr = c + (c - p[D]);
    const double fr = f(xr);
    ++used;
    if (fr < fp[0]) {
      const V xe = c + 2.0 * (c - p[D]);
      const double fe = f(xe);
      ++used;
      if (fe < fr) p[D] = xe, fp[D] = fe;
      else p[D] = xr, fp[D] = fr;
    } else if (fr < fp[D - 1]) {
      p[D] = xr, fp[D] = fr;
    } else {
      const V xc = fr < fp[D] ? V(c + 0.5 * (xr - c)) : V(c + 0.5 * (p[D] - c));
      const double fc = f(xc);
      ++used;
      if (fc < std::min(fr, fp[D])) {
        p[D] = xc, fp[D] = fc;
      } else {  // shrink toward the best
        for (int i = 1; i <= D; ++i) p[i] = p[0] + 0.5 * (p[i] - p[0]), fp[i] = f(p[i]);
        used += D;
      }
    }
  }
  int b = 0;
  for (int i = 1; i <= D; ++i)
    if (fp[i] < fp[b]) b = i;
  return p[b];
}

// Two unit vectors spanning the plane orthogonal to unit u.
void tangent_basis(const Vec& u, Vec& e1, Vec& e2) {
  e1 = (std::abs(u[0]) < 0.6 ? Vec::UnitX() : Vec::UnitY()).cross(u).normalized();
  e2 = u.cross(e1);
}
}  // namespace

SupportOracle::SupportOracle(const geom::Desc& body1, const geom::Desc& body2, SupportOracleOptions options)
    : opt_(options) {
  for (int b = 0; b < 2; ++b) {
    const geom::Desc& d = b == 0 ? body1 : body2;
    try {
      geom::validate(d);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("SupportOracle: body ") + (b == 0 ? "1" : "2") + ": " + e.what());
    }
  }
  if (options.covering < 8) throw std::invalid_argument("SupportOracle: covering must be >= 8, got " + std::to_string(options.covering));
  out1_ = geom::outer_body(body1);
  out2_ = geom::outer_body(body2);
  inner_ok_ = geom::has_inner_body(body1) && geom::has_inner_body(body2);
  if (inner_ok_) {
    in1_ = geom::inner_body(body1);
    in2_ = geom::inner_body(body2);
  }
  exact_ = geom::is_exact(body1) && geom::is_exact(body2);
}

AlphaBracket SupportOracle::bracket(const geom::Pose& X_12) const {
  AlphaBracket out;
  out.exact = exact_;
  const Mat& R = X_12.R;
  const Vec& r = X_12.p;
  if (!R.allFinite() || !r.allFinite()) {
    out.error = "pose has a NaN or Inf entry";
    return out;
  }
  if (r.squaredNorm() == 0.0) {  // concentric: alpha* = 0
    out.ok = true;
    return out;
  }
  // (1): the lower bound of a direction (outer bodies).
  auto lower = [&](const Vec& u) {
    ++out.evaluations;
    const double ur = u.dot(r);
    if (!(ur > 0.0)) return 0.0;
    return ur / (geom::support(out1_, u) + geom::support(out2_, -(R.transpose() * u)));
  };
  // Covering: Fibonacci points, and r's own direction.
  Vec best = r.normalized();
  double f_best = lower(best);
  const int N = opt_.covering;
  for (int k = 0; k < N; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / N, rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double t = 2.0 * kPi * kGolden * k;
    const Vec u(rho * std::cos(t), rho * std::sin(t), z);
    const double f = lower(u);
    if (f > f_best) f_best = f, best = u;
  }
  // Nelder-Mead on the sphere (gnomonic chart about the current best u),
  // restarted with a fresh, smaller simplex until a restart gains nothing.
  double size = 2.0 * std::sqrt(4.0 * kPi / N);
  const int budget = out.evaluations + opt_.max_evaluations;
  for (int round = 0; round < 40 && size > opt_.angle_tol && out.evaluations < budget; ++round) {
    Vec e1, e2;
    tangent_basis(best, e1, e2);
    const Vec u0 = best;
    auto chart = [&](const Eigen::Vector2d& a) { return Vec((u0 + a[0] * e1 + a[1] * e2).normalized()); };
    const Eigen::Vector2d a = nelder_mead<2>([&](const Eigen::Vector2d& v) { return -lower(chart(v)); }, Eigen::Vector2d::Zero(),
                                             size, opt_.angle_tol, budget - out.evaluations);
    const Vec u = chart(a);
    const double f = lower(u);
    const double gain = f - f_best;
    if (f > f_best) f_best = f, best = u;
    size = std::max(std::min(size, 10.0 * a.norm()), 1e-3 * size);
    if (!(gain > 1e-15 * f_best)) size *= 1e-2;
  }
  out.u = best;
  out.lo = f_best * (1.0 - kRoundingMargin);
  if (!inner_ok_) {
    out.hi = std::numeric_limits<double>::infinity();
    out.ok = std::isfinite(out.lo) && out.lo > 0.0;
    if (!out.ok) out.error = "no positive lower bound found";
    return out;
  }
  // (2): the upper bound of a point (inner bodies), from the witnesses of u.
  auto upper = [&](const Vec& x) {
    ++out.evaluations;
    return std::max(geom::gauge(in1_, x), geom::gauge(in2_, R.transpose() * (x - r)));
  };
  const Vec x1 = f_best * geom::support_point(out1_, best);
  const Vec x2 = r + f_best * (R * geom::support_point(out2_, -(R.transpose() * best)));
  Vec x = x1;
  double g = upper(x1);
  for (const Vec& c : {x2, Vec(0.5 * (x1 + x2))}) {
    const double gc = upper(c);
    if (gc < g) g = gc, x = c;
  }
  // max(g1, g2) is convex, so along the segment x1 -> x2 it is unimodal:
  // golden-section search there first (robust where one gauge has a kink).
  {
    double a = 0.0, b = 1.0;
    const Vec d12 = x2 - x1;
    double c = b - kGolden * (b - a), e = a + kGolden * (b - a);
    double gc = upper(x1 + c * d12), ge = upper(x1 + e * d12);
    for (int it = 0; it < 80 && b - a > 1e-15; ++it) {
      if (gc <= ge) {
        b = e, e = c, ge = gc;
        c = b - kGolden * (b - a);
        gc = upper(x1 + c * d12);
      } else {
        a = c, c = e, gc = ge;
        e = a + kGolden * (b - a);
        ge = upper(x1 + e * d12);
      }
    }
    const Vec xs = x1 + (gc <= ge ? c : e) * d12;
    const double gs = std::min(gc, ge);
    if (gs < g) g = gs, x = xs;
  }
  // Nelder-Mead in R^3 from the best point, restarted likewise.
  double step = std::max((x1 - x2).norm(), 1e-6 * x.norm()) + 1e-300;
  const double stop = 1e-15 * std::max(x.norm(), r.norm());
  const int budget2 = out.evaluations + opt_.max_evaluations;
  for (int round = 0; round < 40 && step > stop && out.evaluations < budget2; ++round) {
    const Vec xn = nelder_mead<3>(upper, x, step, stop, budget2 - out.evaluations);
    const double gn = upper(xn);
    const double gain = g - gn;
    if (gn < g) g = gn, step = std::max(std::min(step, 10.0 * (xn - x).norm()), 1e-3 * step), x = xn;
    if (!(gain > 1e-15 * g)) step *= 1e-2;
  }
  // Points on one body's boundary scaled by f_best: there that body's gauge
  // is f_best <= alpha*, so max of the gauges is a bound as tight as the
  // other gauge. Minimise it over the boundary (2D, by direction), from the
  // direction of the support witness. Support points of near-flat bodies
  // (superquadrics of large n, needles) are ill-conditioned in u; the
  // boundary search does not need them to be accurate.
  for (int body = 0; body < 2; ++body) {
    const geom::Convex& K = body == 0 ? in1_ : in2_;
    const Vec w = body == 0 ? geom::support_point(out1_, best) : geom::support_point(out2_, -(R.transpose() * best));
    if (!(w.norm() > 0.0)) continue;
    auto point = [&](const Vec& d) {
      const Vec y = f_best * d / geom::gauge(K, d);
      return body == 0 ? y : Vec(r + R * y);
    };
    Vec d0 = w.normalized();
    double gsz = 0.1;
    for (int round = 0; round < 12 && gsz > opt_.angle_tol && out.evaluations < budget2 + opt_.max_evaluations; ++round) {
      Vec e1, e2;
      tangent_basis(d0, e1, e2);
      auto chart = [&](const Eigen::Vector2d& v) { return Vec((d0 + v[0] * e1 + v[1] * e2).normalized()); };
      const Eigen::Vector2d v = nelder_mead<2>([&](const Eigen::Vector2d& c) { return upper(point(chart(c))); },
                                               Eigen::Vector2d::Zero(), gsz, opt_.angle_tol, opt_.max_evaluations / 4);
      const Vec xd = point(chart(v));
      const double gd = upper(xd);
      const double gain = g - gd;
      if (gd < g) g = gd, x = xd;
      d0 = chart(v);
      gsz = std::max(std::min(gsz, 10.0 * v.norm()), 1e-3 * gsz);
      if (!(gain > 1e-15 * g)) gsz *= 1e-2;
    }
  }
  // Polish: the normals of the bodies at the common point x are candidates
  // for u (exact at the touching point of a smooth body), and each better u
  // gives witnesses for a new segment search.
  for (int round = 0; round < 6; ++round) {
    auto grad = [&](const geom::Convex& K, const Vec& y) {
      const double h = 1e-7 * std::max(y.norm(), 1e-300);
      Vec gr;
      for (int i = 0; i < 3; ++i)
        gr[i] = geom::gauge(K, y + h * Vec::Unit(i)) - geom::gauge(K, y - h * Vec::Unit(i));
      out.evaluations += 6;
      return gr;
    };
    const Vec n1 = grad(out1_, x), n2 = -(R * grad(out2_, R.transpose() * (x - r)));
    bool improved = false;
    for (const Vec& c : {n1, n2, Vec(n1.normalized() + n2.normalized())}) {
      if (!(c.norm() > 0.0) || !c.allFinite()) continue;
      const Vec u = c.normalized();
      const double f = lower(u);
      if (f > f_best) f_best = f, best = u, improved = true;
    }
    const Vec w1 = f_best * geom::support_point(out1_, best);
    const Vec w2 = r + f_best * (R * geom::support_point(out2_, -(R.transpose() * best)));
    double a = 0.0, b = 1.0;
    for (int it = 0; it < 100 && b - a > 1e-16; ++it) {  // ternary search on the convex segment
      const double c = a + (b - a) / 3.0, e = b - (b - a) / 3.0;
      if (upper(w1 + c * (w2 - w1)) <= upper(w1 + e * (w2 - w1))) b = e; else a = c;
    }
    const Vec xs = w1 + 0.5 * (a + b) * (w2 - w1);
    const double gs = upper(xs);
    if (gs < g) g = gs, x = xs, improved = true;
    if (!improved) break;
  }
  out.u = best;
  out.lo = f_best * (1.0 - kRoundingMargin);
  out.x = x;
  out.hi = g * (1.0 + kRoundingMargin);
  out.ok = std::isfinite(out.lo) && std::isfinite(out.hi) && out.lo > 0.0 && out.lo <= out.hi;
  if (!out.ok)
    out.error = "support oracle: inconsistent bracket [" + std::to_string(out.lo) + ", " + std::to_string(out.hi) + "]";
  return out;
}

AlphaBracket support_bracket(const geom::Desc& body1, const geom::Desc& body2, const geom::Pose& X_12) {
  return SupportOracle(body1, body2).bracket(X_12);
}

}  // namespace idcol::baselines
