// Sweep check of the IFT derivatives against finite differences for every
// ordered pair of the paper's four shapes (Table 1), N poses per pair
// (default 10000), |r| log-uniform in [0.2, 8] and uniform rotations, seeded.
//   idcol_check_derivatives [N] [seed]
// Prints one line per pair and the totals; failing poses at 17 digits.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/derivatives.hpp"

using namespace idcol;

namespace {
SmoothPolytope paper_poly() {
  const double s = 1.0 / std::sqrt(3.0);
  return SmoothPolytope({{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}, {s, s, -s}},
                        {s, s, s, s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s}, 20.0);
}
Pose random_pose(std::mt19937_64& rng, double rmin, double rmax) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(std::log(rmin), std::log(rmax));
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  Pose X;
  X.R = q.toRotationMatrix();
  X.p = std::exp(u(rng)) * Vec3(n(rng), n(rng), n(rng)).normalized();
  return X;
}
}  // namespace

int main(int argc, char** argv) {
  const int N = argc > 1 ? std::atoi(argv[1]) : 10000;
  const unsigned long seed = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 1;
  struct Named {
    const char* name;
    Shape s;
  };
  const std::vector<Named> shapes = {{"Poly", paper_poly()},
                                     {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
                                     {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                     {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)}};
  long poses = 0, conv = 0, fdf = 0, agree = 0, dflag = 0, dunflag = 0, flagged = 0;
  double worst = 0.0, min_pr = 1.0, max_s = 0.0;
  std::printf("pair      poses converged fd_failed agree flagged disagree_flagged disagree_unflagged agreement worst_err min_agree_pivot max_agree_sens\n");
  for (const auto& A : shapes)
    for (const auto& B : shapes) {
      std::mt19937_64 rng(seed * 1000003ul + (&A - shapes.data()) * 16 + (&B - shapes.data()));
      std::vector<Pose> P;
      P.reserve(N);
      for (int i = 0; i < N; ++i) P.push_back(random_pose(rng, 0.2, 8.0));
      const DerivativeCheckReport r = check_derivatives(A.s, B.s, P);
      std::printf("%-4s-%-4s %5d %9d %9d %5d %7d %16d %18d %9.6f %9.2e %9.2e %9.2e\n", A.name, B.name, r.poses, r.converged,
                  r.fd_failed, r.agree, r.flagged, r.disagree_flagged, r.disagree_unflagged, r.agreement(), r.worst_error,
                  r.min_agreeing_pivot_ratio, r.max_agreeing_sensitivity);
      for (const auto& f : r.failures) std::printf("  %s-%s %s\n", A.name, B.name, f.c_str());
      poses += r.poses, conv += r.converged, fdf += r.fd_failed, agree += r.agree, dflag += r.disagree_flagged;
      dunflag += r.disagree_unflagged, flagged += r.flagged;
      worst = std::max(worst, r.worst_error), min_pr = std::min(min_pr, r.min_agreeing_pivot_ratio);
      max_s = std::max(max_s, r.max_agreeing_sensitivity);
    }
  std::printf("TOTAL poses %ld converged %ld fd_failed %ld agree %ld (%.6f%%) flagged %ld disagree_flagged %ld "
              "disagree_unflagged %ld worst_err_unflagged %.3e min_agreeing_pivot_ratio %.3e max_agreeing_sensitivity %.3e\n",
              poses, conv, fdf, agree, 100.0 * agree / std::max(1L, conv - fdf), flagged, dflag, dunflag, worst, min_pr, max_s);
  return dunflag == 0 ? 0 : 1;
}
