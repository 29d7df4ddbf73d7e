#include "idcol_baselines/baselines.hpp"

#include <limits>
#include <stdexcept>

namespace idcol::baselines {

const char* to_string(Baseline b) {
  switch (b) {
    case Baseline::FclCollide: return "fcl_collide";
    case Baseline::FclDistance: return "fcl_distance";
    case Baseline::CcdGjk: return "ccd_gjk";
    case Baseline::CcdMpr: return "ccd_mpr";
    case Baseline::CcdMprPenetration: return "ccd_mpr_penetration";
    case Baseline::CcdEpa: return "ccd_epa_unreliable";
  }
  return "unknown";
}

const std::vector<Baseline>& all_baselines() {
  static const std::vector<Baseline> all = {Baseline::FclCollide, Baseline::FclDistance,       Baseline::CcdGjk,
                                            Baseline::CcdMpr,     Baseline::CcdMprPenetration, Baseline::CcdEpa};
  return all;
}

bool can_serve(Baseline b, const Shape& body1, const Shape& body2, std::string* why) {
  std::string w1, w2;
  const bool r1 = representable(body1, &w1), r2 = representable(body2, &w2);
  if (r1 && r2) return true;
  if (why)
    *why = std::string(to_string(b)) + " cannot serve the pair " + describe_pair(body1, body2) + ": " +
           (r1 ? "" : "body 1: " + w1 + (r2 ? "" : "; ")) + (r2 ? "" : "body 2: " + w2);
  return false;
}

std::vector<Baseline> baselines_for(const Shape& body1, const Shape& body2) {
  std::vector<Baseline> out;
  for (Baseline b : all_baselines())
    if (can_serve(b, body1, body2)) out.push_back(b);
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
  if (!can_serve(Baseline::FclCollide, body1, body2, &why))
    throw std::invalid_argument("BaselinePair: no baseline serves the pair " + describe_pair(body1, body2) + " (" +
                                why + ")");
  return classify(body1, body2);
}

// The exact body as an independent description (a polytope at beta = inf
// has no LogSumExp gap: its outer and inner bodies are both P).
geom::Desc exact_desc(const ExactShape& s) {
  if (const auto* e = std::get_if<ExactEllipsoid>(&s)) {
    if (e->is_sphere) return geom::make_sphere(e->axes[0]);
    return geom::make_superellipsoid(e->axes[0], e->axes[1], e->axes[2], 1.0);
  }
  const auto& p = std::get<ExactPolytope>(s);
  return geom::PolytopeDesc{p.normals, p.offsets, std::numeric_limits<double>::infinity(), 1.0};
}
}  // namespace

BaselinePair::BaselinePair(const Shape& body1, const Shape& body2, FclOptions fcl, CcdOptions ccd)
    : kind_(checked_kind(body1, body2)),
      name_(describe_pair(body1, body2)),
      e1_(to_exact(body1)),
      e2_(to_exact(body2)),
      fcl_(e1_, e2_, fcl),
      ccd_(e1_, e2_, ccd),
      support_(exact_desc(e1_), exact_desc(e2_)) {}

BaselineAnswer BaselinePair::run(Baseline b, const Pose& X_12) const {
  switch (b) {
    case Baseline::FclCollide: return fcl_.collide(X_12, true);
    case Baseline::FclDistance: return fcl_.distance(X_12);
    case Baseline::CcdGjk: return ccd_.gjk(X_12);
    case Baseline::CcdMpr: return ccd_.mpr(X_12);
    case Baseline::CcdMprPenetration: return ccd_.mpr_penetration(X_12);
    case Baseline::CcdEpa: return ccd_.epa_penetration(X_12);
  }
  throw std::invalid_argument("BaselinePair::run: unknown baseline id " + std::to_string(static_cast<int>(b)) +
                              " for the pair " + name_);
}

std::vector<BaselineAnswer> BaselinePair::run_all(const Pose& X_12) const {
  std::vector<BaselineAnswer> out;
  for (Baseline b : all_baselines()) out.push_back(run(b, X_12));
  return out;
}

OracleAnswer BaselinePair::oracle(const Pose& X_12) const {
  switch (kind_) {
    case PairKind::EllipEllip:
      return perram_wertheim(std::get<ExactEllipsoid>(e1_).axes, std::get<ExactEllipsoid>(e2_).axes, X_12);
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
