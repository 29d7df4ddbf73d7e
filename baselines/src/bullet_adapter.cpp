#include "idcol_baselines/bullet_adapter.hpp"

#include "idcol_baselines/registry.hpp"

#include <cmath>
#include <string>

#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btConvexInternalShape.h>
#include <BulletCollision/CollisionShapes/btMultiSphereShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>

namespace idcol::baselines {

// CMake compiles this file with the definitions of Bullet's float64 config
// (BT_USE_DOUBLE_PRECISION) and links the -float64 libraries; a mismatch
// would not fail to link for every symbol but would silently read btVector3s
// of the wrong layout. bullet_precision() probes the library itself.
static_assert(sizeof(btScalar) == sizeof(double), "this adapter needs Bullet's double-precision build");

const char* bullet_precision() {
  static const char* const precision = [] {
    const double x = 1.0 + std::ldexp(1.0, -40);  // not a float
    btConvexHullShape hull;
    hull.addPoint(btVector3(x, 0.0, 0.0), false);
    hull.addPoint(btVector3(-1.0, 0.0, 0.0), true);
    return hull.localGetSupportingVertexWithoutMargin(btVector3(1.0, 0.0, 0.0)).x() == x ? "double" : "single";
  }();
  return precision;
}

namespace {

btVector3 to_bt(const Vec3& v) { return btVector3(v[0], v[1], v[2]); }
Vec3 from_bt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

btTransform to_bt(const Pose& X) {
  const Mat3& R = X.R;
  return btTransform(btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                     to_bt(X.p));
}

/// An ellipsoid (a sphere where the axes are equal) with its closed-form
/// support map, E^2 d / |E d| for E = diag(axes), the exact body. Bullet's
/// GJK and EPA reach it through btConvexShape's virtual support call (the
/// CUSTOM_CONVEX_SHAPE_TYPE branch of its non-virtual dispatch). Margin 0.
class ExactEllipsoidShape final : public btConvexInternalShape {
 public:
  explicit ExactEllipsoidShape(const Vec3& axes) : axes_(to_bt(axes)) {
    m_shapeType = CUSTOM_CONVEX_SHAPE_TYPE;
    m_implicitShapeDimensions = axes_;
    setMargin(0.0);
  }

  btVector3 localGetSupportingVertexWithoutMargin(const btVector3& d) const override {
    const btVector3 E = axes_ * m_localScaling;
    const btVector3 w = E * d;
    const btScalar n = w.length();
    return n > 0.0 ? E * w / n : btVector3(E.x(), 0.0, 0.0);
  }
  void batchedUnitVectorGetSupportingVertexWithoutMargin(const btVector3* dirs, btVector3* out, int n) const override {
    for (int i = 0; i < n; ++i) out[i] = localGetSupportingVertexWithoutMargin(dirs[i]);
  }
  // The box of the rotated ellipsoid: half-extent sqrt(sum_j (R_ij E_j)^2) on world axis i.
  void getAabb(const btTransform& t, btVector3& lo, btVector3& hi) const override {
    const btVector3 E = axes_ * m_localScaling;
    btVector3 h;
    for (int i = 0; i < 3; ++i) h[i] = (t.getBasis()[i] * E).length() + getMargin();
    lo = t.getOrigin() - h;
    hi = t.getOrigin() + h;
  }
  void calculateLocalInertia(btScalar mass, btVector3& inertia) const override {
    const btVector3 E = axes_ * m_localScaling, E2 = E * E;
    inertia = btVector3(E2.y() + E2.z(), E2.x() + E2.z(), E2.x() + E2.y()) * (mass / 5.0);
  }
  const char* getName() const override { return "idcol exact ellipsoid"; }

