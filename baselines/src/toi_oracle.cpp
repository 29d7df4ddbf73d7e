#include "idcol_baselines/toi_oracle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "idcol_baselines/oracles.hpp"

namespace idcol::baselines {

namespace {

using geom::Mat;
using geom::Vec;

Mat hat(const Vec& w) {
  Mat W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return W;
}

/// exp of the body twist (w, v): rotation by Rodrigues' formula, translation
/// V v with V = I + (1 - cos th)/th^2 W + (th - sin th)/th^3 W^2.
geom::Pose twist_exp(const Vec& w, const Vec& v) {
  const double th = w.norm();
  const Mat W = hat(w), I = Mat::Identity();
  double a, b, c;  // sin th / th, (1 - cos th) / th^2, (th - sin th) / th^3
  if (th < 1e-5) {
    const double t2 = th * th;
    a = 1.0 - t2 / 6.0, b = 0.5 - t2 / 24.0, c = 1.0 / 6.0 - t2 / 120.0;
  } else {
    a = std::sin(th) / th, b = (1.0 - std::cos(th)) / (th * th), c = (th - std::sin(th)) / (th * th * th);
  }
  return {I + a * W + b * W * W, (I + b * W + c * W * W) * v};
}

}  // namespace

OracleMotion::OracleMotion(const geom::Pose& X0, const geom::Pose& X1) : X0_(X0), X1_(X1) {
  translation_ = X0.R == X1.R;
  if (translation_) return;
  // X0^-1 X1 = (R, p): w from the rotation's angle and axis, v = V^-1 p.
  const Mat R = X0.R.transpose() * X1.R;
  const Vec p = X0.R.transpose() * (X1.p - X0.p);
  const Eigen::AngleAxisd aa(R);
  w_ = aa.angle() * aa.axis();
  const double th = w_.norm();
  const Mat W = hat(w_);
  // V^-1 = I - W/2 + (1/th^2) (1 - (th/2) cot(th/2)) W^2.
  const double k = th < 1e-5 ? 1.0 / 12.0 : (1.0 - 0.5 * th / std::tan(0.5 * th)) / (th * th);
  v_ = (Mat::Identity() - 0.5 * W + k * W * W) * p;
}

geom::Pose OracleMotion::at(double t) const {
  if (translation_) return {X0_.R, X0_.p + t * (X1_.p - X0_.p)};
  const geom::Pose E = twist_exp(t * w_, t * v_);
  return {X0_.R * E.R, X0_.R * E.p + X0_.p};
}

void ToiOracleOptions::validate() const {
  if (samples < 10) throw std::invalid_argument("ToiOracleOptions::samples: expected >= 10, got " + std::to_string(samples));
  if (!(graze >= 0.0) || !(graze < 1.0))
    throw std::invalid_argument("ToiOracleOptions::graze: expected a number in [0, 1), got " + std::to_string(graze));
  if (bisections < 0) throw std::invalid_argument("ToiOracleOptions::bisections: expected >= 0, got " + std::to_string(bisections));
}

namespace {
/// The ellipsoid's axes (a sphere's three equal ones), or false.
bool ellipsoid_axes(const geom::Desc& d, Vec& axes) {
  if (const auto* s = std::get_if<geom::SphereDesc>(&d)) return axes = Vec::Constant(s->R), true;
  if (const auto* e = std::get_if<geom::SuperellipsoidDesc>(&d); e && e->n == 1.0) return axes = Vec(e->a, e->b, e->c), true;
  return false;
}
}  // namespace

ToiOracle::ToiOracle(const geom::Desc& body1, const geom::Desc& body2, ToiOracleOptions options)
    : support_(body1, body2), opt_(options) {
  opt_.validate();
  outer_sum_ = geom::radii(geom::outer_body(body1))[1] + geom::radii(geom::outer_body(body2))[1];
  const auto* s1 = std::get_if<geom::SphereDesc>(&body1);
  const auto* s2 = std::get_if<geom::SphereDesc>(&body2);
  if (s1 && s2) {
    method_ = Method::ClosedForm;
    radius_sum_ = s1->R + s2->R;
  } else if (ellipsoid_axes(body1, axes1_) && ellipsoid_axes(body2, axes2_)) {
    method_ = Method::PerramWertheim;
  }
}

const char* ToiOracle::method() const {
  switch (method_) {
    case Method::ClosedForm: return "closed_form";
    case Method::PerramWertheim: return "perram_wertheim";
    case Method::Support: break;
  }
  return "support_function";
}

std::array<double, 2> ToiOracle::bracket(const geom::Pose& X) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Far apart: the outer balls alone keep the bodies apart (a bracket
  // above 1 whatever the method; the margin covers the radii's rounding).
  if (const double lb = X.p.norm() / outer_sum_ * (1.0 - 1e-12); lb > 1.0 + opt_.graze)
    return {lb, std::numeric_limits<double>::infinity()};
  switch (method_) {
    case Method::ClosedForm: {
      const double a = X.p.norm() / radius_sum_;
      return {a, a};
    }
    case Method::PerramWertheim: {
      const OracleAnswer o = perram_wertheim(axes1_, axes2_, X);
      if (!o.ok) return {nan, nan};
      return {o.alpha, o.alpha};
    }
    case Method::Support: break;
  }
  const AlphaBracket b = support_.bracket(X);
  if (!b.ok) return {nan, nan};
  return {b.lo, b.hi};
}

ToiOracleAnswer ToiOracle::first_contact(const geom::Pose& X0, const geom::Pose& X1) const {
  const OracleMotion m(X0, X1);
  ToiOracleAnswer a;
  a.min_lo = a.min_hi = std::numeric_limits<double>::infinity();
  bool have_lo = false, have_hi = false;
  double prev = 0.0;
  // The first root of end(t) - 1 in [t0, t1], where end(t0) > 1 >= end(t1).
  auto bisect = [&](int end, double t0, double t1) {
    for (int i = 0; i < opt_.bisections; ++i) {
      const double mid = 0.5 * (t0 + t1);
      ++a.evaluations;
      (bracket(m.at(mid))[end] > 1.0 ? t0 : t1) = mid;
    }
    return t1;
  };
  bool unknown = false;
  for (int j = 0; j <= opt_.samples; ++j) {
    const double t = static_cast<double>(j) / opt_.samples;
    const std::array<double, 2> b = bracket(m.at(t));
    ++a.evaluations;
    if (!(b[0] == b[0]) || !(b[1] == b[1])) {  // no answer at this time: no verdict on the motion
      unknown = true;
      break;
    }
    a.min_lo = std::min(a.min_lo, b[0]);
    a.min_hi = std::min(a.min_hi, b[1]);
    if (j == 0 && b[0] <= 1.0) a.initially_touching = true;
    if (!have_lo && b[0] <= 1.0) have_lo = true, a.t_lo = j == 0 ? 0.0 : bisect(0, prev, t);
    if (!have_hi && b[1] <= 1.0) have_hi = true, a.t_hi = j == 0 ? 0.0 : bisect(1, prev, t);
    prev = t;
  }
  if (unknown) return a;  // neither a clear hit nor a clear miss
  a.clear_hit = a.min_hi < 1.0 - opt_.graze;
  a.clear_miss = a.min_lo > 1.0 + opt_.graze;
  return a;
}

}  // namespace idcol::baselines
