#include "idcol/families.hpp"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <optional>
#include <string>
#include <utility>

namespace idcol {
namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

/// A length: finite and > 0, required.
FamilyParam length(const char* key, const char* meaning, double example) {
  return {key, meaning, 0.0, true, kNone, 1, example, false};
}
/// A superquadric's exponent: n >= 1, 1 where omitted (an exact ellipsoid or cylinder).
FamilyParam exponent(double example) {
  return {"n", "exponent (dimensionless), >= 1; 1 where omitted", 1.0, false, 1.0, 0, example, false};
}
/// A LogSumExp sharpness: > 0 (a family may ask more of it), required.
FamilyParam sharpness(const char* meaning, double example) { return {"beta", meaning, 0.0, true, kNone, 0, example, false}; }
FamilyParam array(const char* key, const char* meaning) { return {key, meaning, 0.0, false, kNone, 0, 0.0, true}; }

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

}  // namespace

std::vector<const FamilyParam*> FamilyInfo::scalars() const {
  std::vector<const FamilyParam*> out;
  for (const FamilyParam& p : params)
    if (!p.array) out.push_back(&p);
  return out;
}

// Long: the table itself, one entry a family.
const std::vector<FamilyInfo>& shape_families() {
  static const std::vector<FamilyInfo> families = {
      {Sphere::kName, "Sphere", "a ball: phi(y) = |y|/R - 1", "", "centred at the frame origin",
       {length("R", "radius (length units), > 0", 1.0)}},
      {Superellipsoid::kName, "Superellipsoid",
       "phi(y) = (|y1/a|^2n + |y2/b|^2n + |y3/c|^2n)^(1/2n) - 1; n = 1 is an exact ellipsoid",
       "the box of half-extents a, b, c as n -> infinity", "semi-axes a, b, c along y1, y2, y3 (the frame's x, y, z)",
       {length("a", "semi-axis along y1, the frame's x (length units), > 0", 0.5),
        length("b", "semi-axis along y2, the frame's y (length units), > 0", 1.0),
        length("c", "semi-axis along y3, the frame's z (length units), > 0", 1.5), exponent(8.0)}},
      {SuperellipticCylinder::kName, "SuperellipticCylinder",
       "a cylinder of circular section whose caps are rounded by the exponent n: "
       "phi(y) = ((y1/h)^2n + ((y2^2 + y3^2)/R^2)^n)^(1/2n) - 1",
       "the exact cylinder of radius R and half-length h as n -> infinity", "axis along y1 (the frame's x), centred at the origin",
       {length("R", "radius of the circular section (length units), > 0", 1.0),
        length("h", "half-length along the axis y1 (length units), > 0", 2.0), exponent(8.0)}},
      {SmoothPolytope::kName, "SmoothPolytope",
       "phi(y) = smax_beta((a_i.y - b_i) / L), the LogSumExp smooth maximum over the half-spaces a_i.y <= b_i "
       "(rows normalised at construction); give normals and offsets, or vertices (their convex hull)",
       "the exact polytope {a_i.y <= b_i} as beta -> infinity; the smooth body lies inside it",
       "as its normals or vertices give it; the frame origin strictly inside",
       {array("normals", "[[ax, ay, az], ...], the outward normals a_i (normalised), or"),
        array("offsets", "[b_0, ...], one per normal, length units (> 0: the origin inside)"),
        array("vertices", "[[x, y, z], ...], length units, instead of normals and offsets"),
        sharpness("sharpness (dimensionless), > 0 (up to 1e4 h/L)", 20.0),
        {"L", "length scale of the smoothing (length units), > 0; 1 where omitted", 0.0, true, 1.0, 1, 1.0, false}}},
      {SmoothTruncatedCone::kName, "SmoothTruncatedCone",
       "a truncated cone with smoothed rim: phi = smax_beta(r^2/R(y1)^2 - 1, -y1/a - 1, y1/b - 1), the LogSumExp of "
       "its side and caps",
       "the exact frustum as beta -> infinity",
       "axis along y1 (the frame's x): base (radius Rb) at y1 = -a, top (radius Rt) at y1 = b",
       {length("Rb", "base radius (length units), > 0", 1.0), length("Rt", "top radius (length units), > 0", 1.5),
        length("a", "length of the axis below the origin (length units), > 0", 1.5),
        length("b", "length of the axis above the origin (length units), > 0", 1.5),
        sharpness("sharpness (dimensionless), > log 3", 20.0)}},
  };
  return families;
}

const FamilyInfo& family_info(const Shape& s) { return shape_families()[s.index()]; }

namespace {
/// Alternative I of Shape from theta, where I is index and a scalar family.
template <std::size_t I>
bool make_if(std::size_t index, const double* theta, std::optional<Shape>& out) {
  using T = std::variant_alternative_t<I, Shape>;
  if constexpr (kScalarFamily<T>) {
    if (index == I) out.emplace(FamilyParams<T>::make(theta));
  }
  return out.has_value();
}
template <std::size_t... I>
std::optional<Shape> scalar_shape_of(std::size_t index, const double* theta, std::index_sequence<I...>) {
  std::optional<Shape> out;
  (make_if<I>(index, theta, out) || ...);
  return out;
}
}  // namespace

Shape scalar_family_shape(const FamilyInfo& f, const double* theta) {
  const auto& all = shape_families();
  std::optional<Shape> s =
      scalar_shape_of(static_cast<std::size_t>(&f - all.data()), theta, std::make_index_sequence<std::variant_size_v<Shape>>{});
  if (!s) throw std::invalid_argument(std::string(f.name) + ": its inputs are arrays, not scalar parameters");
  return *std::move(s);
}

void check_param(const char* family, const FamilyParam& p, double v) {
  const bool in = p.lower_open ? v > p.lower : v >= p.lower;
  if (!std::isfinite(v) || !in)
    throw std::invalid_argument(std::string(family) + ": field '" + p.key + "' must be finite and " + (p.lower_open ? "> " : ">= ") +
                                num(p.lower) + ", got " + num(v));
  if (p.lower_open && p.lower == 0.0 && !std::isnormal(v))
    throw std::invalid_argument(std::string(family) + ": field '" + p.key + "' = " + num(v) +
                                " is subnormal; it must be at least " + num(std::numeric_limits<double>::min()) +
                                ", the smallest normal double");
}

}  // namespace idcol