 private:
  btVector3 axes_;
};

/// n points spread evenly over the unit sphere (Fibonacci lattice).
std::vector<Vec3> fibonacci_sphere(int n) {
  std::vector<Vec3> u(static_cast<std::size_t>(n));
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - 2.0 * (k + 0.5) / n, r = std::sqrt(1.0 - z * z);
    u[static_cast<std::size_t>(k)] = Vec3(r * std::cos(golden * k), r * std::sin(golden * k), z);
  }
  return u;
}

std::unique_ptr<btConvexHullShape> make_hull(const std::vector<Vec3>& points) {
  auto hull = std::make_unique<btConvexHullShape>();
  for (const Vec3& p : points) hull->addPoint(to_bt(p), false);
  hull->recalcLocalAabb();
  return hull;
}

std::unique_ptr<btConvexShape> make_shape(const ExactShape& s, const BulletOptions& o) {
  std::unique_ptr<btConvexShape> shape;
  if (!is_ellipsoid(s)) {
    shape = make_hull(std::get<ExactPolytope>(s).vertices);
  } else {
    const Vec3 axes = ellipsoid_axes(s);
    switch (o.ellipsoid) {
      case BulletEllipsoid::ExactSupport: shape = std::make_unique<ExactEllipsoidShape>(axes); break;
      case BulletEllipsoid::ScaledSphere: {
        const btVector3 centre(0.0, 0.0, 0.0);
        const btScalar radius = 1.0;
        shape = std::make_unique<btMultiSphereShape>(&centre, &radius, 1);
        shape->setLocalScaling(to_bt(axes));
        break;
      }
      case BulletEllipsoid::SurfaceHull: {
        std::vector<Vec3> points = fibonacci_sphere(o.hull_points);
        for (Vec3& p : points) p = p.cwiseProduct(axes);
        shape = make_hull(points);
        break;
      }
    }
  }
  // Margin 0: the body itself, not Bullet's rounded body (core + 0.04). What
  // Bullet loses: its GJK stops where the cores are margin apart, and EPA
  // (the slower, less accurate part) runs only for deeper penetrations; at
  // margin 0 every touching or penetrating pose goes to EPA.
  shape->setMargin(0.0);
  return shape;
}

bool finite(const Pose& X) { return X.R.allFinite() && X.p.allFinite(); }

BaselineAnswer failed(std::string why) {
  BaselineAnswer a;
  a.failed = true;
  a.error = std::move(why);
  return a;
}

/// Fills the answer from Bullet's signed distance d, a unit normal n_1 from
/// body 1 toward body 2 and the two points; any non-finite value makes it a
/// failure.
BaselineAnswer answer(const char* call, double d, const Vec3& n_1, const Vec3& p1_1, const Vec3& p2_1) {
  if (!std::isfinite(d) || !n_1.allFinite() || !p1_1.allFinite() || !p2_1.allFinite())
    return failed(std::string(call) + ": non-finite answer");
  BaselineAnswer a;
  a.has_distance = a.has_points = true;
  a.signed_distance = d;
  a.intersect = d <= 0.0;
  a.p1_1 = p1_1;
  a.p2_1 = p2_1;
  const double len = n_1.norm();
  if (len > 0.0) {
    a.has_normal = true;
    a.normal_1 = n_1 / len;
  }
  return a;
}

/// Why SignedDistance returned false, by the status it left. It runs GJK
/// for a distance and, where that finds no separation, GJK again (from the
/// opposite direction) and EPA for a depth; Penetration resets the status
/// to Separated and leaves it there when its own GJK finds the bodies apart.
std::string why_no_answer(btGjkEpaSolver2::sResults::eStatus s) {
  const std::string call = "btGjkEpaSolver2::SignedDistance returned false, status ";
  switch (s) {
    case btGjkEpaSolver2::sResults::Separated:
      return call + "Separated: its distance GJK found no gap and its penetration GJK no overlap (touching)";
    case btGjkEpaSolver2::sResults::Penetrating: return call + "Penetrating";
    case btGjkEpaSolver2::sResults::GJK_Failed: return call + "GJK_Failed (\"probably just touching\")";
    case btGjkEpaSolver2::sResults::EPA_Failed: return call + "EPA_Failed";
  }
  return call + "unknown";
}
}  // namespace

struct BulletPair::Impl {
  std::unique_ptr<btConvexShape> s1, s2;
};

