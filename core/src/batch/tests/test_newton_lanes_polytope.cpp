// The smooth polytope's evaluation in the Newton lanes
// (newton_lanes_polytope.hpp) against SmoothPolytope::eval, to the bit:
// phi, the gradient and all nine Hessian entries (which the solves of
// test_batch_simd see only through the Newton steps), for the face kernel
// the library runs on this CPU (detail::polytope_kernel_isa(): fused
// multiply-adds or none), at points near and far from the body, with
// weights that underflow, and for face counts that are and are not
// multiples of 4, up to more than the kernel's block of 64. The kernel is
// compiled here as in batch_simd_sse2.cpp (2 lanes, -ffp-contract=off:
// core/tests/CMakeLists.txt), where a fused multiply-add is std::fma per
// lane (correctly rounded, as the instruction).
#define IDCOL_LANES 2
#define IDCOL_LANE_FN ellipsoid_lanes_polytope_test
#include "src/batch/batch_simd_kernel.hpp"
#define IDCOL_NEWTON_FN newton_lanes_polytope_test
#define IDCOL_NEWTON_FINISH_FN newton_finish_lanes_polytope_test
#include "src/batch/newton_lanes_kernel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "idcol/shapes.hpp"
#include "test_util.hpp"

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b)); }

/// LaneShape for a polytope as lane_shape_polytope (batch_simd.cpp) fills it.
idcol::detail::LaneShape lane_polytope(const idcol::SmoothPolytope& p, bool fused) {
  idcol::detail::LaneShape s{};
  s.family = idcol::detail::LaneFamily::Polytope;
  s.poly = {p.face_block(), p.face_block_rows(), p.beta(), p.L(), p.beta() / p.L(), fused};
  return s;
}

idcol::SmoothPolytope hull(int n, unsigned seed, double beta, double L) {
  std::mt19937_64 rng(seed);
  std::vector<idcol::Vec3> V;
  for (int i = 0; i < n; ++i) {
    const idcol::Vec3 u = idcol::test::random_unit(rng);
    V.push_back(idcol::Vec3(0.8 * u.x(), 1.1 * u.y(), 0.6 * u.z()));
  }
  return idcol::SmoothPolytope::from_vertices(V, beta, L);
}

TEST(NewtonLanesPolytope, EvalIsTheShapesEvalToTheBit) {
  const bool fused = std::string(idcol::detail::polytope_kernel_isa()) == "avx2";
  const std::vector<idcol::SmoothPolytope> polys = {
      idcol::test::paper_poly(), idcol::test::box(0.6, 0.9, 0.4, 10.0),
      idcol::SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {0.6, 0.6, 0.9, 0.9, 0.4, 0.4},
                            2000.0, 0.7),
      hull(11, 7, 40.0, 1.0), hull(60, 8, 40.0, 0.3)};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), decade(-4.0, 2.0);
  long points = 0, differ = 0;
  for (const auto& P : polys) {
    const idcol::detail::LaneShape s = lane_polytope(P, fused);
    for (int it = 0; it < 20000; ++it) {
      double ys[W][3];
      V3 y;
      for (int l = 0; l < W; ++l) {
        for (int k = 0; k < 3; ++k) ys[l][k] = u(rng) * std::pow(10.0, decade(rng));
        y.x[l] = ys[l][0], y.y[l] = ys[l][1], y.z[l] = ys[l][2];
      }
      Eval e;
      M bad = M{};
      if (fused) eval_polytope_impl<true>(s, y, e, bad);
      else eval_polytope_impl<false>(s, y, e, bad);
      for (int l = 0; l < W; ++l) {
        idcol::ShapeEval want;
        P.eval(idcol::Vec3(ys[l][0], ys[l][1], ys[l][2]), want);
        ++points;
        bool same = bad[l] == 0 && same_bits(e.phi[l], want.phi) && same_bits(e.g.x[l], want.grad[0]) &&
                    same_bits(e.g.y[l], want.grad[1]) && same_bits(e.g.z[l], want.grad[2]);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) same = same && same_bits(e.h[3 * i + j][l], want.hess(i, j));
        if (!same && differ < 5)
          ADD_FAILURE() << P.num_halfspaces() << " faces, y = (" << ys[l][0] << ", " << ys[l][1] << ", " << ys[l][2]
                        << "): phi " << e.phi[l] << " vs " << want.phi << ", hess(0,1) " << e.h[1][l] << " vs "
                        << want.hess(0, 1);
        differ += !same;
      }
    }
  }
  EXPECT_EQ(differ, 0) << "of " << points << " points (face kernel " << idcol::detail::polytope_kernel_isa() << ")";
  std::printf("[face kernel %s] %ld points, %ld differ\n", idcol::detail::polytope_kernel_isa(), points, differ);
}

}  // namespace
