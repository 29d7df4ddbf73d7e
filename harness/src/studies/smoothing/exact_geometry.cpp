#include "studies/smoothing/exact_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "idcol_baselines/core_adapter.hpp"
#include "io/text.hpp"

namespace idcol::smoothing {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

using harness::format;

/// Distance from p to the segment [a, b] in the plane.
double seg_dist(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0.0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(px - (ax + t * dx), py - (ay + t * dy));
}

std::vector<Vec3> rim(double y1, double R, int m) {
  std::vector<Vec3> d;
  for (int k = 0; k < m; ++k) {
    const double ph = 2.0 * kPi * (k + 0.5) / m;
    d.push_back(Vec3(y1, R * std::cos(ph), R * std::sin(ph)).normalized());
  }
  return d;
}

/// {y : a_i.y <= b_i}, |a_i| = 1. Its half-spaces, vertices and faces are
/// the baselines' independent geometry's (geom::exact_polytope, through
/// core_adapter's public parameters), never core's own vertices: the radial
/// gap and the Hausdorff bound measure core's smoothing, so the exact body
/// must not come from the code it measures.
class ExactPolytopeBody : public ExactBody {
 public:
  explicit ExactPolytopeBody(const baselines::ExactPolytope& p) {
    for (std::size_t i = 0; i < p.normals.size(); ++i) {
      a_.push_back(p.normals[i]);
      b_.push_back(p.offsets[i]);
    }
    verts_ = p.vertices;
    inner_ = *std::min_element(b_.begin(), b_.end());
    for (const Vec3& v : verts_) outer_ = std::max(outer_, v.norm());
  }
  double radial(const Vec3& u) const override {
    double t = kInf;
    for (std::size_t i = 0; i < a_.size(); ++i) {
      const double c = a_[i].dot(u);
      if (c > 0.0) t = std::min(t, b_[i] / c);
    }
    return t;
  }
  double depth_inside(const Vec3& y) const override {
    double d = kInf;
    for (std::size_t i = 0; i < a_.size(); ++i) d = std::min(d, b_[i] - a_[i].dot(y));
    return std::max(d, 0.0);
  }
  double distance(const Vec3&) const override { return -1.0; }
  bool has_distance() const override { return false; }
  std::vector<Vec3> special_directions() const override {
    std::vector<Vec3> d;
    for (const Vec3& v : verts_) d.push_back(v.normalized());
    // edge midpoints: pairs of vertices sharing two active half-spaces
    for (std::size_t i = 0; i < verts_.size(); ++i)
      for (std::size_t j = i + 1; j < verts_.size(); ++j) {
        int shared = 0;
        for (std::size_t k = 0; k < a_.size(); ++k)
          if (std::abs(a_[k].dot(verts_[i]) - b_[k]) < 1e-9 && std::abs(a_[k].dot(verts_[j]) - b_[k]) < 1e-9) ++shared;
        if (shared >= 2) d.push_back((0.5 * (verts_[i] + verts_[j])).normalized());
      }
    return d;
  }
  double inner() const override { return inner_; }
  double outer() const override { return outer_; }
  std::string describe() const override {
    return "exact polytope (" + std::to_string(a_.size()) + " half-spaces, " + std::to_string(verts_.size()) +
           " vertices)";
  }

 private:
  std::vector<Vec3> a_, verts_;
  std::vector<double> b_;
  double inner_ = 0.0, outer_ = 0.0;
};

/// |y_i| <= h_i.
class BoxBody : public ExactBody {
 public:
  explicit BoxBody(const Vec3& h) : h_(h) {}
  double radial(const Vec3& u) const override {
    double t = kInf;
    for (int i = 0; i < 3; ++i)
      if (u[i] != 0.0) t = std::min(t, h_[i] / std::abs(u[i]));
    return t;
  }
  double depth_inside(const Vec3& y) const override { return std::max(0.0, (h_ - y.cwiseAbs()).minCoeff()); }
  double distance(const Vec3& y) const override { return (y.cwiseAbs() - h_).cwiseMax(0.0).norm(); }
  std::vector<Vec3> special_directions() const override {
    std::vector<Vec3> d;
    for (int s = 0; s < 8; ++s)
      d.push_back(Vec3((s & 1) ? -h_[0] : h_[0], (s & 2) ? -h_[1] : h_[1], (s & 4) ? -h_[2] : h_[2]).normalized());
    for (int i = 0; i < 3; ++i)  // edge midpoints
      for (int s = 0; s < 4; ++s) {
        Vec3 v = h_;
        v[i] = 0.0;
        v[(i + 1) % 3] *= (s & 1) ? -1.0 : 1.0;
        v[(i + 2) % 3] *= (s & 2) ? -1.0 : 1.0;
        d.push_back(v.normalized());
      }
    return d;
  }
  double inner() const override { return h_.minCoeff(); }
  double outer() const override { return h_.norm(); }
  std::string describe() const override { return format("box (half-extents %.17g, %.17g, %.17g)", h_[0], h_[1], h_[2]); }