BulletPair::BulletPair(const ExactShape& body1, const ExactShape& body2, BulletOptions options) : impl_(new Impl) {
  impl_->s1 = make_shape(body1, options);
  impl_->s2 = make_shape(body2, options);
}
BulletPair::~BulletPair() = default;
BulletPair::BulletPair(BulletPair&&) noexcept = default;
BulletPair& BulletPair::operator=(BulletPair&&) noexcept = default;

BaselineAnswer BulletPair::pair_detector(const Pose& X_12) const {
  if (!finite(X_12)) return failed("btGjkPairDetector: the pose is not finite");
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector gjk(impl_->s1.get(), impl_->s2.get(), &simplex, &epa);
  btGjkPairDetector::ClosestPointInput in;
  in.m_transformA.setIdentity();
  in.m_transformB = to_bt(X_12);
  btPointCollector out;
  gjk.getClosestPoints(in, out, nullptr);
  if (!out.m_hasResult)
    return failed("btGjkPairDetector: no result (m_lastUsedMethod " + std::to_string(gjk.m_lastUsedMethod) + ")");
  // Bullet: the point is on B (body 2), the normal on B points toward A, and
  // the point on A is point + distance * normal (btDiscreteCollisionDetectorInterface.h).
  const double d = out.m_distance;
  const Vec3 n_B = from_bt(out.m_normalOnBInWorld), p2 = from_bt(out.m_pointInWorld);
  return answer("btGjkPairDetector", d, -n_B, p2 + d * n_B, p2);
}

BaselineAnswer BulletPair::gjk_epa2(const Pose& X_12) const {
  if (!finite(X_12)) return failed("btGjkEpaSolver2: the pose is not finite");
  btTransform I;
  I.setIdentity();
  // The first search direction: body 2's origin seen from body 1's, as
  // Bullet's own btGjkEpaPenetrationDepthSolver tries first.
  const btVector3 guess = X_12.p.squaredNorm() > 0.0 ? to_bt(X_12.p) : btVector3(1.0, 0.0, 0.0);
  btGjkEpaSolver2::sResults r;
  if (!btGjkEpaSolver2::SignedDistance(impl_->s1.get(), I, impl_->s2.get(), to_bt(X_12), guess, r))
    return failed(why_no_answer(r.status));
  // Bullet: witnesses[0] on shape 0 (body 1), witnesses[1] on shape 1, and
  // normal = (witnesses[0] - witnesses[1]) / distance, from body 2 toward
  // body 1, in both the separated and the penetrating case (btGjkEpa2.cpp).
  return answer("btGjkEpaSolver2", r.distance, -from_bt(r.normal), from_bt(r.witnesses[0]), from_bt(r.witnesses[1]));
}

// ------------------------------------------------------------- registration
// Bullet's rows of the competitor table (registry.hpp); this file is compiled
// only where CMake finds Bullet's double-precision build.
namespace {
BaselineAnswer bullet_gjk_pair(const BulletPair& p, const Pose& X_12) { return p.pair_detector(X_12); }
BaselineAnswer bullet_gjk_epa2(const BulletPair& p, const Pose& X_12) { return p.gjk_epa2(X_12); }

// Its boolean is the sign of the signed distance (intersect = distance <= 0).
const Competitor kBulletGjkPair{"bullet_gjk_pair", "Bullet GJK/EPA (btGjkPairDetector)",
                                "Bullet 3.24 btGjkPairDetector::getClosestPoints (Voronoi simplex GJK, "
                                "btGjkEpaPenetrationDepthSolver), margin 0",
                                Answers{true, true, true}, serves_exact_bodies,
                                &Prepared<BulletPair, bullet_gjk_pair>::make};
const Competitor kBulletGjkEpa2{"bullet_gjk_epa2", "Bullet GJK/EPA (btGjkEpaSolver2)",
                                "Bullet 3.24 btGjkEpaSolver2::SignedDistance, margin 0", Answers{true, true, true},
                                serves_exact_bodies, &Prepared<BulletPair, bullet_gjk_epa2>::make};
}  // namespace

namespace detail {
std::vector<const Competitor*> competitors_bullet() { return {&kBulletGjkPair, &kBulletGjkEpa2}; }
}  // namespace detail

}  // namespace idcol::baselines
