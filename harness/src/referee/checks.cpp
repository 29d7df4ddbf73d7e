#include "referee/checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "io/text.hpp"

#include "idcol_baselines/core_adapter.hpp"
#include "idcol_baselines/exact_shape.hpp"
#include "idcol_baselines/oracles.hpp"
#include "idcol_baselines/overloaded.hpp"
#include "referee/lp_oracle.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {
// A length of the body from its parameters alone (the surface check's unit).
double independent_size(const baselines::geom::Desc& d) {
  namespace g = baselines::geom;
  return std::visit(baselines::Overloaded{[](const g::SphereDesc& x) { return x.R; },
                                          [](const g::SuperellipsoidDesc& x) { return std::max({x.a, x.b, x.c}); },
                                          [](const g::CylinderDesc& x) { return std::max(x.R, x.h); },
                                          [](const g::PolytopeDesc& x) { return *std::max_element(x.offsets.begin(), x.offsets.end()); },
                                          [](const g::ConeDesc& x) { return std::max({x.Rb, x.Rt, x.a, x.b}); }},
                    d);
}
}  // namespace

json CheckTolerances::to_json() const {
  return {{"surface", surface}, {"normal", normal}, {"closed_form", closed_form},
          {"pw", pw},           {"bracket", bracket}, {"touching", touching}};
}

bool is_sphere(const Shape& s) { return std::holds_alternative<Sphere>(s); }
bool is_exact_ellipsoid(const Shape& s) {
  const auto* se = std::get_if<Superellipsoid>(&s);
  return is_sphere(s) || (se && se->sharpness() == 1.0);
}
bool is_polytope(const Shape& s) { return std::holds_alternative<SmoothPolytope>(s); }

// The baselines' independent description of the pair: geometry for the
// surface checks and the exact bodies of the oracles.
struct AnswerChecker::Independent {
  baselines::geom::Desc d1, d2;
  double size1 = 1.0, size2 = 1.0;
  std::optional<baselines::ExactShape> x1, x2;  // exact ellipsoids or polytopes (PW, LP)
  std::optional<baselines::SupportOracle> support;
  Independent(const Shape& b1, const Shape& b2, OracleChoice oracle)
      : d1(baselines::to_desc(b1)), d2(baselines::to_desc(b2)), size1(independent_size(d1)), size2(independent_size(d2)) {
    const bool exact = (is_exact_ellipsoid(b1) && is_exact_ellipsoid(b2)) || (is_polytope(b1) && is_polytope(b2) && have_polytope_lp());
    if (exact) {
      x1 = baselines::to_exact(b1);
      x2 = baselines::to_exact(b2);
    }
    if (!exact || oracle == OracleChoice::SupportFunction) support.emplace(d1, d2);
  }
};

AnswerChecker::AnswerChecker(const Shape& b1, const Shape& b2, OracleChoice oracle, const SolverOptions& solver,
                             CheckTolerances tol)
    : b1_(b1), b2_(b2), oracle_(oracle == OracleChoice::Auto ? resolve_oracle(b1, b2) : oracle), solver_(solver), tol_(tol),
      ind_(std::make_unique<Independent>(b1, b2, oracle_)) {}
AnswerChecker::~AnswerChecker() = default;

OracleChoice AnswerChecker::resolve_oracle(const Shape& b1, const Shape& b2) {
  if (is_sphere(b1) && is_sphere(b2)) return OracleChoice::ClosedForm;
  if (is_exact_ellipsoid(b1) && is_exact_ellipsoid(b2)) return OracleChoice::PerramWertheim;
  if (is_polytope(b1) && is_polytope(b2) && have_polytope_lp()) return OracleChoice::PolytopeLP;
  return OracleChoice::SupportFunction;
}

TouchReference AnswerChecker::reference(const Pose& X) const {
  TouchReference t;
  if (is_sphere(b1_) && is_sphere(b2_)) {
    t.ok = true;
    t.method = "closed_form";
    t.lo = t.hi = X.p.norm() / (std::get<Sphere>(b1_).R() + std::get<Sphere>(b2_).R());
    return t;
  }
  const Independent& co = *ind_;
  baselines::OracleAnswer a;
  std::array<double, 2> br{};
  if (is_exact_ellipsoid(b1_) && is_exact_ellipsoid(b2_)) {
    a = baselines::perram_wertheim(baselines::ellipsoid_axes(*co.x1), baselines::ellipsoid_axes(*co.x2), X);
    br = {a.alpha_lo, a.alpha_hi};
  } else if (is_polytope(b1_) && is_polytope(b2_) && have_polytope_lp()) {
    a = polytope_lp_answer(std::get<baselines::ExactPolytope>(*co.x1), std::get<baselines::ExactPolytope>(*co.x2), X);
    if (a.ok) br = baselines::smoothing_bracket(*co.x1, *co.x2, a.alpha_lo, a.alpha_hi);
  } else {
    a = baselines::support_function_oracle(*co.support, X);
    br = {a.alpha_lo, a.alpha_hi};
  }
  t.method = baselines::to_string(a.method);
  t.ok = a.ok && std::isfinite(br[0]) && std::isfinite(br[1]);
  t.lo = br[0], t.hi = br[1];
  if (!t.ok) t.error = a.ok ? "the oracle's bracket is unbounded" : a.error;
  return t;
}

