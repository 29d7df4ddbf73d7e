#include "idcol_baselines/exact_shape.hpp"

#include <algorithm>
#include <stdexcept>

namespace idcol::baselines {

const char* to_string(PairKind k) {
  switch (k) {
    case PairKind::EllipEllip: return "Ellip-Ellip";
    case PairKind::EllipPoly: return "Ellip-Poly";
    case PairKind::PolyEllip: return "Poly-Ellip";
    case PairKind::PolyPoly: return "Poly-Poly";
    case PairKind::Unsupported: return "unsupported";
  }
  return "unknown";
}

bool is_ellipsoid(const ExactShape& s) { return !std::holds_alternative<ExactPolytope>(s); }

Vec3 ellipsoid_axes(const ExactShape& s) {
  if (const auto* sp = std::get_if<geom::SphereDesc>(&s)) return Vec3::Constant(sp->R);
  if (const auto* e = std::get_if<geom::SuperellipsoidDesc>(&s)) return Vec3(e->a, e->b, e->c);
  throw std::invalid_argument("ellipsoid_axes: an exact polytope has no axes");
}

ExactPolytope exact_polytope_of(const geom::PolytopeDesc& p) {
  ExactPolytope out;
  static_cast<geom::PolyBody&>(out) = geom::exact_polytope(p.normals, p.offsets);
  out.beta = p.beta;
  out.L = p.L;
  return out;
}

namespace {
std::array<double, 2> radii_of(const ExactShape& s) {
  if (is_ellipsoid(s)) {
    const Vec3 axes = ellipsoid_axes(s);
    return {axes.minCoeff(), axes.maxCoeff()};
  }
  const auto& p = std::get<ExactPolytope>(s);
  double rin = *std::min_element(p.offsets.begin(), p.offsets.end()), rout = 0.0;
  for (const Vec3& v : p.vertices) rout = std::max(rout, v.norm());
  return {rin, rout};
}
}  // namespace

std::array<double, 2> alpha_bounds(const ExactShape& s1, const ExactShape& s2, const Vec3& r) {
  const auto a = radii_of(s1), b = radii_of(s2);
  const double n = r.norm();
  return {n / (a[1] + b[1]), n / (a[0] + b[0])};
}

}  // namespace idcol::baselines
