// The random-body generator (random_bodies.hpp).
#include "gen/random_bodies.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "gen/poses.hpp"

namespace idcol::harness {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr const char* kFamilyNames[kNumBodyFamilies] = {"sphere", "superellipsoid", "cylinder", "box", "polytope", "cone"};

/// SplitMix64's finaliser: a bijection of 64-bit words that scatters nearby keys.
std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double sharpness_beta(BodyRange r, BodyDraws& g) {
  static const double normal[] = {5, 20, 100, 1000}, wide[] = {5, 20, 100, 1e4};
  return (r == BodyRange::Wide ? wide : normal)[g.index(4)];
}
double exponent_n(BodyRange r, BodyDraws& g) {
  static const double normal[] = {1, 1.5, 2, 3, 4, 8, 16}, wide[] = {1, 1.5, 2, 3, 4, 32, 64};
  return (r == BodyRange::Wide ? wide : normal)[g.index(7)];
}
double size(BodyRange r, BodyDraws& g) { return r == BodyRange::Wide ? g.log_uniform(-3, 3) : g.log_uniform(-0.5, 0.5); }
double aspect(BodyRange r, BodyDraws& g) { return g.log_uniform(0.0, r == BodyRange::Wide ? 3.0 : 1.0); }
}  // namespace

const char* to_string(BodyFamily f) { return kFamilyNames[static_cast<int>(f)]; }

BodyFamily body_family_from_string(const std::string& s) {
  for (int i = 0; i < kNumBodyFamilies; ++i)
    if (s == kFamilyNames[i]) return static_cast<BodyFamily>(i);
  throw std::invalid_argument("unknown body family \"" + s +
                              "\" (expected sphere, superellipsoid, cylinder, box, polytope or cone)");
}

const char* to_string(BodyRange r) { return r == BodyRange::Wide ? "wide" : "normal"; }

BodyRange body_range_from_string(const std::string& s) {
  if (s == "normal") return BodyRange::Normal;
  if (s == "wide") return BodyRange::Wide;
  throw std::invalid_argument("unknown range \"" + s + "\" (expected \"normal\" or \"wide\")");
}

std::uint64_t BodyDraws::next() {
  state_ += 0x9e3779b97f4a7c15ull;
  return mix(state_);
}
double BodyDraws::uniform(double lo, double hi) { return lo + (hi - lo) * (static_cast<double>(next() >> 11) * 0x1.0p-53); }
double BodyDraws::log_uniform(double lo_exp10, double hi_exp10) { return std::pow(10.0, uniform(lo_exp10, hi_exp10)); }
double BodyDraws::normal() {
  const double u1 = 1.0 - uniform(0.0, 1.0);  // in (0, 1]: log(u1) is finite
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * uniform(0.0, 1.0));
}
int BodyDraws::index(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }

