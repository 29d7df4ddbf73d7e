// The paper's Table 1 shapes, the seeded poses that the derivative checks
// (check_derivatives.cpp, check_shape_derivatives.cpp) and benchmarks
// (core/bench/bench_*derivatives.cpp) run on, and the paper's sweep that the
// speed benchmarks and the batch tests run, in one place so that their
// figures are always taken on the same shapes and poses.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"

namespace idcol::examples {

/// The paper's octahedron-like polytope (8 faces), beta = 20.
inline SmoothPolytope paper_poly() {
  const double s = 1.0 / std::sqrt(3.0);
  return SmoothPolytope({{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}, {s, s, -s}},
                        {s, s, s, s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s}, 20.0);
}

/// The five shapes of the paper's Table 1 pairs, by the short names the
/// benchmarks and scripts/callgrind_pairs.sh use.
struct NamedShape {
  const char* name;
  Shape shape;
};
inline std::vector<NamedShape> paper_catalogue() {
  return {
      {"Poly", paper_poly()},
      {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
      {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
      {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)},
      {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
  };
}

/// Uniform rotation, |p| log-uniform in [rmin, rmax], uniform direction.
inline Pose random_pose(std::mt19937_64& rng, double rmin, double rmax) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(std::log(rmin), std::log(rmax));
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  Pose X;
  X.R = q.toRotationMatrix();
  X.p = std::exp(u(rng)) * Vec3(n(rng), n(rng), n(rng)).normalized();
  return X;
}

/// A seeded smooth trajectory of `poses` poses that starts at contact
/// (alpha* = 1) and moves by a fixed small twist per pose, so that warm
/// starts are those of a simulation.
inline std::vector<Pose> near_contact_trajectory(const Shape& a, const Shape& b, unsigned seed, int poses) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  Pose X0{q.toRotationMatrix(), 2.0 * Vec3(n(rng), n(rng), n(rng)).normalized()};
  const SolveResult r0 = solve(a, b, X0);
  if (r0.converged()) X0.p /= r0.alpha;  // start at contact
  Vec6 step;
  for (int i = 0; i < 6; ++i) step[i] = 0.002 * n(rng);
  std::vector<Pose> P;
  for (int k = 0; k < poses; ++k) P.push_back(X0 * se3_exp(static_cast<double>(k) * step));
  return P;
}

/// Default solver options that keep the factorisation derivatives read.
inline SolverOptions with_derivatives() {
  SolverOptions o;
  o.derivatives = true;
  return o;
}

/// Seeded sweep poses for the pair (i, j) of a catalogue: n poses with
/// |r| log-uniform in [0.2, 8], as the derivative checks take them.
inline std::vector<Pose> sweep_poses(unsigned long seed, std::ptrdiff_t i, std::ptrdiff_t j, int n) {
  std::mt19937_64 rng(seed * 1000003ul + i * 16 + j);
  std::vector<Pose> P;
  P.reserve(n);
  for (int k = 0; k < n; ++k) P.push_back(random_pose(rng, 0.2, 8.0));
  return P;
}

/// The totals of a derivative sweep over several pairs, and their line.
struct SweepTotals {
  long poses = 0, converged = 0, fd_failed = 0, agree = 0, disagree_flagged = 0, disagree_unflagged = 0, flagged = 0;
  double worst = 0.0, min_pivot_ratio = 1.0, max_sensitivity = 0.0;
  void add(const DerivativeCheckReport& r) {
    poses += r.poses, converged += r.converged, fd_failed += r.fd_failed, agree += r.agree;
    disagree_flagged += r.disagree_flagged, disagree_unflagged += r.disagree_unflagged, flagged += r.flagged;
    worst = std::max(worst, r.worst_error), min_pivot_ratio = std::min(min_pivot_ratio, r.min_agreeing_pivot_ratio);
    max_sensitivity = std::max(max_sensitivity, r.max_agreeing_sensitivity);
  }
  void print() const {
    std::printf("TOTAL poses %ld converged %ld fd_failed %ld agree %ld (%.6f%%) flagged %ld disagree_flagged %ld "
                "disagree_unflagged %ld worst_err_unflagged %.3e min_agreeing_pivot_ratio %.3e max_agreeing_sensitivity "
                "%.3e\n",
                poses, converged, fd_failed, agree, 100.0 * agree / std::max(1L, converged - fd_failed), flagged,
                disagree_flagged, disagree_unflagged, worst, min_pivot_ratio, max_sensitivity);
  }
};

/// Pose k of the paper's sweep (Sec. "Simulations and Benchmarking";
/// configs/paper_table1.toml): at t = k 1e-4, |r| between rmin and rmax
/// (uniform in volume along a sine), its direction and the rotation by sines
/// of incommensurate frequencies, so consecutive poses are close.
inline Pose paper_sweep_pose(std::size_t k, double rmin, double rmax) {
  const double t = static_cast<double>(k) * 1e-4, tp = 2.0 * M_PI;
  const double u = 0.5 * (1.0 + std::sin(tp * std::sqrt(2.0) * t));
  const double rad = std::cbrt(rmin * rmin * rmin + (rmax * rmax * rmax - rmin * rmin * rmin) * u);
  const double th = 0.5 * M_PI * std::sin(tp * std::sqrt(3.0) * t), ph = tp * std::sqrt(5.0) * t;
  Eigen::Quaterniond q(std::sin(tp * std::sqrt(7.0) * t), std::cos(tp * std::sqrt(11.0) * t), std::sin(tp * std::sqrt(13.0) * t),
                       std::cos(tp * std::sqrt(17.0) * t));
  q.normalize();
  return Pose{q.toRotationMatrix(), rad * Vec3(std::cos(th) * std::cos(ph), std::cos(th) * std::sin(ph), std::sin(th))};
}

/// The sweep's first n poses for a pair: |r| from a tenth of the smaller
/// inner radius to twice the larger outer one.
inline std::vector<Pose> paper_sweep(const Shape& a, const Shape& b, std::size_t n) {
  const Radii ra = radii(a), rb = radii(b);
  const double rmin = 0.1 * std::min(ra.inner, rb.inner), rmax = 2.0 * std::max(ra.outer, rb.outer);
  std::vector<Pose> P(n);
  for (std::size_t k = 0; k < n; ++k) P[k] = paper_sweep_pose(k, rmin, rmax);
  return P;
}

}  // namespace idcol::examples
