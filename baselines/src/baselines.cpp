#include "idcol_baselines/baselines.hpp"

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
    case PairKind::PolyEllip: return OracleMethod::Bisection;
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
}  // namespace

BaselinePair::BaselinePair(const Shape& body1, const Shape& body2, FclOptions fcl, CcdOptions ccd)
    : kind_(checked_kind(body1, body2)),
      name_(describe_pair(body1, body2)),
      e1_(to_exact(body1)),
      e2_(to_exact(body2)),
      fcl_(e1_, e2_, fcl),
      ccd_(e1_, e2_, ccd) {}

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
    case PairKind::PolyEllip: {
      if (X_12.p.squaredNorm() == 0.0) {
        OracleAnswer o;
        o.method = OracleMethod::Bisection;
        o.ok = true;
        return o;
      }
      const auto b = alpha_bounds(e1_, e2_, X_12.p);
      return bisect_alpha([&](const Vec3& rs) { return fcl_.intersects(Pose{X_12.R, rs}); }, X_12.p, b[0], b[1]);
    }
    case PairKind::Unsupported: break;
  }
  OracleAnswer o;
  o.error = "no oracle for the pair " + name_;
  return o;
}

}  // namespace idcol::baselines
