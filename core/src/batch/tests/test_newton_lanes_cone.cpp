// The smooth truncated cone's evaluation in the Newton lanes
// (newton_lanes_cone.hpp) against SmoothTruncatedCone::eval, to the bit:
// phi, the gradient and all nine Hessian entries, at points near and far
// from the body, beyond its axial range (the R < Rfloor branch, which the
// solves of test_batch_simd do not reach) and where the exponentials
// underflow (beta = 10^4). The kernel is compiled here as in
// batch_simd_sse2.cpp (2 lanes, -ffp-contract=off: core/tests/CMakeLists.txt).
#define IDCOL_LANES 2
#define IDCOL_LANE_FN ellipsoid_lanes_cone_test
#include "src/batch/batch_simd_kernel.hpp"
#define IDCOL_NEWTON_FN newton_lanes_cone_test
#define IDCOL_NEWTON_FINISH_FN newton_finish_lanes_cone_test
#include "src/batch/newton_lanes_kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "idcol/shapes.hpp"

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b)); }

/// LaneShape::cone with its constants formed here from the public lengths,
/// as the constructor forms them (lane_shape_cone takes the shape's own).
idcol::detail::LaneShape lane_cone(const idcol::SmoothTruncatedCone& c) {
  idcol::detail::LaneShape s{};
  s.family = idcol::detail::LaneFamily::Cone;
  s.cone.Rb = c.Rb();
  s.cone.kappa = (c.Rt() - c.Rb()) / (c.a() + c.b());
  s.cone.a = c.a();
  s.cone.b = c.b();
  s.cone.Rfloor = 0.5 * std::min(c.Rb(), c.Rt());
  s.cone.gbx = -1.0 / c.a();
  s.cone.gtx = 1.0 / c.b();
  s.cone_beta = c.beta();
  return s;
}

TEST(NewtonLanesCone, EvalIsTheShapesEvalToTheBit) {
  const idcol::SmoothTruncatedCone cones[] = {{1.0, 1.5, 1.5, 1.5, 20.0},
                                              {0.6, 0.25, 0.8, 1.9, 120.0},
                                              {1.0, 0.01, 0.1, 5.0, 1e4},
                                              {0.02, 3.0, 2.0, 0.3, 2.0}};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), decade(-6.0, 3.0);
  long points = 0, floored = 0, differ = 0;
  for (const auto& c : cones) {
    const idcol::detail::LaneShape s = lane_cone(c);
    for (int it = 0; it < 50000; ++it) {
      double ys[W][3];
      V3 y;
      for (int l = 0; l < W; ++l) {
        for (int k = 0; k < 3; ++k) ys[l][k] = u(rng) * std::pow(10.0, decade(rng));
        if (it % 4 == 0) ys[l][0] = (u(rng) > 0.0 ? c.b() : -c.a()) * (1.0 + 0.3 * u(rng));  // about the end caps
        y.x[l] = ys[l][0], y.y[l] = ys[l][1], y.z[l] = ys[l][2];
      }
      Eval e;
      M bad = M{};
      eval_cone(s, y, e, bad);
      for (int l = 0; l < W; ++l) {
        idcol::ShapeEval want;
        c.eval(idcol::Vec3(ys[l][0], ys[l][1], ys[l][2]), want);
        ++points;
        floored += s.cone.Rb + s.cone.kappa * (ys[l][0] + s.cone.a) < s.cone.Rfloor;
        bool same = bad[l] == 0 && same_bits(e.phi[l], want.phi) && same_bits(e.g.x[l], want.grad[0]) &&
                    same_bits(e.g.y[l], want.grad[1]) && same_bits(e.g.z[l], want.grad[2]);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) same = same && same_bits(e.h[3 * i + j][l], want.hess(i, j));
        if (!same && differ < 5)
          ADD_FAILURE() << "y = (" << ys[l][0] << ", " << ys[l][1] << ", " << ys[l][2] << "): phi " << e.phi[l] << " vs "
                        << want.phi;
        differ += !same;
      }
    }
  }
  EXPECT_EQ(differ, 0) << "of " << points << " points";
  EXPECT_GT(floored, points / 20) << "too few points beyond the axial range (R < Rfloor)";
}

}  // namespace
