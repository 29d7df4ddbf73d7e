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
#include "cli_args.hpp"
#include "paper_shapes.hpp"

using namespace idcol;

using examples::paper_poly;
using examples::sweep_poses;

int main(int argc, char** argv) {
  examples::positional_args("idcol_check_shape_derivatives [N = 10000] [seed = 1]", argc, argv, 2);
  const int N = argc > 1 ? static_cast<int>(examples::count_arg("idcol_check_shape_derivatives", "N", argv[1], 1, 100000000)) : 10000;
  const unsigned long seed = argc > 2 ? static_cast<unsigned long>(examples::count_arg("idcol_check_shape_derivatives", "seed", argv[2], 0, 2147483647)) : 1;
  struct Named {
    const char* name;
    Shape s;
  };
  const std::vector<Named> shapes = {{"Sph", Sphere(0.8)},
                                     {"Poly", paper_poly()},
                                     {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
                                     {"SE", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                     {"SEC", SuperellipticCylinder(1.0, 2.0, 8.0)}};
  examples::SweepTotals total;
  std::printf("pair      body params poses converged fd_failed agree flagged disagree_flagged disagree_unflagged agreement worst_err min_agree_pivot max_agree_sens\n");
  for (const auto& A : shapes)
    for (const auto& B : shapes)
      for (int body : {1, 2}) {
        const std::vector<Pose> P = sweep_poses(seed, &A - shapes.data(), &B - shapes.data(), N);
        const DerivativeCheckReport r = check_shape_derivatives(A.s, B.s, body, P);
        std::printf("%-4s-%-4s %4d %6d %5d %9d %9d %5d %7d %16d %18d %9.6f %9.2e %9.2e %9.2e\n", A.name, B.name, body,
                    num_params(body == 1 ? A.s : B.s), r.poses, r.converged, r.fd_failed, r.agree, r.flagged,
                    r.disagree_flagged, r.disagree_unflagged, r.agreement(), r.worst_error, r.min_agreeing_pivot_ratio,
                    r.max_agreeing_sensitivity);
        for (const auto& f : r.failures) std::printf("  %s-%s body %d %s\n", A.name, B.name, body, f.c_str());
        std::fflush(stdout);
        total.add(r);
      }
  total.print();
  return total.disagree_unflagged == 0 ? 0 : 1;
}
