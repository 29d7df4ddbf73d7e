#include "idcol_baselines/exact_shape.hpp"

#include <algorithm>
#include <stdexcept>

#include "idcol/convex_hull.hpp"

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

bool representable(const Shape& s, std::string* why) {
  if (std::holds_alternative<Sphere>(s) || std::holds_alternative<SmoothPolytope>(s)) return true;
  if (const auto* se = std::get_if<Superellipsoid>(&s)) {
    if (se->n() == 1.0) return true;
    if (why) *why = "superellipsoid with n = " + std::to_string(se->n()) + " != 1 has no exact FCL/libccd counterpart";
    return false;
  }
  if (why) *why = std::string(family_name(s)) + " has no exact FCL/libccd counterpart";
  return false;
}

ExactShape to_exact(const Shape& s) {
  std::string why;
  if (!representable(s, &why)) throw std::invalid_argument("baselines: cannot represent " + describe(s) + ": " + why);
  if (const auto* sp = std::get_if<Sphere>(&s)) return ExactEllipsoid{Vec3::Constant(sp->R()), true};
  if (const auto* se = std::get_if<Superellipsoid>(&s)) return ExactEllipsoid{Vec3(se->a(), se->b(), se->c()), false};
  const auto& P = std::get<SmoothPolytope>(s);
  ExactPolytope out;
  for (int i = 0; i < P.num_halfspaces(); ++i) {
    out.normals.push_back(P.normal(i));
    out.offsets.push_back(P.offset(i));
  }
  out.vertices = P.vertices();
  const ConvexHull hull = convex_hull(out.vertices, "baselines: exact polytope vertices");
  for (const HullFace& f : hull.faces) out.faces.push_back(f.vertices);
  out.beta = P.beta();
  out.L = P.L();
  return out;
}

PairKind classify(const Shape& body1, const Shape& body2) {
  if (!representable(body1) || !representable(body2)) return PairKind::Unsupported;
  const bool p1 = std::holds_alternative<SmoothPolytope>(body1);
  const bool p2 = std::holds_alternative<SmoothPolytope>(body2);
  if (p1 && p2) return PairKind::PolyPoly;
  if (p1) return PairKind::PolyEllip;
  if (p2) return PairKind::EllipPoly;
  return PairKind::EllipEllip;
}

std::string describe_pair(const Shape& body1, const Shape& body2) { return describe(body1) + " x " + describe(body2); }

namespace {
std::array<double, 2> radii_of(const ExactShape& s) {
  if (const auto* e = std::get_if<ExactEllipsoid>(&s)) return {e->axes.minCoeff(), e->axes.maxCoeff()};
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
