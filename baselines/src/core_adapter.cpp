// core -> independent geometry (see core_adapter.hpp). Public parameters only.
#include "idcol_baselines/core_adapter.hpp"

#include <stdexcept>

#include "idcol_baselines/overloaded.hpp"

namespace idcol::baselines {

geom::Desc to_desc(const Shape& s) {
  return std::visit(Overloaded{[](const Sphere& sp) -> geom::Desc { return geom::make_sphere(sp.R()); },
                               [](const Superellipsoid& se) -> geom::Desc { return geom::make_superellipsoid(se.a(), se.b(), se.c(), se.n()); },
                               [](const SuperellipticCylinder& cy) -> geom::Desc { return geom::make_cylinder(cy.R(), cy.h(), cy.n()); },
                               [](const SmoothPolytope& p) -> geom::Desc {
                                 std::vector<geom::Vec> A;
                                 std::vector<double> b;
                                 for (int i = 0; i < p.num_halfspaces(); ++i) {
                                   A.push_back(p.normal(i));
                                   b.push_back(p.offset(i));
                                 }
                                 return geom::make_polytope(A, b, p.beta(), p.L());
                               },
                               [](const SmoothTruncatedCone& c) -> geom::Desc { return geom::make_cone(c.Rb(), c.Rt(), c.a(), c.b(), c.beta()); }},
                    s);
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
  if (const auto* sp = std::get_if<Sphere>(&s)) return geom::make_sphere(sp->R());
  if (const auto* se = std::get_if<Superellipsoid>(&s)) return geom::make_superellipsoid(se->a(), se->b(), se->c(), 1.0);
  return exact_polytope_of(std::get<geom::PolytopeDesc>(to_desc(s)));
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

}  // namespace idcol::baselines
