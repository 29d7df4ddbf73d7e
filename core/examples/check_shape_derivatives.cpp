// Sweep check of the shape-parameter derivatives dz*/dtheta (rows x_1 and
// alpha, shape_derivatives.hpp) against central differences in theta, for
// every ordered pair of a sphere and the paper's four shapes (Table 1), the
// parameters of body 1 and of body 2 separately; N poses per pair (default
// 10000), |r| log-uniform in [0.2, 8] and uniform rotations, seeded.
//   idcol_check_shape_derivatives [N] [seed]
// Prints one line per pair and body and the totals; failing poses at 17
// digits. Exit status 1 if a disagreement was not flagged by Conditioning.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/shape_derivatives.hpp"

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
  const std::vector<Named> shapes = {{"Sph", Sphere(0.8)},
                                     {"Poly", paper_poly()},
                                     {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
                                     {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                     {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)}};
  long poses = 0, conv = 0, fdf = 0, agree = 0, dflag = 0, dunflag = 0, flagged = 0;
  double worst = 0.0, min_pr = 1.0, max_s = 0.0;
  std::printf("pair      body params poses converged fd_failed agree flagged disagree_flagged disagree_unflagged agreement worst_err min_agree_pivot max_agree_sens\n");
  for (const auto& A : shapes)
    for (const auto& B : shapes)
      for (int body : {1, 2}) {
        std::mt19937_64 rng(seed * 1000003ul + (&A - shapes.data()) * 16 + (&B - shapes.data()));
        std::vector<Pose> P;
        P.reserve(N);
        for (int i = 0; i < N; ++i) P.push_back(random_pose(rng, 0.2, 8.0));
        const DerivativeCheckReport r = check_shape_derivatives(A.s, B.s, body, P);
        std::printf("%-4s-%-4s %4d %6d %5d %9d %9d %5d %7d %16d %18d %9.6f %9.2e %9.2e %9.2e\n", A.name, B.name, body,
                    num_params(body == 1 ? A.s : B.s), r.poses, r.converged, r.fd_failed, r.agree, r.flagged,
                    r.disagree_flagged, r.disagree_unflagged, r.agreement(), r.worst_error, r.min_agreeing_pivot_ratio,
                    r.max_agreeing_sensitivity);
        for (const auto& f : r.failures) std::printf("  %s-%s body %d %s\n", A.name, B.name, body, f.c_str());
        std::fflush(stdout);
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
