#include <cmath>
#include <cstdio>

#include "idcol/solver.hpp"

int main() {
  const idcol::SolveResult r = idcol::solve(idcol::Sphere(1.0), idcol::Sphere(2.0), idcol::Pose{idcol::Mat3::Identity(), idcol::Vec3(0, 0, 6)});
  std::printf("alpha = %.17g\n", r.alpha);
  return r.converged() && std::abs(r.alpha - 2.0) < 1e-12 ? 0 : 1;
}
