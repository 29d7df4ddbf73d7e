#include "gen/poses.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace idcol::harness {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;

Mat3 rotation_from_wxyz(double w, double x, double y, double z) {
  Eigen::Quaterniond q(w, x, y, z);
  const double n = q.norm();
  if (!(n > 0.0)) return Mat3::Identity();  // all four terms vanish together: never on a finite sweep
  q.coeffs() /= n;
  return q.toRotationMatrix();
}
}  // namespace

const char* to_string(GeneratorKind g) { return g == GeneratorKind::Paper ? "paper" : "uniform"; }

GeneratorKind generator_from_string(const std::string& s) {
  if (s == "paper") return GeneratorKind::Paper;
  if (s == "uniform") return GeneratorKind::Uniform;
  throw std::invalid_argument("unknown generator \"" + s + "\" (expected \"paper\" or \"uniform\")");
}

RadialRange radial_range(const Shape& body1, const Shape& body2) {
  const Radii r1 = radii(body1), r2 = radii(body2);
  return {0.1 * std::min(r1.inner, r2.inner), 2.0 * std::max(r1.outer, r2.outer)};
}

double PoseGenerator::radius(double u) const {
  const double rmin3 = range_.rmin * range_.rmin * range_.rmin;
  const double rmax3 = range_.rmax * range_.rmax * range_.rmax;
  return std::cbrt(rmin3 + (rmax3 - rmin3) * u);
}

Pose PoseGenerator::paper(std::uint64_t k) const {
  const double t = static_cast<double>(k) * dt_;
  const double th = 0.5 * kPi * std::sin(kTwoPi * std::sqrt(3.0) * t);
  const double ph = kTwoPi * std::sqrt(5.0) * t;
  Pose X;
  X.p = radius(0.5 * (1.0 + std::sin(kTwoPi * std::sqrt(2.0) * t))) *
        Vec3(std::cos(th) * std::cos(ph), std::cos(th) * std::sin(ph), std::sin(th));
  X.R = rotation_from_wxyz(std::sin(kTwoPi * std::sqrt(7.0) * t), std::cos(kTwoPi * std::sqrt(11.0) * t),
                           std::sin(kTwoPi * std::sqrt(13.0) * t), std::cos(kTwoPi * std::sqrt(17.0) * t));
  return X;
}

double radical_inverse(std::uint64_t n, unsigned base) {
  const double inv = 1.0 / base;
  double f = inv, r = 0.0;
  while (n > 0) {
    r += f * static_cast<double>(n % base);
    n /= base;
    f *= inv;
  }
  return r;
}

std::array<double, 6> halton6(std::uint64_t k) {
  const std::uint64_t n = k + 1;  // index 0 of every Halton base is the corner 0
  return {radical_inverse(n, 2), radical_inverse(n, 3), radical_inverse(n, 5),
          radical_inverse(n, 7), radical_inverse(n, 11), radical_inverse(n, 13)};
}

Mat3 uniform_rotation(double u1, double u2, double u3) {
  const double s1 = std::sqrt(1.0 - u1), s2 = std::sqrt(u1);
  return rotation_from_wxyz(s2 * std::cos(kTwoPi * u3), s1 * std::sin(kTwoPi * u2), s1 * std::cos(kTwoPi * u2),
                            s2 * std::sin(kTwoPi * u3));
}

Vec3 uniform_direction(double u4, double u5) {
  const double z = 1.0 - 2.0 * u4, rho = std::sqrt(std::max(0.0, 1.0 - z * z)), az = kTwoPi * u5;
  return Vec3(rho * std::cos(az), rho * std::sin(az), z);
}

Pose PoseGenerator::uniform(std::uint64_t k) const {
  const auto [u1, u2, u3, u4, u5, u6] = halton6(k);
  Pose X;
  X.R = uniform_rotation(u1, u2, u3);
  X.p = radius(u6) * uniform_direction(u4, u5);
  return X;
}

std::vector<Vec3> fibonacci_sphere(int m) {
  std::vector<Vec3> v;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < m; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / m;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    v.emplace_back(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
  }
  return v;
}

Pose shell_pose(std::uint64_t k, double L, double rmin, double rmax, std::uint64_t zero_every) {
  const auto [u1, u2, u3, u4, u5, u6] = halton6(k);
  Pose X;
  X.R = uniform_rotation(u1, u2, u3);
  if (zero_every && k % zero_every == 0) return X;  // r = 0 exactly: concentric
  const double lo = std::log10(rmin), hi = std::log10(rmax);
  X.p = L * std::pow(10.0, lo + (hi - lo) * u6) * uniform_direction(u4, u5);
  return X;
}

Pose touching_pose(std::uint64_t k, TouchOrientation o, double L) {
  const auto [u1, u2, u3, u4, u5, u6] = halton6(k);
  (void)u6;
  Pose X;
  Vec3 d = uniform_direction(u4, u5);
  switch (o) {
    case TouchOrientation::Uniform: X.R = uniform_rotation(u1, u2, u3); break;
    case TouchOrientation::Face:
      X.R = Eigen::AngleAxisd(kTwoPi * u2, Vec3::UnitZ()).toRotationMatrix();
      d = Vec3(0.3 * (u4 - 0.5), 0.3 * (u5 - 0.5), 1.0).normalized();
      break;
    case TouchOrientation::Edge: {
      const Vec3 e = Vec3(0.0, 1.0, 1.0).normalized();
      X.R = Eigen::AngleAxisd(0.5 * kPi + 0.2 * (u2 - 0.5), e).toRotationMatrix();
      d = Vec3(0.2 * (u4 - 0.5), 1.0, 1.0).normalized();
      break;
    }
    case TouchOrientation::Vertex: {
      const Mat3 Q = Eigen::Quaterniond::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitZ()).toRotationMatrix();
      X.R = Eigen::AngleAxisd(kTwoPi * u2, Vec3::UnitZ()).toRotationMatrix() * Q;
      d = Vec3(0.2 * (u4 - 0.5), 0.2 * (u5 - 0.5), 1.0).normalized();
      break;
    }
  }
  X.p = L * d;
  return X;
}

}  // namespace idcol::harness
