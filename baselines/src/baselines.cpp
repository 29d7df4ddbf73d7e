#include "idcol_baselines/baselines.hpp"

#include <limits>
#include <stdexcept>

namespace idcol::baselines {

bool can_serve(const Competitor& c, const Shape& body1, const Shape& body2, std::string* why) {
  if (c.serves(body1, body2, why)) return true;
  if (why) *why = std::string(c.name) + " cannot serve " + *why;
  return false;
}

std::vector<const Competitor*> competitors_for(const Shape& body1, const Shape& body2) {
  std::vector<const Competitor*> out;
  for (const Competitor* c : baselines::competitors())
    if (c->serves(body1, body2, nullptr)) out.push_back(c);
  return out;
}

OracleMethod oracle_for(const Shape& body1, const Shape& body2) {
  switch (classify(body1, body2)) {
    case PairKind::EllipEllip: return OracleMethod::PerramWertheim;
    case PairKind::PolyPoly: return OracleMethod::PolytopeLP;
    case PairKind::EllipPoly:
    case PairKind::PolyEllip: return OracleMethod::SupportFunction;
    case PairKind::Unsupported: return OracleMethod::None;
  }
  return OracleMethod::None;
}

namespace {
PairKind checked_kind(const Shape& body1, const Shape& body2) {
  std::string why;
  if (!serves_exact_bodies(body1, body2, &why))
    throw std::invalid_argument("BaselinePair: no exact counterpart for " + why);
  return classify(body1, body2);
}

// The exact body as an independent description (a polytope at beta = inf
// has no LogSumExp gap: its outer and inner bodies are both P).
geom::Desc exact_desc(const ExactShape& s) {
  if (const auto* sp = std::get_if<geom::SphereDesc>(&s)) return *sp;
  if (const auto* e = std::get_if<geom::SuperellipsoidDesc>(&s)) return *e;
  const auto& p = std::get<ExactPolytope>(s);
  return geom::PolytopeDesc{p.normals, p.offsets, std::numeric_limits<double>::infinity(), 1.0};
}
}  // namespace

OracleAnswer exact_oracle(const ExactShape& e1, const ExactShape& e2, const Pose& X_12) {
  if (is_ellipsoid(e1) && is_ellipsoid(e2)) return perram_wertheim(ellipsoid_axes(e1), ellipsoid_axes(e2), X_12);
  if (!is_ellipsoid(e1) && !is_ellipsoid(e2)) return polytope_lp(std::get<ExactPolytope>(e1), std::get<ExactPolytope>(e2), X_12);
  return support_function_oracle(SupportOracle(exact_desc(e1), exact_desc(e2)), X_12);
}

BaselinePair::BaselinePair(const Shape& body1, const Shape& body2)
    : kind_(checked_kind(body1, body2)),
      name_(describe_pair(body1, body2)),
      e1_(to_exact(body1)),
      e2_(to_exact(body2)),
      support_(exact_desc(e1_), exact_desc(e2_)) {
  for (const Competitor* c : competitors_for(body1, body2)) prepared_.emplace_back(c, c->prepare(e1_, e2_));
}

std::vector<const Competitor*> BaselinePair::competitors() const {
  std::vector<const Competitor*> out;
  for (const auto& [c, p] : prepared_) out.push_back(c);
  return out;
}

const PreparedPair& BaselinePair::prepared(const Competitor& c) const {
  for (const auto& [pc, p] : prepared_)
    if (pc == &c) return *p;
  throw std::invalid_argument(std::string("BaselinePair: ") + c.name + " does not serve the pair " + name_);
}

OracleAnswer BaselinePair::oracle(const Pose& X_12) const {
  switch (kind_) {
    case PairKind::EllipEllip:
      return perram_wertheim(ellipsoid_axes(e1_), ellipsoid_axes(e2_), X_12);
    case PairKind::PolyPoly: return polytope_lp(std::get<ExactPolytope>(e1_), std::get<ExactPolytope>(e2_), X_12);
    case PairKind::EllipPoly:
    case PairKind::PolyEllip: return support_function_oracle(support_, X_12);
    case PairKind::Unsupported: break;
  }
  OracleAnswer o;
  o.error = "no oracle for the pair " + name_;
  return o;
}

}  // namespace idcol::baselines
