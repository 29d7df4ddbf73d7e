#include "idcol_baselines/fcl_adapter.hpp"

#include "idcol_baselines/registry.hpp"

#include <csetjmp>
#include <csignal>
#include <exception>
#include <vector>

#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/ellipsoid.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/continuous_collision.h>
#include <fcl/narrowphase/distance.h>

namespace idcol::baselines {

namespace {
std::shared_ptr<fcl::CollisionGeometryd> make_geometry(const ExactShape& s) {
  if (const auto* sp = std::get_if<geom::SphereDesc>(&s)) return std::make_shared<fcl::Sphered>(sp->R);
  if (const auto* e = std::get_if<geom::SuperellipsoidDesc>(&s)) return std::make_shared<fcl::Ellipsoidd>(e->a, e->b, e->c);
  const auto& p = std::get<ExactPolytope>(s);
  auto verts = std::make_shared<std::vector<fcl::Vector3d>>(p.vertices.begin(), p.vertices.end());
  // FCL's face encoding: [n, i_0, ..., i_{n-1}, n', ...], counter-clockwise from outside.
  auto faces = std::make_shared<std::vector<int>>();
  for (const auto& f : p.faces) {
    faces->push_back(static_cast<int>(f.size()));
    faces->insert(faces->end(), f.begin(), f.end());
  }
  auto g = std::make_shared<fcl::Convexd>(verts, static_cast<int>(p.faces.size()), faces, true);
  g->computeLocalAABB();
  return g;
}

// Debian's libfcl is built with assertions on, and its EPA (signed distance
// in penetration) can fail `isOutsidePolytopeFace` near touching contact,
// which calls abort(). A SIGABRT handler, armed only around FCL calls, jumps
// back to the call site so the failure is counted instead of killing the
// sweep. The handler is installed once (SA_NODEFER, so no mask needs
// restoring and sigsetjmp need not save it); unarmed, it re-raises with the
// default action. What EPA had allocated leaks; FCL's state is per call.
thread_local sigjmp_buf* t_abort_target = nullptr;
void on_abort(int sig) {
  if (t_abort_target) siglongjmp(*t_abort_target, 1);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}
void install_abort_trap() {
  static const bool installed = [] {
    struct sigaction sa {};
    sa.sa_handler = on_abort;
    sa.sa_flags = SA_NODEFER;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGABRT, &sa, nullptr);
    return true;
  }();
  (void)installed;
}

fcl::Transform3d to_fcl(const Pose& X) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.linear() = X.R;
  T.translation() = X.p;
  return T;
}
}  // namespace

struct FclPair::Impl {
  std::shared_ptr<fcl::CollisionGeometryd> g1, g2;
  FclOptions opt;
  fcl::CollisionRequestd creq, creq_contact;
  fcl::DistanceRequestd dreq;
};

FclPair::FclPair(const ExactShape& body1, const ExactShape& body2, FclOptions options) : impl_(new Impl) {
  impl_->g1 = make_geometry(body1);
  impl_->g2 = make_geometry(body2);
  impl_->opt = options;
  auto& c = impl_->creq;
  c.num_max_contacts = 1;
  c.enable_contact = false;
  c.gjk_solver_type = fcl::GST_LIBCCD;
  c.gjk_tolerance = options.gjk_tolerance;
  impl_->creq_contact = c;
  impl_->creq_contact.enable_contact = true;
  auto& d = impl_->dreq;
  d.enable_nearest_points = true;
  d.enable_signed_distance = true;
  d.gjk_solver_type = fcl::GST_LIBCCD;
  d.distance_tolerance = options.distance_tolerance;
}
FclPair::~FclPair() = default;
FclPair::FclPair(FclPair&&) noexcept = default;
FclPair& FclPair::operator=(FclPair&&) noexcept = default;

FclContinuousAnswer FclPair::continuous(const Pose& X0, const Pose& X1, FclContinuousMethod method, bool screw,
                                        int steps) const {
  const bool naive = method == FclContinuousMethod::Naive;
  fcl::ContinuousCollisionRequestd req(naive ? steps : 100, naive ? 1.0 / steps : 1e-6,
                                       screw ? fcl::CCDM_SCREW : fcl::CCDM_TRANS, fcl::GST_LIBCCD,
                                       naive ? fcl::CCDC_NAIVE : fcl::CCDC_CONSERVATIVE_ADVANCEMENT);
  fcl::ContinuousCollisionResultd res;
  const fcl::Transform3d I = fcl::Transform3d::Identity();
  const double rc = fcl::continuousCollide(impl_->g1.get(), I, I, impl_->g2.get(), to_fcl(X0), to_fcl(X1), req, res);
  FclContinuousAnswer a;
  if (rc < 0) return a.supported = false, a;
  a.hit = res.is_collide;
  a.t = res.time_of_contact;
  return a;
}

