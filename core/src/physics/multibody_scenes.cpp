#include "idcol/multibody_scenes.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace idcol {

namespace {

/// The paper's sharpness for the LogSumExp families (Table 1: beta = 20)
/// and for the superquadrics (n = 8).
constexpr double kBeta = 20.0;
constexpr double kN = 8.0;

SmoothPolytope box(double hx, double hy, double hz, double s) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.emplace_back(s * ((i & 1) ? hx : -hx), s * ((i & 2) ? hy : -hy), s * ((i & 4) ? hz : -hz));
  return SmoothPolytope::from_vertices(v, kBeta, s);
}

/// The ten kinds, each scaled by s (every length; the polytopes' length
/// L with them, so that each is the same shape at every s).
std::vector<std::pair<std::string, Shape>> ten_kinds(double s) {
  std::vector<std::pair<std::string, Shape>> k;
  // Cone: a truncated cone whose top radius is a tenth of its base's; the
  // frame origin a third of the way up.
  k.emplace_back("cone", SmoothTruncatedCone(0.7 * s, 0.07 * s, 0.4 * s, 0.8 * s, kBeta));
  k.emplace_back("cube", box(0.5, 0.5, 0.5, s));
  k.emplace_back("cuboid", box(0.8, 0.45, 0.3, s));
  k.emplace_back("cylinder", SuperellipticCylinder(0.45 * s, 0.6 * s, kN));
  k.emplace_back("ellipsoid", Superellipsoid(0.8 * s, 0.5 * s, 0.4 * s, 1.0));
  k.emplace_back("frustum", SmoothTruncatedCone(0.7 * s, 0.4 * s, 0.5 * s, 0.5 * s, kBeta));
  {  // An irregular polytope: the hull of twelve seeded points on an ellipsoid.
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<Vec3> v;
    for (int i = 0; i < 12; ++i) {
      const Vec3 u = Vec3(g(rng), g(rng), g(rng)).normalized();
      v.push_back(s * Vec3(0.75 * u.x(), 0.6 * u.y(), 0.5 * u.z()));
    }
    k.emplace_back("polytope", SmoothPolytope::from_vertices(v, kBeta, s));
  }
  {  // Square pyramid: base 1.1 x 1.1, height 1; the frame origin at its centroid.
    std::vector<Vec3> v = {{-0.55, -0.55, -0.25}, {0.55, -0.55, -0.25}, {-0.55, 0.55, -0.25},
                           {0.55, 0.55, -0.25},   {0.0, 0.0, 0.75}};
    for (Vec3& p : v) p *= s;
    k.emplace_back("pyramid", SmoothPolytope::from_vertices(v, kBeta, s));
  }
  k.emplace_back("sphere", Sphere(0.5 * s));
  {  // Regular tetrahedron of edge 1.4 about its centroid.
    const double e = 1.4 / (2.0 * std::sqrt(2.0));
    std::vector<Vec3> v = {{e, e, e}, {e, -e, -e}, {-e, e, -e}, {-e, -e, e}};
    for (Vec3& p : v) p *= s;
    k.emplace_back("tetrahedron", SmoothPolytope::from_vertices(v, kBeta, s));
  }
  return k;
}

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q.toRotationMatrix();
}

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

}  // namespace

BodyScene paper_ten_bodies(unsigned seed, double radius, double speed, int mass_cells) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("paper_ten_bodies: radius must be finite and > 0, got " + std::to_string(radius));
  if (!(speed >= 0.0) || !std::isfinite(speed))
    throw std::invalid_argument("paper_ten_bodies: speed must be finite and >= 0, got " + std::to_string(speed));
  BodyScene sc;
  for (auto& [name, shape] : ten_kinds(1.0)) {
    sc.names.push_back(name);
    sc.masses.push_back(mass_properties(shape, 1.0, mass_cells));
    sc.shapes.push_back(std::move(shape));
  }
  std::mt19937_64 rng(seed);
  const std::size_t n = sc.shapes.size();
  std::vector<Vec3> dir(n);
  for (int attempt = 0;; ++attempt) {
    if (attempt == 10000)
      throw std::invalid_argument("paper_ten_bodies: no placement without overlap on a sphere of radius " +
                                  std::to_string(radius));
    for (Vec3& d : dir) d = random_unit(rng);
    bool apart = true;
    for (std::size_t i = 0; i < n && apart; ++i)
      for (std::size_t j = i + 1; j < n && apart; ++j)
        apart = (radius * (dir[i] - dir[j])).norm() > radii(sc.shapes[i]).outer + radii(sc.shapes[j]).outer + 0.5;
    if (apart) break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Pose X{random_rotation(rng), radius * dir[i]};
    sc.X_W.push_back(X);
    Vec6 eta = Vec6::Zero();
    eta.tail<3>() = X.R.transpose() * (-speed * dir[i]);  // toward the origin, in body coordinates
    sc.eta.push_back(eta);
  }
  return sc;
}

BodyScene box_of_bodies(int n, unsigned seed, double scale, double jitter, double speed) {
  if (n < 1) throw std::invalid_argument("box_of_bodies: n must be >= 1, got " + std::to_string(n));
  if (!(scale > 0.0) || !std::isfinite(scale))
    throw std::invalid_argument("box_of_bodies: scale must be finite and > 0, got " + std::to_string(scale));
  if (!(jitter >= 0.0) || !std::isfinite(jitter))
    throw std::invalid_argument("box_of_bodies: jitter must be finite and >= 0, got " + std::to_string(jitter));
  const auto kinds = ten_kinds(scale);
  std::vector<MassProperties> kind_mass;
  for (const auto& k : kinds) kind_mass.push_back(mass_properties(k.second));
  const int m = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n)) - 1e-9));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  BodyScene sc;
  for (int b = 0; b < n; ++b) {
    const std::size_t kind = static_cast<std::size_t>(b) % kinds.size();
    sc.names.push_back(kinds[kind].first);
    sc.shapes.push_back(kinds[kind].second);
    sc.masses.push_back(kind_mass[kind]);
    const Vec3 cell(b % m, (b / m) % m, b / (m * m));
    const Pose X{random_rotation(rng), cell + Vec3(u(rng), u(rng), u(rng))};
    sc.X_W.push_back(X);
    Vec6 eta = Vec6::Zero();
    eta.tail<3>() = speed * random_unit(rng);
    sc.eta.push_back(eta);
  }
  return sc;
}

}  // namespace idcol
