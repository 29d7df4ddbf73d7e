#include "idcol_baselines/ccd_adapter.hpp"

#include "idcol_baselines/registry.hpp"

#include <ccd/ccd.h>

namespace idcol::baselines {

static_assert(sizeof(ccd_real_t) == sizeof(double), "this adapter assumes libccd built with CCD_DOUBLE");

const char* ccd_precision() { return sizeof(ccd_real_t) == sizeof(double) ? "double" : "single"; }

namespace {
using Body = CcdPair::Body;

Vec3 local_support(const ExactShape& s, const Vec3& d) {
  if (is_ellipsoid(s)) {
    // argmax_{y^T E^-2 y <= 1} d^T y = E^2 d / |E d|.
    const Vec3 axes = ellipsoid_axes(s);
    const Vec3 w = axes.cwiseProduct(d);
    const double n = w.norm();
    return n > 0.0 ? Vec3(axes.cwiseProduct(w) / n) : Vec3(axes[0], 0.0, 0.0);
  }
  const auto& p = std::get<ExactPolytope>(s);
  int best = 0;
  double bv = p.vertices[0].dot(d);
  for (int i = 1; i < static_cast<int>(p.vertices.size()); ++i) {
    const double v = p.vertices[i].dot(d);
    if (v > bv) bv = v, best = i;
  }
  return p.vertices[best];
}

void support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* b = static_cast<const Body*>(obj);
  const Vec3 d(dir->v[0], dir->v[1], dir->v[2]);
  const Vec3 s = b->R * local_support(*b->shape, b->R.transpose() * d) + b->p;
  out->v[0] = s[0], out->v[1] = s[1], out->v[2] = s[2];
}

void center(const void* obj, ccd_vec3_t* out) {
  const auto* b = static_cast<const Body*>(obj);
  out->v[0] = b->p[0], out->v[1] = b->p[1], out->v[2] = b->p[2];
}

ccd_t make_ccd(const CcdOptions& o) {
  ccd_t c;
  CCD_INIT(&c);
  c.support1 = support;
  c.support2 = support;
  c.center1 = center;
  c.center2 = center;
  c.max_iterations = o.max_iterations;
  c.mpr_tolerance = o.mpr_tolerance;
  c.epa_tolerance = o.epa_tolerance;
  c.dist_tolerance = o.dist_tolerance;
  return c;
}

// libccd's penetration outputs: moving body 2 by depth * dir separates the
// bodies (dir points from body 1 toward body 2); pos is midway between them.
void fill_penetration(BaselineAnswer& a, double depth, const ccd_vec3_t& dir, const ccd_vec3_t& pos) {
  a.has_distance = a.has_normal = a.has_points = true;
  a.signed_distance = -depth;
  a.normal_1 = Vec3(dir.v[0], dir.v[1], dir.v[2]);
  const Vec3 c(pos.v[0], pos.v[1], pos.v[2]);
  a.p1_1 = c + 0.5 * depth * a.normal_1;
  a.p2_1 = c - 0.5 * depth * a.normal_1;
}
}  // namespace

CcdPair::CcdPair(ExactShape body1, ExactShape body2, CcdOptions options)
    : s1_(std::move(body1)), s2_(std::move(body2)), opt_(options) {}

bool CcdPair::gjk_intersect(const Pose& X_12) const {
  const Body b1{&s1_}, b2{&s2_, X_12.R, X_12.p};
  const ccd_t c = make_ccd(opt_);
  return ccdGJKIntersect(&b1, &b2, &c) != 0;
}

bool CcdPair::mpr_intersect(const Pose& X_12) const {
  const Body b1{&s1_}, b2{&s2_, X_12.R, X_12.p};
  const ccd_t c = make_ccd(opt_);
  return ccdMPRIntersect(&b1, &b2, &c) != 0;
}

BaselineAnswer CcdPair::gjk(const Pose& X_12) const {
  BaselineAnswer a;
  a.intersect = gjk_intersect(X_12);
  return a;
}

BaselineAnswer CcdPair::mpr(const Pose& X_12) const {
  BaselineAnswer a;
  a.intersect = mpr_intersect(X_12);
  return a;
}

BaselineAnswer CcdPair::mpr_penetration(const Pose& X_12) const {
  BaselineAnswer a;
  const Body b1{&s1_}, b2{&s2_, X_12.R, X_12.p};
  const ccd_t c = make_ccd(opt_);
  ccd_real_t depth = 0;
  ccd_vec3_t dir, pos;
  const int rc = ccdMPRPenetration(&b1, &b2, &c, &depth, &dir, &pos);
  a.intersect = rc == 0;
  if (a.intersect) fill_penetration(a, depth, dir, pos);
  return a;
}

BaselineAnswer CcdPair::epa_penetration(const Pose& X_12) const {
  BaselineAnswer a;
  const Body b1{&s1_}, b2{&s2_, X_12.R, X_12.p};
  const ccd_t c = make_ccd(opt_);
  ccd_real_t depth = 0;
  ccd_vec3_t dir, pos;
  const int rc = ccdGJKPenetration(&b1, &b2, &c, &depth, &dir, &pos);
  if (rc == -2) {
    a.failed = true;
    a.error = "ccdGJKPenetration: memory allocation failure (-2)";
    return a;
  }
  a.intersect = rc == 0;
  if (a.intersect) fill_penetration(a, depth, dir, pos);
  return a;
}

// ------------------------------------------------------------- registration
// libccd's rows of the competitor table (registry.hpp); this file is compiled
// only where CMake finds libccd.
namespace {
BaselineAnswer ccd_gjk(const CcdPair& p, const Pose& X_12) { return p.gjk(X_12); }
BaselineAnswer ccd_mpr(const CcdPair& p, const Pose& X_12) { return p.mpr(X_12); }
BaselineAnswer ccd_mpr_penetration(const CcdPair& p, const Pose& X_12) { return p.mpr_penetration(X_12); }
BaselineAnswer ccd_epa(const CcdPair& p, const Pose& X_12) { return p.epa_penetration(X_12); }

const Competitor kCcdGjk{"ccd_gjk", "libccd GJK", "libccd ccdGJKIntersect", Answers{false, false, false},
                         serves_exact_bodies, &Prepared<CcdPair, ccd_gjk>::make};
const Competitor kCcdMpr{"ccd_mpr", "libccd MPR", "libccd ccdMPRIntersect", Answers{false, false, false},
                         serves_exact_bodies, &Prepared<CcdPair, ccd_mpr>::make};
// Depth along MPR's own direction: an upper bound on the minimum depth.
const Competitor kCcdMprPenetration{"ccd_mpr_penetration", "libccd MPR penetration", "libccd ccdMPRPenetration",
                                    Answers{false, true, false}, serves_exact_bodies,
                                    &Prepared<CcdPair, ccd_mpr_penetration>::make};
// EPA on smooth shapes is unreliable (ccd_adapter.hpp); the name says so.
const Competitor kCcdEpa{"ccd_epa_unreliable", "libccd EPA (unreliable on smooth shapes)",
                         "libccd ccdGJKPenetration", Answers{false, true, false}, serves_exact_bodies,
                         &Prepared<CcdPair, ccd_epa>::make};
}  // namespace

namespace detail {
std::vector<const Competitor*> competitors_ccd() { return {&kCcdGjk, &kCcdMpr, &kCcdMprPenetration, &kCcdEpa}; }
}  // namespace detail

}  // namespace idcol::baselines