Shape random_body(BodyFamily f, BodyRange range, BodyDraws& g) {
  const bool wide = range == BodyRange::Wide;
  const double s = size(range, g);
  switch (f) {
    case BodyFamily::Sphere: return Sphere(s);
    case BodyFamily::Superellipsoid: {
      const double b = s * aspect(range, g), c = s * aspect(range, g);
      return Superellipsoid(s, b, c, exponent_n(range, g));
    }
    case BodyFamily::Cylinder: {
      const double h = s * aspect(range, g);
      return SuperellipticCylinder(s, h, exponent_n(range, g));
    }
    case BodyFamily::Box: {
      const double h1 = s * aspect(range, g), h2 = s * aspect(range, g);
      const double h[3] = {s, h1, h2};
      const double hmin = std::min({h[0], h[1], h[2]}), hmax = std::max({h[0], h[1], h[2]});
      std::vector<Vec3> A;
      std::vector<double> b;
      for (int i = 0; i < 3; ++i)
        for (int sg = -1; sg <= 1; sg += 2) {
          Vec3 a = Vec3::Zero();
          a[i] = sg;
          A.push_back(a);
          b.push_back(h[i]);
        }
      const double beta = sharpness_beta(range, g);
      if (!wide) return SmoothPolytope(A, b, beta, hmin);
      return SmoothPolytope(A, b, std::min(std::max(beta, 3.0 * hmax * std::log(6.0) / hmin), 1e4), hmax);
    }
    case BodyFamily::Polytope: {
      const double a1 = aspect(range, g), a2 = aspect(range, g);
      const Vec3 ax(s, s * a1, s * a2);
      std::vector<Vec3> V;
      const int m = 6 + g.index(20);
      for (int i = 0; i < m; ++i) {
        const double x = g.normal(), y = g.normal(), z = g.normal();
        V.push_back(Vec3(x, y, z).normalized().cwiseProduct(ax));
      }
      for (int i = 0; i < 3; ++i)
        for (int sg = -1; sg <= 1; sg += 2) {
          Vec3 v = Vec3::Zero();
          v[i] = sg * ax[i];
          V.push_back(v);
        }
      const double beta = sharpness_beta(range, g);
      if (!wide) return SmoothPolytope::from_vertices(V, beta, 0.3 * ax.minCoeff());
      const SmoothPolytope sharp = SmoothPolytope::from_vertices(V, 1e4, ax.maxCoeff());
      double bmin = 1e300;
      for (int i = 0; i < sharp.num_halfspaces(); ++i) bmin = std::min(bmin, sharp.offset(i));
      const double need = 3.0 * ax.maxCoeff() * std::log(static_cast<double>(sharp.num_halfspaces())) / bmin;
      return SmoothPolytope::from_vertices(V, std::min(std::max(beta, need), 1e4), ax.maxCoeff());
    }
    case BodyFamily::Cone:
    default: {
      if (wide) {
        // Nearly pointed (Rt down to Rb / 100), flat as a disc or long as a
        // needle (a / Rb in 10^[-1.5, 3] / 2), the origin anywhere from the
        // middle of the axis to just below the top (b / a in 10^[-1.5, 0]).
        const double Rt = s * g.log_uniform(-2.0, 0.0);
        const double a = 0.5 * s * g.log_uniform(-1.5, 3.0);
        const double b = a * g.log_uniform(-1.5, 0.0);
        return SmoothTruncatedCone(s, Rt, a, b, sharpness_beta(range, g));
      }
      const double Rt = s * g.uniform(0.1, 1.0);
      const double a = 0.5 * s * aspect(range, g);
      const double b = a * g.uniform(0.3, 1.0);
      return SmoothTruncatedCone(s, Rt, a, b, sharpness_beta(range, g));
    }
  }
}

RandomBodyPose random_body_pose(const RandomBodyCase& c, std::uint64_t k) {
  const std::uint64_t pair = static_cast<std::uint64_t>(c.family1) * kNumBodyFamilies + static_cast<std::uint64_t>(c.family2);
  BodyDraws g(mix(mix(mix(c.seed) ^ (pair + 64 * static_cast<std::uint64_t>(c.range))) ^ k));
  Shape b1 = random_body(c.family1, c.range, g);
  Shape b2 = random_body(c.family2, c.range, g);
  const double u1 = g.uniform(0, 1), u2 = g.uniform(0, 1), u3 = g.uniform(0, 1);
  const double u4 = g.uniform(0, 1), u5 = g.uniform(0, 1);
  Pose X;
  X.R = uniform_rotation(u1, u2, u3);
  X.p = uniform_direction(u4, u5) * ((radii(b1).inner + radii(b2).inner) * g.log_uniform(-3, 3));
  Pose X_near = X;
  X_near.p *= 1.01;
  X_near.R = X.R * Eigen::AngleAxisd(0.02, Vec3::UnitZ()).toRotationMatrix();
  return RandomBodyPose{std::move(b1), std::move(b2), X, X_near};
}

}  // namespace idcol::harness