bool FclPair::intersects(const Pose& X_12) const {
  fcl::CollisionResultd res;
  fcl::collide(impl_->g1.get(), fcl::Transform3d::Identity(), impl_->g2.get(), to_fcl(X_12), impl_->creq, res);
  return res.isCollision();
}

BaselineAnswer FclPair::collide(const Pose& X_12, bool with_contact) const {
  BaselineAnswer a;
  try {
    fcl::CollisionResultd res;
    fcl::collide(impl_->g1.get(), fcl::Transform3d::Identity(), impl_->g2.get(), to_fcl(X_12),
                 with_contact ? impl_->creq_contact : impl_->creq, res);
    a.intersect = res.isCollision();
    if (a.intersect && with_contact && res.numContacts() > 0) {
      const auto& c = res.getContact(0);
      // FCL: normal points from o1 to o2, pos is mid-contact, world = body-1 frame.
      a.has_distance = a.has_normal = a.has_points = true;
      a.signed_distance = -c.penetration_depth;
      a.normal_1 = c.normal;
      a.p1_1 = c.pos + 0.5 * c.penetration_depth * c.normal;
      a.p2_1 = c.pos - 0.5 * c.penetration_depth * c.normal;
    }
  } catch (const std::exception& e) {
    a.failed = a.threw = true;
    a.error = e.what();
  }
  return a;
}

BaselineAnswer FclPair::distance(const Pose& X_12) const {
  BaselineAnswer a;
  install_abort_trap();
  try {
    fcl::DistanceResultd res;
    sigjmp_buf env;
    if (sigsetjmp(env, 0) != 0) {
      t_abort_target = nullptr;
      a.failed = a.threw = true;
      a.error = "FCL aborted (assertion in its EPA); trapped";
      note_trapped_abort();
      return a;
    }
    t_abort_target = &env;
    fcl::distance(impl_->g1.get(), fcl::Transform3d::Identity(), impl_->g2.get(), to_fcl(X_12), impl_->dreq, res);
    t_abort_target = nullptr;
    a.has_distance = true;
    a.signed_distance = res.min_distance;
    a.intersect = res.min_distance <= 0.0;
    a.has_points = true;
    a.p1_1 = res.nearest_points[0];  // FCL 0.7: world frame (= body-1 frame here)
    a.p2_1 = res.nearest_points[1];
    const Vec3 d = a.p2_1 - a.p1_1;
    if (d.norm() > 0.0 && res.min_distance != 0.0) {
      a.has_normal = true;
      a.normal_1 = (res.min_distance > 0.0 ? 1.0 : -1.0) * d.normalized();
    }
  } catch (const std::exception& e) {
    t_abort_target = nullptr;
    a.failed = a.threw = true;
    a.error = e.what();
  }
  return a;
}

// ------------------------------------------------------------- registration
// FCL's rows of the competitor table (registry.hpp); this file is compiled
// only where CMake finds FCL.
namespace {
BaselineAnswer fcl_collide(const FclPair& p, const Pose& X_12) { return p.collide(X_12, true); }
BaselineAnswer fcl_distance(const FclPair& p, const Pose& X_12) { return p.distance(X_12); }

const Competitor kFclCollide{"fcl_collide", "FCL collide (GJK, libccd)",
                             "FCL 0.7 fcl::collide (GST_LIBCCD) with its MPR contact",
                             Answers{false, true, false}, serves_exact_bodies, &Prepared<FclPair, fcl_collide>::make};
// Its boolean is the sign of the signed distance (intersect = distance <= 0).
const Competitor kFclDistance{"fcl_distance", "FCL distance (GJK/EPA)",
                              "FCL 0.7 fcl::distance (GST_LIBCCD), signed, with nearest points",
                              Answers{true, true, true}, serves_exact_bodies, &Prepared<FclPair, fcl_distance>::make};
}  // namespace

namespace detail {
std::vector<const Competitor*> competitors_fcl() { return {&kFclCollide, &kFclDistance}; }
}  // namespace detail

}  // namespace idcol::baselines