Vec3 AnswerChecker::normal(int body, const Vec3& y) const {
  const Vec3 g = baselines::geom::eval(body == 1 ? ind_->d1 : ind_->d2, y).grad;
  return g / g.norm();
}

double AnswerChecker::surface_distance(int body, const Vec3& y) const {
  const baselines::geom::PhiGrad e = baselines::geom::eval(body == 1 ? ind_->d1 : ind_->d2, y);
  const double size = body == 1 ? ind_->size1 : ind_->size2;
  return static_cast<double>(e.phi) / e.grad.norm() / size;
}

namespace {
// The largest |change(y + delta e) | over the six moves of y by delta along
// an axis, times sqrt(3): a displacement along no axis changes a smooth
// measure by up to the sum of the three.
template <class Change>
double spread_over_rounding(const Vec3& y, double delta, Change change) {
  if (!(delta > 0.0) || !std::isfinite(delta)) return 0.0;
  double spread = 0.0;
  for (int j = 0; j < 3; ++j)
    for (const double sgn : {-1.0, 1.0}) {
      const double d = change(Vec3(y + sgn * delta * Vec3::Unit(j)));
      if (std::isfinite(d)) spread = std::max(spread, d);
    }
  return std::sqrt(3.0) * spread;
}
}  // namespace

double AnswerChecker::surface_spread(int body, const Vec3& y, double delta) const {
  const double m0 = surface_distance(body, y);
  return spread_over_rounding(y, delta, [&](const Vec3& yy) { return std::abs(surface_distance(body, yy) - m0); });
}

double AnswerChecker::normal_spread(int body, const Vec3& y, double delta) const {
  const Vec3 n0 = normal(body, y);
  return spread_over_rounding(y, delta, [&](const Vec3& yy) { return (normal(body, yy) - n0).norm(); });
}