 private:
  Vec3 h_;
};

/// Solid of revolution about y1 whose meridian section (y1, rho >= 0) is the
/// trapezoid -a <= y1 <= b, rho <= Rb + kappa (y1 + a). The nearest point of
/// a convex solid of revolution to y lies in y's meridian half-plane, so the
/// 3D distance is the 2D distance to the trapezoid. Rb == Rt is the cylinder.
class FrustumBody : public ExactBody {
 public:
  FrustumBody(double Rb, double Rt, double a, double b, std::string name)
      : Rb_(Rb), Rt_(Rt), a_(a), b_(b), kappa_((Rt - Rb) / (a + b)), name_(std::move(name)) {}
  double R0() const { return Rb_ + kappa_ * a_; }  // radius at y1 = 0
  double radial(const Vec3& u) const override {
    const double u1 = u[0], ur = std::hypot(u[1], u[2]);
    double t = kInf;
    if (u1 > 0.0) t = std::min(t, b_ / u1);
    if (u1 < 0.0) t = std::min(t, a_ / -u1);
    const double den = ur - kappa_ * u1;  // t ur <= R0 + kappa t u1
    if (den > 0.0) t = std::min(t, R0() / den);
    return t;
  }
  double depth_inside(const Vec3& y) const override {
    const double rho = std::hypot(y[1], y[2]);
    const double side = (R0() + kappa_ * y[0] - rho) / std::sqrt(1.0 + kappa_ * kappa_);
    return std::max(0.0, std::min({y[0] + a_, b_ - y[0], side}));
  }
  double distance(const Vec3& y) const override {
    const double p1 = y[0], pr = std::hypot(y[1], y[2]);
    if (p1 >= -a_ && p1 <= b_ && pr <= Rb_ + kappa_ * (p1 + a_)) return 0.0;
    // boundary of the meridian section: base cap, slanted side, top cap
    return std::min({seg_dist(p1, pr, -a_, 0.0, -a_, Rb_), seg_dist(p1, pr, -a_, Rb_, b_, Rt_),
                     seg_dist(p1, pr, b_, Rt_, b_, 0.0)});
  }
  std::vector<Vec3> special_directions() const override {
    std::vector<Vec3> d = rim(-a_, Rb_, 64);
    for (const Vec3& v : rim(b_, Rt_, 64)) d.push_back(v);
    return d;
  }
  double inner() const override { return std::min({a_, b_, R0() / std::sqrt(1.0 + kappa_ * kappa_)}); }
  double outer() const override { return std::max(std::hypot(a_, Rb_), std::hypot(b_, Rt_)); }
  std::string describe() const override { return name_; }

 private:
  double Rb_, Rt_, a_, b_, kappa_;
  std::string name_;
};

struct Maker {
  std::unique_ptr<ExactBody> operator()(const Sphere&) const {
    throw std::invalid_argument("exact_body: a sphere is not smoothed; nothing to compare");
  }
  std::unique_ptr<ExactBody> operator()(const Superellipsoid& s) const {
    return std::make_unique<BoxBody>(Vec3(s.a(), s.b(), s.c()));
  }
  std::unique_ptr<ExactBody> operator()(const SuperellipticCylinder& s) const {
    return std::make_unique<FrustumBody>(s.R(), s.R(), s.h(), s.h(),
                                         format("cylinder (R %.17g, half-length %.17g, axis y1)", s.R(), s.h()));
  }
  std::unique_ptr<ExactBody> operator()(const SmoothPolytope& s) const {
    return std::make_unique<ExactPolytopeBody>(std::get<baselines::ExactPolytope>(baselines::to_exact(Shape(s))));
  }
  std::unique_ptr<ExactBody> operator()(const SmoothTruncatedCone& s) const {
    return std::make_unique<FrustumBody>(s.Rb(), s.Rt(), s.a(), s.b(),
                                         format("frustum (Rb %.17g, Rt %.17g, a %.17g, b %.17g, axis y1)", s.Rb(), s.Rt(),
                                             s.a(), s.b()));
  }
};
}  // namespace

std::unique_ptr<ExactBody> exact_body(const Shape& s) { return std::visit(Maker{}, s); }

double smooth_radial(const Shape& s, const Vec3& u, double t_hi) {
  double lo = 0.0, hi = t_hi;
  ShapeEval e;
  for (int i = 0; i < 80 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    eval(s, mid * u, e);
    (e.phi <= 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace idcol::smoothing
