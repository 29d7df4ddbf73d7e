// Time of impact against oracles that share no code with the solver: the
// quadratic of two spheres in translation, the distance from a point to an
// ellipsoid (a one-dimensional root in the Lagrange multiplier) with dense
// sampling and bisection in t, the plate's exact and shrunk polytopes for
// tunnelling, and finite differences through the SE(3) exponential for dt*.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "idcol/solver.hpp"
#include "idcol/toi.hpp"
#include "test_util.hpp"

namespace idcol {
namespace {

using test::box;

Pose translation(const Vec3& p, const Mat3& R = Mat3::Identity()) { return Pose{R, p}; }
Mat3 rot_z(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

/// Smallest t in [0, 1] with |p0 + t d| = R, or NaN: the closed form for two
/// spheres in translation.
double sphere_quadratic(const Vec3& p0, const Vec3& p1, double R) {
  const Vec3 d = p1 - p0;
  const double a = d.squaredNorm(), b = 2.0 * p0.dot(d), c = p0.squaredNorm() - R * R;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return std::nan("");
  const double t = (-b - std::sqrt(disc)) / (2.0 * a);
  return (t >= 0.0 && t <= 1.0) ? t : std::nan("");
}


/// First time the ellipsoid (body 2, pose X(t)) touches the ball of radius
/// Rs at the origin (body 1): dense sampling of the gap, then bisection.
template <class PoseAt>
double ellipsoid_sphere_toi(double Rs, const Vec3& ax, PoseAt pose_at, int samples = 4000) {
  auto gap = [&](double t) {
    const Pose X = pose_at(t);
    return test::point_ellipsoid_distance(ax, X.R.transpose() * (-X.p)) - Rs;
  };
  double prev = 0.0;
  for (int k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) / samples;
    if (gap(t) <= 0.0) {
      double lo = prev, hi = t;
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (lo + hi);
        (gap(mid) > 0.0 ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    }
    prev = t;
  }
  return std::nan("");
}

TEST(Toi, TwoSpheresInTranslationMatchTheQuadratic) {
  const Sphere a(0.3), b(0.2);
  const Vec3 p0(-2.0, 0.1, 0.05), p1(2.0, -0.1, 0.2);
  const ToiResult r = time_of_impact(a, b, translation(p0), translation(p1));
  const double t_ref = sphere_quadratic(p0, p1, 0.5);
  ASSERT_EQ(r.status, ToiStatus::Impact);
  EXPECT_NEAR(r.t, t_ref, 1e-9);
  EXPECT_NEAR(r.contact.alpha, 1.0, 1e-8);
  EXPECT_LE(r.t_free, r.t);
  EXPECT_LT(r.alpha_rate, 0.0);
  EXPECT_LE(r.solves, 10);  // Newton from the left on the convex alpha*(t)
  // the contact pose is the translated one, exactly linear in t
  EXPECT_TRUE(r.X_12.R == Mat3::Identity());
  EXPECT_NEAR((r.X_12.p - (p0 + r.t * (p1 - p0))).norm(), 0.0, 1e-15);
}

TEST(Toi, RandomSphereTranslationsMissNoContact) {
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> u(-3.0, 3.0), rad(0.05, 1.0);
  int hits = 0, misses = 0;
  for (int k = 0; k < 300; ++k) {
    const double R1 = rad(rng), R2 = rad(rng);
    const Vec3 p0(u(rng), u(rng), u(rng)), p1(u(rng), u(rng), u(rng));
    if (p0.norm() <= 1.01 * (R1 + R2)) continue;
    const Mat3 R = test::random_rotation(rng);
    const ToiResult r = time_of_impact(Sphere(R1), Sphere(R2), translation(p0, R), translation(p1, R));
    const double t_ref = sphere_quadratic(p0, p1, R1 + R2);
    SCOPED_TRACE(k);
    if (std::isnan(t_ref)) {
      // a graze within alpha_tolerance may count as touching
      const double dmin = [&] {
        const Vec3 d = p1 - p0;
        const double s = std::clamp(-p0.dot(d) / d.squaredNorm(), 0.0, 1.0);
        return (p0 + s * d).norm();
      }();
      if (dmin > (R1 + R2) * (1.0 + 1e-6)) EXPECT_EQ(r.status, ToiStatus::NoImpact);
      ++misses;
    } else {
      ASSERT_EQ(r.status, ToiStatus::Impact);
      EXPECT_NEAR(r.t, t_ref, 1e-7);
      ++hits;
    }
  }
  EXPECT_GT(hits, 30);
  EXPECT_GT(misses, 30);
}

TEST(Toi, SphereAgainstEllipsoidMatchesTheDistanceOracle) {
  const double Rs = 0.25;
  const Vec3 ax(0.8, 0.3, 0.2);
  const Sphere s(Rs);
  const Superellipsoid e(ax[0], ax[1], ax[2], 1.0);
  std::mt19937_64 rng(7);
  int hits = 0;
  for (int k = 0; k < 12; ++k) {
    SCOPED_TRACE(k);
    Pose X0{test::random_rotation(rng), Vec3(-2.0, 0.3 * (k % 3) - 0.3, 0.1)};
    Pose X1{k < 6 ? X0.R : test::random_rotation(rng), Vec3(2.0, 0.2, -0.1 * (k % 4))};
    const Vec6 xi = se3_log(X0.inverse() * X1);
    auto pose_at = [&](double t) { return X0 * test::se3_exp(t * xi.head<3>(), t * xi.tail<3>()); };
    const double t_ref = ellipsoid_sphere_toi(Rs, ax, pose_at);
    const ToiResult r = time_of_impact(s, e, X0, X1);
    if (std::isnan(t_ref)) {
      EXPECT_EQ(r.status, ToiStatus::NoImpact);
    } else {
      ++hits;
      ASSERT_EQ(r.status, ToiStatus::Impact);
      EXPECT_NEAR(r.t, t_ref, 1e-8);
    }
  }
  EXPECT_GE(hits, 8);
}

TEST(Toi, RotationOnlyMotionSweepsTheRodIntoTheSphere) {
  // A rod (ellipsoid 1 x 0.05 x 0.05) turning about its centre, whose tip
  // sweeps through a sphere: p stays fixed, R turns by pi/2 about z.
  const double Rs = 0.1;
  const Vec3 ax(1.0, 0.05, 0.05);
  const Vec3 r(-0.3, -0.6, 0.0);  // rod centre in body 1 (sphere at the origin)
  const Pose X0{rot_z(0.0), r}, X1{rot_z(M_PI / 2), r};
  auto pose_at = [&](double t) { return Pose{rot_z(t * M_PI / 2), r}; };
  const double t_ref = ellipsoid_sphere_toi(Rs, ax, pose_at);
  ASSERT_FALSE(std::isnan(t_ref));
  const ToiResult res = time_of_impact(Sphere(Rs), Superellipsoid(ax[0], ax[1], ax[2], 1.0), X0, X1);
  ASSERT_EQ(res.status, ToiStatus::Impact);
  EXPECT_NEAR(res.t, t_ref, 1e-8);
  EXPECT_NEAR((res.X_12.p - r).norm(), 0.0, 1e-12);
}

TEST(Toi, SmallSphereTunnellingThroughAThinPlateIsCaught) {
  // Plate 2 x 2 x 0.01 (a sharp smooth polytope), sphere of radius 0.02
  // crossing it within one motion: both end poses are far from it.
  const double h = 0.005, Rs = 0.02, beta = 2000.0;
  const SmoothPolytope plate = box(1.0, 1.0, h, beta);
  const Sphere ball(Rs);
  const Vec3 p0(0.1, -0.2, -1.0), p1(0.12, -0.18, 1.0);
  EXPECT_GT(solve(plate, ball, translation(p0)).alpha, 1.0);
  EXPECT_GT(solve(plate, ball, translation(p1)).alpha, 1.0);
  const ToiResult r = time_of_impact(plate, ball, translation(p0), translation(p1));
  ASSERT_EQ(r.status, ToiStatus::Impact);
  // the smooth plate lies between the exact one and (1 - log(6)/(beta h)) of it
  const double h_in = h * (1.0 - std::log(6.0) / (beta * h));
  const double t_early = (1.0 - h - Rs) / 2.0, t_late = (1.0 - h_in - Rs) / 2.0;
  // (|alpha* - 1| <= 1e-9 is a gap of 1e-9 |r| ~ 3e-11, 1.5e-11 in t)
  EXPECT_GE(r.t, t_early - 1e-10);
  EXPECT_LE(r.t, t_late + 1e-10);
  // and turning: the plate (body 2) spins half a turn while the sphere passes
  const Pose Y0{Mat3::Identity(), -p0}, Y1{rot_z(M_PI * 0.9), -p1};
  const ToiResult r2 = time_of_impact(ball, plate, Y0, Y1);
  EXPECT_EQ(r2.status, ToiStatus::Impact);
  EXPECT_GT(r2.t, 0.3);
  EXPECT_LT(r2.t, 0.6);
  EXPECT_NEAR(r2.contact.alpha, 1.0, 1e-8);
}

TEST(Toi, DenseSamplingFindsNoContactBeforeT) {
  // Certification seen from outside: alpha* > 1 at dense times before t (on
  // [0, 1] for NoImpact). A screw motion's origin follows a helix, which may
  // swing around the plate: the oracle, not intuition, says which motions hit.
  const SmoothPolytope plate = box(1.0, 0.5, 0.02, 200.0);
  const Superellipsoid e(0.3, 0.1, 0.05, 2.0);
  std::mt19937_64 rng(11);
  int hits = 0;
  for (int k = 0; k < 10; ++k) {
    SCOPED_TRACE(k);
    const Pose X0{test::random_rotation(rng), Vec3(0.2, 0.1, -1.5)};
    const Mat3 turn = Eigen::AngleAxisd(0.3 * k, test::random_unit(rng)).toRotationMatrix();
    const Pose X1{X0.R * turn, Vec3(-0.1, 0.0, 1.5)};
    const ToiResult r = time_of_impact(plate, e, X0, X1);
    ASSERT_TRUE(r.status == ToiStatus::Impact || r.status == ToiStatus::NoImpact) << to_string(r.status);
    const double t_end = r.status == ToiStatus::Impact ? r.t : 1.0;
    if (r.status == ToiStatus::Impact) {
      ++hits;
      EXPECT_NEAR(r.contact.alpha, 1.0, 1e-8);
    }
    for (int j = 0; j <= 1000; ++j) {
      const double t = t_end * j / 1000.0;
      if (r.status == ToiStatus::Impact && j == 1000) break;
      const SolveResult s = solve(plate, e, screw_interpolate(X0, X1, t));
      ASSERT_TRUE(s.converged());
      EXPECT_GT(s.alpha, 1.0) << "t = " << t << " before the reported " << r.t;
    }
  }
  EXPECT_GE(hits, 5);
}

TEST(Toi, CurvedScrewPathsAgainstDenseSampling) {
  // Large turns make body 2's origin follow a tight helix, which can bend
  // into the plate where the straight tangent would not: the path's
  // curvature term of the certified step is what keeps these. The oracle
  // samples alpha* every 1/4000 and bisects the first sign change; motions
  // whose sampled minimum of alpha* is within 1e-3 of 1 (grazes) are skipped.
  const SmoothPolytope plate = box(1.0, 1.0, 0.01, 500.0);
  const Sphere ball(0.05);
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(-1.0, 1.0), ang(2.0, 3.1);
  int hits = 0, misses = 0;
  for (int k = 0; k < 40; ++k) {
    SCOPED_TRACE(k);
    const Pose X0{test::random_rotation(rng), Vec3(0.8 * u(rng), 0.8 * u(rng), 0.4 + 0.3 * std::abs(u(rng)))};
    const Mat3 turn = Eigen::AngleAxisd(ang(rng), test::random_unit(rng)).toRotationMatrix();
    const Pose X1{X0.R * turn, Vec3(0.8 * u(rng), 0.8 * u(rng), -0.4 - 0.3 * std::abs(u(rng)))};
    auto alpha_at = [&](double t) { return solve(plate, ball, screw_interpolate(X0, X1, t)).alpha; };
    double t_ref = std::nan(""), amin = alpha_at(0.0), prev = 0.0;
    for (int j = 1; j <= 4000; ++j) {
      const double t = j / 4000.0, a = alpha_at(t);
      amin = std::min(amin, a);
      if (a <= 1.0) {
        double lo = prev, hi = t;
        for (int it = 0; it < 60; ++it) {
          const double mid = 0.5 * (lo + hi);
          (alpha_at(mid) > 1.0 ? lo : hi) = mid;
        }
        t_ref = 0.5 * (lo + hi);
        break;
      }
      prev = t;
    }
    if (std::abs(amin - 1.0) < 1e-3) continue;
    const ToiResult r = time_of_impact(plate, ball, X0, X1);
    if (std::isnan(t_ref)) {
      EXPECT_EQ(r.status, ToiStatus::NoImpact);
      ++misses;
    } else {
      ASSERT_EQ(r.status, ToiStatus::Impact);
      EXPECT_NEAR(r.t, t_ref, 1e-8);
      ++hits;
    }
  }
  EXPECT_GE(hits, 10);
  EXPECT_GE(misses, 2);
}

TEST(Toi, ContactsBroughtAboutByTheTurnAreDecided) {
  // Motions drawn for 25 ordered pairs of five shapes, 20 each (k odd: pure
  // translations); those of the superelliptic cylinder (body 1) and the
  // superellipsoid (body 2) are run. Motion 16 there is a contact the turn
  // brings about while alpha* dips to 0.9996 only: it takes 226 solves and
  // ended in IterationLimit under the former max_solves = 200. Every motion
  // must be decided, and alpha* > 1 at dense times before t.
  const Superellipsoid a(0.5, 0.3, 0.2, 3.0);
  const SuperellipticCylinder c(0.2, 0.5, 4.0);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  int max_solves = 0;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 20; ++k) {
        const Vec3 d = test::random_unit(rng);
        const Pose X0{test::random_rotation(rng), (1.2 + u(rng)) * d};
        const Pose X1{k % 2 ? X0.R : Mat3(X0.R * Eigen::AngleAxisd(3.0 * u(rng), test::random_unit(rng)).toRotationMatrix()),
                      -(1.2 + u(rng)) * d + 0.8 * u(rng) * test::random_unit(rng)};
        if (i != 2 || j != 1) continue;
        SCOPED_TRACE(k);
        const ToiResult r = time_of_impact(c, a, X0, X1);
        max_solves = std::max(max_solves, r.solves);
        ASSERT_TRUE(r.status == ToiStatus::Impact || r.status == ToiStatus::NoImpact) << to_string(r.status);
        const double t_end = r.status == ToiStatus::Impact ? r.t : 1.0;
        for (int n = 0; n < 1000; ++n) {
          const double t = t_end * n / 1000.0;
          const SolveResult s = solve(c, a, screw_interpolate(X0, X1, t));
          ASSERT_TRUE(s.converged());
          EXPECT_GT(s.alpha, 1.0) << "t = " << t << " before the reported " << r.t;
        }
      }
  EXPECT_GT(max_solves, 200);  // the hard motion is still in the set
}

TEST(Toi, GrazingMotions) {
  const Sphere a(0.3), b(0.2);
  // exactly tangent at t = 0.5
  {
    const ToiResult r = time_of_impact(a, b, translation({-1.0, 0.5, 0.0}), translation({1.0, 0.5, 0.0}));
    ASSERT_EQ(r.status, ToiStatus::Impact);
    EXPECT_NEAR(r.t, 0.5, 1e-4);
    EXPECT_NEAR(r.contact.alpha, 1.0, 2e-9);
  }
  // a hair outside: no contact
  {
    const ToiResult r = time_of_impact(a, b, translation({-1.0, 0.5 * (1 + 1e-6), 0.0}),
                                       translation({1.0, 0.5 * (1 + 1e-6), 0.0}));
    EXPECT_EQ(r.status, ToiStatus::NoImpact);
    EXPECT_EQ(r.t_free, 1.0);
  }
  // a hair inside: the contact, at the quadratic's time
  {
    const Vec3 p0(-1.0, 0.5 * (1 - 1e-6), 0.0), p1(1.0, 0.5 * (1 - 1e-6), 0.0);
    const ToiResult r = time_of_impact(a, b, translation(p0), translation(p1));
    ASSERT_EQ(r.status, ToiStatus::Impact);
    EXPECT_NEAR(r.t, sphere_quadratic(p0, p1, 0.5), 2e-5);  // a graze: t ~ sqrt(alpha_tolerance)
  }
}

TEST(Toi, InitiallyTouchingOrPenetrating) {
  const Sphere a(0.3), b(0.2);
  const ToiResult pen = time_of_impact(a, b, translation({0.3, 0.0, 0.0}), translation({2.0, 0.0, 0.0}));
  EXPECT_EQ(pen.status, ToiStatus::InitiallyInContact);
  EXPECT_EQ(pen.t, 0.0);
  EXPECT_LT(pen.contact.alpha, 1.0);
  const ToiResult touch = time_of_impact(a, b, translation({0.5, 0.0, 0.0}), translation({2.0, 0.0, 0.0}));
  EXPECT_EQ(touch.status, ToiStatus::InitiallyInContact);
  const ToiResult concentric = time_of_impact(a, b, translation({0.0, 0.0, 0.0}), translation({2.0, 0.0, 0.0}));
  EXPECT_EQ(concentric.status, ToiStatus::InitiallyInContact);
}

TEST(Toi, NoImpact) {
  const Sphere a(0.3);
  const Superellipsoid e(0.4, 0.2, 0.1, 2.0);
  // moving apart
  EXPECT_EQ(time_of_impact(a, e, translation({1.0, 0.0, 0.0}), translation({3.0, 0.0, 0.0})).status,
            ToiStatus::NoImpact);
  // passing by, turning (min alpha* = 2.98 by sampling; the helix of the screw
  // motion swings towards body 1, with y = 1.5 it hits)
  const ToiResult r = time_of_impact(a, e, Pose{rot_z(0.3), {-2.0, 3.0, 0.0}}, Pose{rot_z(2.0), {2.0, 3.0, 0.1}});
  EXPECT_EQ(r.status, ToiStatus::NoImpact);
  EXPECT_EQ(r.t_free, 1.0);
  // standing still
  EXPECT_EQ(time_of_impact(a, e, translation({1.0, 0.0, 0.0}), translation({1.0, 0.0, 0.0})).status,
            ToiStatus::NoImpact);
}

/// dt*/d eta0 and dt*/d eta1 by central differences through the SE(3)
/// exponential (test_util's, not the library's).
void check_toi_derivatives(const Shape& b1, const Shape& b2, const Pose& X0, const Pose& X1) {
  ToiOptions opt;
  opt.solver.tolerance = 1e-13;
  opt.alpha_tolerance = 1e-12;
  opt.t_tolerance = 1e-13;
  const ToiResult r = time_of_impact(b1, b2, X0, X1, opt);
  ASSERT_EQ(r.status, ToiStatus::Impact);
  ASSERT_TRUE(r.has_derivatives);
  const double h = 1e-5;
  for (int end = 0; end < 2; ++end) {
    for (int i = 0; i < 6; ++i) {
      Vec6 e = Vec6::Zero();
      e[i] = h;
      auto perturbed = [&](double sgn) {
        const Pose E = test::se3_exp(sgn * e.head<3>(), sgn * e.tail<3>());
        const ToiResult q = end == 0 ? time_of_impact(b1, b2, X0 * E, X1, opt) : time_of_impact(b1, b2, X0, X1 * E, opt);
        EXPECT_EQ(q.status, ToiStatus::Impact);
        return q.t;
      };
      const double fd = (perturbed(1.0) - perturbed(-1.0)) / (2.0 * h);
      const double ift = end == 0 ? r.dt_dX0[i] : r.dt_dX1[i];
      EXPECT_NEAR(ift, fd, 1e-5 * std::max(1.0, std::abs(fd))) << "end " << end << " component " << i;
    }
  }
}

TEST(Toi, DerivativesMatchFiniteDifferences) {
  check_toi_derivatives(Sphere(0.3), Sphere(0.2), translation({-2.0, 0.1, 0.05}), translation({2.0, -0.1, 0.2}));
  std::mt19937_64 rng(3);
  const Pose X0{test::random_rotation(rng), Vec3(-1.5, 0.2, 0.1)}, X1{test::random_rotation(rng), Vec3(1.0, -0.1, 0.3)};
  check_toi_derivatives(Sphere(0.25), Superellipsoid(0.8, 0.3, 0.2, 1.0), X0, X1);
  check_toi_derivatives(test::box(0.5, 0.4, 0.3, 20.0), Superellipsoid(0.5, 0.3, 0.2, 2.0), X0, X1);
}

TEST(Toi, ScrewMotionIsExactForTranslationsAndInvertsTheLog) {
  std::mt19937_64 rng(5);
  for (int k = 0; k < 20; ++k) {
    const Pose X{test::random_rotation(rng), test::random_unit(rng) * 3.0};
    const Pose Y = se3_exp(se3_log(X));
    EXPECT_LT((Y.R - X.R).norm(), 1e-12);
    EXPECT_LT((Y.p - X.p).norm(), 1e-12);
  }
  const Pose A{test::random_rotation(rng), Vec3(1, 2, 3)}, B{A.R, Vec3(-1, 0.5, 7)};
  const Pose M = screw_interpolate(A, B, 0.3);
  EXPECT_TRUE(M.R == A.R);
  EXPECT_TRUE(M.p == A.p + 0.3 * (B.p - A.p));
}

TEST(Toi, BadInputIsRejectedByName) {
  const Sphere a(0.3), b(0.2);
  Pose nan_pose = translation({1.0, 0.0, 0.0});
  nan_pose.R(1, 2) = std::nan("");
  try {
    time_of_impact(a, b, nan_pose, translation({2.0, 0.0, 0.0}));
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("X0_12.R(1,2) = nan"), std::string::npos) << e.what();
  }
  Pose inf_pose = translation({1.0, 0.0, std::numeric_limits<double>::infinity()});
  try {
    time_of_impact(a, b, translation({2.0, 0.0, 0.0}), inf_pose);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("X1_12.p[2] = inf"), std::string::npos) << e.what();
  }
  try {
    time_of_impact(a, b, translation({-1e308, 0.0, 0.0}), translation({1.7e308, 0.0, 0.0}));
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("leaves the double range"), std::string::npos) << e.what();
  }
  // a displacement near the double range is still a motion: answered, not thrown
  const ToiResult huge = time_of_impact(a, b, translation({-8e307, 1e300, 0.0}), translation({8e307, 1e300, 0.0}));
  EXPECT_EQ(huge.status, ToiStatus::NoImpact);
  // ... but passing at 1 from body 1, t cannot resolve the certified steps
  const ToiResult close = time_of_impact(a, b, translation({-8e307, 1.0, 0.0}), translation({8e307, 1.0, 0.0}));
  EXPECT_EQ(close.status, ToiStatus::NumericalFailure);
  EXPECT_EQ(close.t_free, 0.5);
  const ToiResult huge_hit = time_of_impact(a, b, translation({-8e307, 0.1, 0.0}), translation({8e307, 0.1, 0.0}));
  EXPECT_EQ(huge_hit.status, ToiStatus::Impact);
  EXPECT_NEAR(huge_hit.t, 0.5, 1e-15);
  Pose skewed = translation({1.0, 0.0, 0.0});
  skewed.R(0, 1) = 0.1;
  EXPECT_THROW(time_of_impact(a, b, skewed, translation({2.0, 0.0, 0.0})), std::invalid_argument);
  ToiOptions bad;
  bad.t_tolerance = 0.0;
  try {
    time_of_impact(a, b, translation({1.0, 0.0, 0.0}), translation({2.0, 0.0, 0.0}), bad);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("t_tolerance"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace idcol
