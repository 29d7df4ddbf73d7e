// The generators against their formulas, written out again here without the
// generator's code.
#include <gtest/gtest.h>

#include <cmath>

#include "gen/poses.hpp"
#include "test_util.hpp"

namespace idcol::harness {
namespace {

const double kPi = std::acos(-1.0);

TEST(PaperGenerator, MatchesTheFormulasAtChosenK) {
  const RadialRange range{0.05, 6.0};
  const double dt = 1e-4;
  const PoseGenerator gen(GeneratorKind::Paper, range, dt);
  for (std::uint64_t k : {0ull, 1ull, 7ull, 12345ull, 500000ull, 999999ull}) {
    const double t = k * dt;
    const double u = 0.5 * (1 + std::sin(2 * kPi * std::sqrt(2.0) * t));
    const double rad = std::pow(std::pow(0.05, 3) + (std::pow(6.0, 3) - std::pow(0.05, 3)) * u, 1.0 / 3.0);
    const double th = kPi / 2 * std::sin(2 * kPi * std::sqrt(3.0) * t);
    const double ph = 2 * kPi * std::sqrt(5.0) * t;
    const Vec3 p = rad * Vec3(std::cos(th) * std::cos(ph), std::cos(th) * std::sin(ph), std::sin(th));
    double w = std::sin(2 * kPi * std::sqrt(7.0) * t), x = std::cos(2 * kPi * std::sqrt(11.0) * t),
           y = std::sin(2 * kPi * std::sqrt(13.0) * t), z = std::cos(2 * kPi * std::sqrt(17.0) * t);
    const double n = std::sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    // Rotation matrix of a unit quaternion, written out.
    Mat3 R;
    R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
    const Pose X = gen(k);
    EXPECT_LT((X.p - p).norm(), 1e-12 * (1 + p.norm())) << "k = " << k;
    EXPECT_LT((X.R - R).norm(), 1e-13) << "k = " << k;
    EXPECT_EQ(check_pose(X), PoseCheck::Ok);
    const double r = X.p.norm();
    EXPECT_GE(r, range.rmin * (1 - 1e-12));
    EXPECT_LE(r, range.rmax * (1 + 1e-12));
  }
  // k = 0: t = 0, u = 1/2, theta = phi = 0, q = (0, 1, 0, 1)/sqrt2.
  const Pose X0 = gen(0);
  EXPECT_NEAR(X0.p.y(), 0.0, 1e-15);
  EXPECT_NEAR(X0.p.z(), 0.0, 1e-15);
}

TEST(PaperGenerator, PoseKDependsOnKAlone) {
  const PoseGenerator gen(GeneratorKind::Paper, {0.1, 3.0}, 1e-4);
  const Pose a = gen(424242);
  for (std::uint64_t k = 0; k < 100; ++k) (void)gen(k);
  const Pose b = gen(424242);
  EXPECT_EQ(a.R, b.R);
  EXPECT_EQ(a.p, b.p);
}

TEST(PaperGenerator, RadialRangeOfPair) {
  const auto shapes = test::paper_shapes();
  const RadialRange r = radial_range(shapes[2].shape, shapes[3].shape);  // SE(0.5, 1, 1.5, 8), SEC(1, 2, 8)
  // From the bodies' closed-form radii, worked out by hand: inner = min axis,
  // 0.5 and 1; outer = sqrt(||(a_i^2)||_{n/(n-1)}), 1.77908... (SE) and
  // sqrt((4^(8/7) + 1)^(7/8)) = 2.17008... (SEC). rmin = 0.1 min inner,
  // rmax = 2 max outer.
  EXPECT_NEAR(r.rmin, 0.05, 1e-15);
  EXPECT_NEAR(r.rmax, 4.3401530395948225, 1e-12);
}

TEST(UniformGenerator, HaltonCoordinates) {
  EXPECT_EQ(radical_inverse(1, 2), 0.5);
  EXPECT_EQ(radical_inverse(6, 2), 0.375);  // 110b -> 0.011b
  EXPECT_NEAR(radical_inverse(5, 3), 2.0 / 3.0 + 1.0 / 9.0, 1e-15);  // 12 (base 3) -> 0.21 (base 3)
}

TEST(UniformGenerator, ProperRotationsRadiiInRangeAndUniformMoments) {
  const RadialRange range{0.1, 2.0};
  const PoseGenerator gen(GeneratorKind::Uniform, range, 1e-4);
  const int n = 20000;
  Mat3 meanR = Mat3::Zero();
  Vec3 meanDir = Vec3::Zero();
  double mean_r3 = 0;
  for (int k = 0; k < n; ++k) {
    const Pose X = gen(k);
    ASSERT_EQ(check_pose(X), PoseCheck::Ok);
    const double r = X.p.norm();
    ASSERT_GE(r, range.rmin * (1 - 1e-12));
    ASSERT_LE(r, range.rmax * (1 + 1e-12));
    meanR += X.R / n;
    meanDir += X.p.normalized() / n;
    mean_r3 += r * r * r / n;
  }
  // Haar measure: E[R] = 0; uniform direction: E[d] = 0; r^3 uniform: E[r^3] = (a+b)/2.
  EXPECT_LT(meanR.norm(), 0.02);
  EXPECT_LT(meanDir.norm(), 0.02);
  EXPECT_NEAR(mean_r3, 0.5 * (0.001 + 8.0), 0.02);
}

}  // namespace
}  // namespace idcol::harness
