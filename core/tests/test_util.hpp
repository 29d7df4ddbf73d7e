// Shared fixtures for the core tests: a catalogue of shapes of every family
// and seeded random poses, and solver options. Nothing here calls the solver.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/options.hpp"
#include "idcol/shapes.hpp"

namespace idcol::test {

inline std::vector<Vec3> octa_normals() {
  const double s = 1.0 / std::sqrt(3.0);
  return {{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}, {s, s, -s}};
}

/// The paper's Table 1 polytope: 8 half-spaces (+-1,+-1,+-1), b = 1 on the
/// even-sign ones and 5/3 on the others (before normalisation), beta = 20.
inline SmoothPolytope paper_poly(double beta = 20.0) {
  const double s = 1.0 / std::sqrt(3.0);
  return SmoothPolytope(octa_normals(), {s, s, s, s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s}, beta);
}

/// A box with half-extents (hx, hy, hz) as a smooth polytope.
inline SmoothPolytope box(double hx, double hy, double hz, double beta) {
  return SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {hx, hx, hy, hy, hz, hz}, beta);
}

/// Default solver options that keep the factorisation derivatives read.
inline SolverOptions with_derivatives() {
  SolverOptions o;
  o.derivatives = true;
  return o;
}

struct Named {
  std::string name;
  Shape shape;
};

/// One or more shapes of every family, at the paper's parameters and others.
inline std::vector<Named> catalogue() {
  return {
      {"sphere", Sphere(0.8)},
      {"ellipsoid", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
      {"SE_n8", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
      {"SE_n2.5", Superellipsoid(1.2, 0.7, 0.9, 2.5)},
      {"SEC_n8", SuperellipticCylinder(1.0, 2.0, 8.0)},
      {"SEC_n1", SuperellipticCylinder(0.6, 1.1, 1.0)},
      {"Poly_b20", paper_poly(20.0)},
      {"Box_b10", box(0.6, 0.9, 0.4, 10.0)},
      {"TC_b20", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
      {"Cone_b15", SmoothTruncatedCone(1.2, 0.2, 0.8, 1.0, 15.0)},
  };
}

/// The paper's four Table 1 shapes.
inline std::vector<Named> paper_shapes() {
  return {{"Poly", paper_poly()},
          {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
          {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
          {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)}};
}

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

inline Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

/// A pose with |r| log-uniform in [rmin, rmax] and a uniform rotation.
inline Pose random_pose(std::mt19937_64& rng, double rmin, double rmax) {
  std::uniform_real_distribution<double> u(std::log(rmin), std::log(rmax));
  Pose X;
  X.R = random_rotation(rng);
  X.p = std::exp(u(rng)) * random_unit(rng);
  return X;
}

/// The SE(3) exponential of a body twist xi = (v, w) in the paper's ordering
/// ... here (w, v): rotation part first. Used to build perturbed poses.
inline Pose se3_exp(const Vec3& w, const Vec3& v) {
  const double th = w.norm();
  Mat3 W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  Mat3 R = Mat3::Identity(), V = Mat3::Identity();
  if (th > 1e-12) {
    R += std::sin(th) / th * W + (1 - std::cos(th)) / (th * th) * W * W;
    V += (1 - std::cos(th)) / (th * th) * W + (th - std::sin(th)) / (th * th * th) * W * W;
  } else {
    R += W + 0.5 * W * W;
    V += 0.5 * W;
  }
  return Pose{R, V * v};
}


/// Distance from q to the ellipsoid with semi-axes ax (0 if inside), by
/// bisection on the multiplier mu of the closest point x_i = a_i^2 q_i / (a_i^2 + mu).
inline double point_ellipsoid_distance(const Vec3& ax, const Vec3& q) {
  double s = 0.0;
  for (int i = 0; i < 3; ++i) s += (q[i] / ax[i]) * (q[i] / ax[i]);
  if (s <= 1.0) return 0.0;
  double lo = 0.0, hi = q.norm() * ax.maxCoeff() + ax.maxCoeff() * ax.maxCoeff();
  for (int it = 0; it < 200; ++it) {
    const double mu = 0.5 * (lo + hi);
    double f = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double xi = ax[i] * q[i] / (ax[i] * ax[i] + mu);
      f += xi * xi;
    }
    (f > 1.0 ? lo : hi) = mu;
  }
  Vec3 x;
  for (int i = 0; i < 3; ++i) x[i] = ax[i] * ax[i] * q[i] / (ax[i] * ax[i] + 0.5 * (lo + hi));
  return (q - x).norm();
}
}  // namespace idcol::test