AnswerCheck AnswerChecker::check(const Pose& X, const SolveResult& r, bool with_oracle, double expected_alpha,
                                 const TouchReference& touch, const OracleVerdict* known) const {
  AnswerCheck out;
  auto note = [&](const std::string& p) { out.problem += (out.problem.empty() ? "" : "; ") + p; };
  // Witness points on the surfaces, normals opposite.
  const Vec3 y1 = r.x_1 / r.alpha, y2 = X.R.transpose() * (r.x_1 - X.p) / r.alpha;
  const Independent& co = *ind_;
  const baselines::geom::PhiGrad e1 = baselines::geom::eval(co.d1, y1), e2 = baselines::geom::eval(co.d2, y2);
  const double phi1 = static_cast<double>(e1.phi), phi2 = static_cast<double>(e2.phi);
  const double size1 = co.size1, size2 = co.size2;
  const double g1 = e1.grad.norm(), g2 = e2.grad.norm();
  const double d1 = std::abs(phi1) / g1 / size1, d2 = std::abs(phi2) / g2 / size2;
  out.surface = std::isfinite(d1) && std::isfinite(d2) ? std::max(d1, d2) : 1.0;
  const double nerr = (e1.grad / g1 + X.R * e2.grad / g2).norm();
  out.normal = std::isfinite(nerr) ? nerr : 2.0;
  // A witness point in double carries a rounding error of a few ulps of the
  // coordinates it is computed from (x in body 1's frame; x - p and the
  // rotation for body 2), however exact the answer. Where the bodies differ
  // in size by 10^6, that alone moves the small body's witness point off its
  // surface by more than tol_.surface of its size (x - p cancels: x is ~|p|
  // and its rounding is divided by alpha), and, if the small body is sharp,
  // turns its normal by more than tol_.normal. The allowances are the largest
  // change of each measure over that rounding box, measured with the same
  // geometry.
  const double u = 4.0 * std::numeric_limits<double>::epsilon() / r.alpha;
  const double delta1 = u * r.x_1.norm(), delta2 = u * (r.x_1.norm() + X.p.norm());
  out.surface_allowance = std::max(surface_spread(1, y1, delta1), surface_spread(2, y2, delta2));
  out.normal_allowance = normal_spread(1, y1, delta1) + normal_spread(2, y2, delta2);
  if ((out.surface_failed = out.surface > tol_.surface + out.surface_allowance))
    note("witness point off its surface by " + fmt17(out.surface) + " of the outer radius (allowed " + fmt17(tol_.surface) +
         " + rounding " + fmt17(out.surface_allowance) + ")");
  if ((out.normal_failed = out.normal > tol_.normal + out.normal_allowance))
    note("normals not opposite: |n1 + n2| = " + fmt17(out.normal) + " (allowed " + fmt17(tol_.normal) + " + rounding " +
         fmt17(out.normal_allowance) + ")");

  if (std::isfinite(expected_alpha) && touch.ok) {
    // Where the oracle's bracket is tight the constructed 1 + eps is the
    // answer; otherwise (smoothing brackets) alpha must lie in the bracket.
    const double e = touch.hi / touch.lo - 1.0 <= 0.1 * tol_.touching
                         ? std::abs(r.alpha / expected_alpha - 1.0)
                         : std::max({0.0, touch.lo / r.alpha - 1.0, r.alpha / touch.hi - 1.0});
    out.touching_error = e;
    out.alpha_error = std::max(out.alpha_error, e);
    if ((out.touching_failed = e > tol_.touching))
      note("touching pose: alpha " + fmt17(r.alpha) + ", constructed " + fmt17(expected_alpha) + " (" + touch.method +
           " bracket [" + fmt17(touch.lo) + ", " + fmt17(touch.hi) + "])");
  }
  if (!with_oracle || oracle_ == OracleChoice::None) return out;
  const OracleVerdict a = known ? *known : oracle_verdict(X);
  if (!a.ok) {
    out.oracle_failed_to_answer = true;
    return out;
  }
  out.oracle_checked = true;
  out.oracle_alpha = a.alpha;
  if (a.oracle == OracleChoice::ClosedForm || a.oracle == OracleChoice::PerramWertheim) {
    const bool closed = a.oracle == OracleChoice::ClosedForm;
    out.oracle_error = std::abs(r.alpha / a.alpha - 1.0);
    out.alpha_error = std::max(out.alpha_error, out.oracle_error);
    if ((out.oracle_disagrees = out.oracle_error > (closed ? tol_.closed_form : tol_.pw)))
      note(std::string(closed ? "closed form" : "Perram-Wertheim") + " alpha " + fmt17(a.alpha) + ", solver " + fmt17(r.alpha));
    return out;
  }
  const double v = std::max(a.lo / r.alpha - 1.0, std::isfinite(a.hi) ? r.alpha / a.hi - 1.0 : 0.0);
  if (std::isfinite(a.hi)) out.bracket_width = a.hi / a.lo - 1.0;
  out.bracket_violation = std::max(0.0, v);
  if ((out.oracle_disagrees = v > tol_.bracket))
    note("alpha " + fmt17(r.alpha) + " outside the " + a.method + " bracket [" + fmt17(a.lo) + ", " + fmt17(a.hi) + "]");
  return out;
}

OracleVerdict AnswerChecker::oracle_verdict(const Pose& X) const {
  OracleVerdict v;
  v.oracle = oracle_;
  if (oracle_ == OracleChoice::None) return v;
  if (oracle_ == OracleChoice::ClosedForm) {
    v.ok = true;
    v.method = "closed_form";
    v.alpha = v.lo = v.hi = X.p.norm() / (std::get<Sphere>(b1_).radii().outer + std::get<Sphere>(b2_).radii().outer);
    return v;
  }
  const Independent& co = *ind_;
  baselines::OracleAnswer a;
  if (oracle_ == OracleChoice::SupportFunction)
    a = baselines::support_function_oracle(*co.support, X);
  else if (oracle_ == OracleChoice::PerramWertheim)
    a = baselines::perram_wertheim(baselines::ellipsoid_axes(*co.x1), baselines::ellipsoid_axes(*co.x2), X);
  else
    a = polytope_lp_answer(std::get<baselines::ExactPolytope>(*co.x1), std::get<baselines::ExactPolytope>(*co.x2), X);
  if (!a.ok || !std::isfinite(a.alpha)) return v;
  v.ok = true;
  v.alpha = a.alpha;
  v.method = baselines::to_string(a.method);
  // LP: the smoothing bracket of the exact alpha*; support function: its own
  // bracket (of alpha* itself, or the smoothing bracket between exact inner
  // and outer bodies for polytopes and cones).
  if (oracle_ == OracleChoice::PerramWertheim) {
    v.lo = v.hi = a.alpha;
  } else if (oracle_ == OracleChoice::SupportFunction) {
    v.lo = a.alpha_lo, v.hi = a.alpha_hi;
  } else {
    const std::array<double, 2> br = baselines::smoothing_bracket(*co.x1, *co.x2, a.alpha);
    v.lo = br[0], v.hi = br[1];
  }
  return v;
}

}  // namespace idcol::harness
