// Solves one contact between the paper's superellipsoid and smooth polytope
// and prints the result.
#include <cstdio>

#include <Eigen/Geometry>

#include "idcol/solver.hpp"

int main() {
  using namespace idcol;
  const Shape se = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  const double s = 1.0 / std::sqrt(3.0);
  const Shape poly = SmoothPolytope({{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}, {-s, -s, -s}, {-s, s, s}, {s, -s, s}, {s, s, -s}},
                                    {s, s, s, s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s, 5.0 / 3.0 * s}, 20.0);
  Pose X_12;
  X_12.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X_12.p = Vec3(1.2, -0.4, 0.9);
  const SolveResult r = solve(se, poly, X_12);
  std::printf("status      %s\n", to_string(r.status));
  std::printf("alpha*      %.15g (%s)\n", r.alpha, r.alpha < 1 ? "penetrating" : "separated");
  std::printf("x* (body 1) %.12g %.12g %.12g\n", r.x_1.x(), r.x_1.y(), r.x_1.z());
  std::printf("lambda      %.6g %.6g\n", r.lambda1, r.lambda2);
  std::printf("iterations  %d   residual %.3g\n", r.iterations, r.residual_norm);
  return r.converged() ? 0 : 1;
}
