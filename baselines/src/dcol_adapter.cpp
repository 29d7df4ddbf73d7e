// DCOL (dcol.hpp) as a row of the competitor table: the exact bodies every
// competitor takes (exact_shape.hpp) as DCOL's primitives, body 1 at the
// identity and body 2 at X_12. It answers alpha* itself, so its boolean is
// alpha < 1 and the harness also compares its alpha with the exact oracle's.
#include "idcol_baselines/dcol_adapter.hpp"

#include <cmath>
#include <utility>

#include "idcol_baselines/registry.hpp"

namespace idcol::baselines {

dcol::Primitive to_dcol(const ExactShape& s) {
  if (const auto* sp = std::get_if<geom::SphereDesc>(&s)) return dcol::make_sphere(sp->R);
  if (const auto* e = std::get_if<geom::SuperellipsoidDesc>(&s)) return dcol::make_ellipsoid_axes(e->a, e->b, e->c);
  const auto& p = std::get<ExactPolytope>(s);
  Eigen::Matrix<double, Eigen::Dynamic, 3> A(p.normals.size(), 3);
  Eigen::VectorXd b(p.offsets.size());
  for (std::size_t i = 0; i < p.normals.size(); ++i) {
    A.row(i) = p.normals[i].transpose();
    b(i) = p.offsets[i];
  }
  return dcol::make_polytope(A, b);
}

DcolPair::DcolPair(const ExactShape& body1, const ExactShape& body2, dcol::Options options)
    : p1_(to_dcol(body1)), p2_(to_dcol(body2)), opt_(options) {
  // Validates the options now, not at the first query.
  (void)dcol::proximity(dcol::Sphere{}, Vec3::Zero(), Mat3::Identity(), dcol::Sphere{}, Vec3::UnitX(), Mat3::Identity(), opt_);
}

dcol::Result DcolPair::solve(const Pose& X_12) const {
  return dcol::proximity(p1_, Vec3::Zero(), Mat3::Identity(), p2_, X_12.p, X_12.R, opt_);
}

BaselineAnswer DcolPair::answer(const Pose& X_12) const {
  const dcol::Result r = solve(X_12);
  BaselineAnswer a;
  a.iterations = r.iterations;
  if (!r.converged() || !std::isfinite(r.alpha)) {
    a.failed = true;
    a.error = std::string("DCOL: ") + dcol::to_string(r.status) + " after " + std::to_string(r.iterations) +
              " iterations (s.z / degree " + std::to_string(r.mu) + ")";
    return a;
  }
  a.has_alpha = true;
  a.alpha = r.alpha;
  // alpha lies within about its duality gap of alpha* (1.24 gaps at most in
  // idcol_dcol_tests, baselines/README.md): twice the gap is its bound.
  a.alpha_bound = 2.0 * r.gap;
  a.intersect = r.alpha < 1.0;
  return a;
}

// ------------------------------------------------------------- registration
namespace {
BaselineAnswer dcol_query(const DcolPair& p, const Pose& X_12) { return p.answer(X_12); }

const Competitor kDcol{"dcol", "DCOL (interior point, exact bodies)",
                       "this project's C++ DCOL (baselines/src/dcol.cpp), pdip_tol 1e-6",
                       Answers{false, false, false, true}, serves_exact_bodies, &Prepared<DcolPair, dcol_query>::make};
}  // namespace

namespace detail {
std::vector<const Competitor*> competitors_dcol() { return {&kDcol}; }
}  // namespace detail

}  // namespace idcol::baselines
