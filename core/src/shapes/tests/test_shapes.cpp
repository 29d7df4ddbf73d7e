// Shape families against finite differences, closed-form radii and
// validation. The oracles here are central differences of phi itself and
// bisection along rays, which share no code with the analytic derivatives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>

#include "idcol/convex_hull.hpp"
#include "idcol/detail/fast_math.hpp"
#include "idcol/families.hpp"
#include "idcol/shape_params.hpp"
#include "idcol/shapes.hpp"
#include "test_util.hpp"

using namespace idcol;
using idcol::test::catalogue;

namespace {

double phi_at(const Shape& s, const Vec3& y) {
  ShapeEval e;
  eval(s, y, e);
  return e.phi;
}
Vec3 grad_at(const Shape& s, const Vec3& y) {
  ShapeEval e;
  eval(s, y, e);
  return e.grad;
}

/// Distance from the origin to the boundary along u, by bisection on phi.
double boundary_along(const Shape& s, const Vec3& u) {
  double lo = 0.0, hi = 1.0;
  while (phi_at(s, hi * u) < 0.0) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (phi_at(s, mid * u) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Points near the surface, far outside and deep inside, avoiding the
/// coordinate planes and exactly representable values.
std::vector<Vec3> probe_points(const Shape& s, std::mt19937_64& rng) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 40; ++i) {
    const Vec3 u = test::random_unit(rng);
    const double rho = boundary_along(s, u);
    for (double f : {0.31, 0.93, 0.9991, 1.0007, 1.13, 3.7, 41.0}) pts.push_back(f * rho * u);
  }
  return pts;
}

}  // namespace

TEST(Shapes, GradientAndHessianMatchCentralDifferences) {
  std::mt19937_64 rng(7);
  for (const auto& [name, s] : catalogue()) {
    for (const Vec3& y : probe_points(s, rng)) {
      ShapeEval e;
      eval(s, y, e);
      // Central differences err by O(h^2 / l^2) relative, l the local length
      // scale of phi (down to ~0.1 for the cone near its apex), plus rounding
      // O(eps |phi| / h). h = 2e-6 max(1, |y|) keeps both under ~1e-7
      // relative on every probe point; the bounds below leave a 10x margin.
      const double h = 2e-6 * std::max(1.0, y.norm());
      Vec3 g_fd;
      Mat3 H_fd;
      for (int k = 0; k < 3; ++k) {
        Vec3 dy = Vec3::Zero();
        dy[k] = h;
        g_fd[k] = (phi_at(s, y + dy) - phi_at(s, y - dy)) / (2 * h);
        H_fd.col(k) = (grad_at(s, y + dy) - grad_at(s, y - dy)) / (2 * h);
      }
      const double gs = std::max(e.grad.norm(), 1e-3);
      const double Hs = std::max(e.hess.norm(), 1e-3);
      EXPECT_LT((e.grad - g_fd).norm(), 1e-6 * gs) << name << " y=" << y.transpose();
      EXPECT_LT((e.hess - H_fd).norm(), 1e-5 * Hs) << name << " y=" << y.transpose();
      EXPECT_LT((e.hess - e.hess.transpose()).norm(), 1e-12 * Hs) << name;
    }
  }
}

// The radii are certified against the independent support functions of the
// baselines' geometry (baselines/tests/test_oracles.cpp,
// CoreShapes.RadiiAreCertifiedBySupportFunctions): sampling directions
// underestimates a maximum, so it cannot certify an outer radius.
TEST(Shapes, RadiiArePositiveAndOrdered) {
  for (const auto& [name, s] : catalogue()) {
    const Radii r = radii(s);
    EXPECT_GT(r.inner, 0.0) << name;
    EXPECT_GE(r.outer, r.inner) << name;
  }
}

// support_point against the implicit function itself: for the
// superquadrics (at their own exponent and at another) a surface point whose
// normal is u; for every family a point that reaches support(u), the
// independent closed form, and that no boundary point found by bisection
// along a ray beats.
TEST(Shapes, SupportPointsReachTheSupportFunction) {
  std::mt19937_64 rng(11);
  for (const auto& [name, s] : catalogue()) {
    std::vector<Vec3> dirs = {Vec3::UnitX(), -Vec3::UnitY(), Vec3::UnitZ(), Vec3(1, 1, 0).normalized()};
    for (int i = 0; i < 200; ++i) dirs.push_back(test::random_unit(rng));
    std::vector<Vec3> boundary;
    for (int i = 0; i < 300; ++i) {
      const Vec3 v = test::random_unit(rng);
      boundary.push_back(boundary_along(s, v) * v);
    }
    for (const Vec3& u : dirs) {
      const double h = std::visit([&u](const auto& x) { return x.support(u); }, s);
      const Vec3 p = std::visit([&u](const auto& x) { return x.support_point(u, x.sharpness()); }, s);
      ASSERT_TRUE(p.allFinite()) << name;
      EXPECT_NEAR(u.dot(p), h, 1e-12 * radii(s).outer) << name << " u=" << u.transpose();
      for (const Vec3& y : boundary) EXPECT_LE(u.dot(y), u.dot(p) + 1e-12) << name;
      if (std::holds_alternative<SmoothPolytope>(s) || std::holds_alternative<SmoothTruncatedCone>(s)) continue;
      ShapeEval e;
      eval(s, p, e);
      EXPECT_NEAR(e.phi, 0.0, 1e-13) << name;
      EXPECT_GT(e.grad.normalized().dot(u), 1.0 - 1e-12) << name << " u=" << u.transpose();
    }
  }
  // At a sharpness other than the body's own (a continuation stage).
  const Superellipsoid se(0.5, 1.0, 1.5, 8.0);
  const SuperellipticCylinder sec(1.0, 2.0, 8.0);
  for (double n : {1.0, 2.0, 3.5}) {
    for (int i = 0; i < 50; ++i) {
      const Vec3 u = test::random_unit(rng);
      ShapeEval e;
      se.eval(se.support_point(u, n), n, e);
      EXPECT_NEAR(e.phi, 0.0, 1e-13);
      EXPECT_GT(e.grad.normalized().dot(u), 1.0 - 1e-12) << "n=" << n;
      sec.eval(sec.support_point(u, n), n, e);
      EXPECT_NEAR(e.phi, 0.0, 1e-13);
      EXPECT_GT(e.grad.normalized().dot(u), 1.0 - 1e-12) << "n=" << n;
    }
  }
}

TEST(Shapes, SuperquadricRadiiAreExact) {
  // inner = min axis along the axis; outer from the Hoelder conjugate, attained
  // at the direction where (y_i/a_i)^2 is proportional to a_i^(2/(n-1)).
  const Superellipsoid se(0.5, 1.0, 1.5, 8.0);
  EXPECT_NEAR(boundary_along(se, Vec3::UnitX()), se.radii().inner, 1e-12);
  const double q = 8.0 / 7.0;
  Vec3 u;
  for (int i = 0; i < 3; ++i) {
    const double a = (i == 0 ? 0.5 : i == 1 ? 1.0 : 1.5);
    u[i] = std::pow(a, q);  // the maximiser has y_i proportional to a_i^q, q = n/(n-1)
  }
  u.normalize();
  EXPECT_NEAR(boundary_along(se, u), se.radii().outer, 1e-9);
  const Superellipsoid ell(0.5, 1.0, 1.5, 1.0);
  EXPECT_DOUBLE_EQ(ell.radii().outer, 1.5);
  EXPECT_DOUBLE_EQ(ell.radii().inner, 0.5);
}

TEST(Shapes, EllipsoidIsExactForNEqualsOne) {
  const Superellipsoid e(0.7, 1.3, 2.1, 1.0);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Vec3 y = 3.0 * test::random_unit(rng) * std::abs(std::sin(i + 0.3));
    const double q = std::sqrt(std::pow(y.x() / 0.7, 2) + std::pow(y.y() / 1.3, 2) + std::pow(y.z() / 2.1, 2));
    EXPECT_NEAR(phi_at(e, y), q - 1.0, 1e-14 * std::max(1.0, q));
  }
}

TEST(Shapes, StaysFiniteFarOutsideAtHighExponentsAndSharpness) {
  const Superellipsoid se(0.5, 1.0, 1.5, 64.0);
  const SuperellipticCylinder sec(1.0, 2.0, 64.0);
  const SmoothPolytope poly = test::paper_poly(1e4);
  const SmoothTruncatedCone tc(1.0, 0.01, 1.5, 1.5, 1e4);
  for (double d : {1e3, 1e8, 1e100, 1e150, 1e300}) {
    for (const Vec3& u : {Vec3(0.3, -0.5, 0.81), Vec3(1, 0, 0), Vec3(0, 0, -1)}) {
      for (const Shape& s : {Shape(se), Shape(sec), Shape(poly), Shape(tc)}) {
        // The cone's side term r^2 / R^3 is documented to overflow past ~1e100.
        if (std::holds_alternative<SmoothTruncatedCone>(s) && d > 1e100) continue;
        ShapeEval e;
        eval(s, d * u, e);
        EXPECT_TRUE(std::isfinite(e.phi) && e.grad.allFinite() && e.hess.allFinite()) << family_name(s) << " d=" << d;
        EXPECT_GT(e.phi, 0.0);
      }
    }
  }
  // Homogeneous families grow linearly: phi(d u) + 1 = d (phi(u) + 1).
  EXPECT_NEAR((phi_at(se, 1e200 * Vec3(0.3, -0.5, 0.81)) + 1) / 1e200, phi_at(se, Vec3(0.3, -0.5, 0.81)) + 1, 1e-14);
}

TEST(Shapes, OriginIsHandledWithoutNaN) {
  for (const auto& [name, s] : catalogue()) {
    ShapeEval e;
    eval(s, Vec3::Zero(), e);
    EXPECT_LT(e.phi, 0.0) << name;
    EXPECT_TRUE(e.grad.allFinite() && e.hess.allFinite()) << name;
  }
}

// Points inside a body within the double range's underflow of its frame
// origin: subnormal coordinates (1e-320, 5e-324) and normal ones so close
// that the Hessian (of order (2n - 1)/(|y| a^2) for a superquadric) or the
// evaluation's 1/|y| overflows. phi is -1 in double there for the
// homogeneous families; eval answers finitely, as at the origin where it
// must, and wherever the solver's overload (the shape's own sharpness) gives
// a finite answer, eval gives the same bits: only what overflowed is
// replaced (the sphere excepted, whose |y| is taken exactly there).
TEST(Shapes, FiniteWithinTheUnderflowOfTheOrigin) {
  std::vector<test::Named> shapes = catalogue();
  shapes.push_back({"SE_thin", Superellipsoid(1e-3, 1.0, 1.5, 8.0)});
  shapes.push_back({"SE_big", Superellipsoid(1e3, 1e3, 1e3, 3.0)});
  shapes.push_back({"SE_n64", Superellipsoid(0.5, 1.0, 1.5, 64.0)});
  shapes.push_back({"SEC_thin", SuperellipticCylinder(1e-3, 2.0, 4.0)});
  std::vector<Vec3> dirs;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k)
        if (i || j || k) dirs.emplace_back(i, j, k);
  dirs.push_back(Vec3(1.0, 2.0, 3.0).normalized());
  dirs.push_back(Vec3(1.0, 1e-3, 0.0));
  int replaced = 0, kept = 0;
  for (const auto& [name, s] : shapes) {
    for (int decade = 280; decade <= 324; ++decade) {
      const double d = decade == 324 ? std::numeric_limits<double>::denorm_min() : std::pow(10.0, -decade);
      for (const Vec3& u : dirs) {
        const Vec3 y = d * u;
        ShapeEval e, solver;
        eval(s, y, e);
        std::visit([&](const auto& x) { x.eval(y, x.sharpness(), solver); }, s);
        ASSERT_TRUE(std::isfinite(e.phi) && e.grad.allFinite() && e.hess.allFinite())
            << name << " at " << y.transpose() << ": phi " << e.phi << ", grad " << e.grad.transpose() << ", hess "
            << e.hess.row(0);
        const bool homogeneous = std::visit([](const auto& x) { return std::decay_t<decltype(x)>::kHomogeneous; }, s);
        if (homogeneous) EXPECT_EQ(e.phi, -1.0) << name << " at " << y.transpose();
        const bool finite = std::isfinite(solver.phi) && solver.grad.allFinite() && solver.hess.allFinite();
        if (finite && !std::holds_alternative<Sphere>(s)) {
          EXPECT_TRUE(e.phi == solver.phi && e.grad == solver.grad && e.hess == solver.hess)
              << name << " at " << y.transpose();
          ++kept;
        } else {
          ++replaced;
        }
      }
    }
  }
  EXPECT_GT(replaced, 1000);
  EXPECT_GT(kept, 1000);
}

// A sphere's evaluation from its norm, where |y|^2 is not a normal double:
// |y| from 1e-300 (its square zero) or 1e-161 (its square subnormal, three
// digits) to 1e300 (its square infinite) gives phi, a unit gradient times
// 1/R and a finite Hessian with u in its null space, to rounding.
TEST(Shapes, SphereIsExactWhereTheSquaredNormIsNot) {
  const Sphere s(0.8);
  for (double d : {1e-300, 1e-200, 1e-161, 1e-155, 1e160, 1e200, 1e300}) {
    for (const Vec3& u : {Vec3(1.0, 2.0, 3.0).normalized(), Vec3(0.0, 0.0, -1.0), Vec3(0.6, 0.8, 0.0)}) {
      ShapeEval e;
      s.eval(d * u, e);
      if (d < 1.0)
        EXPECT_EQ(e.phi, -1.0) << d;
      else
        EXPECT_NEAR((e.phi + 1.0) / d, 1.0 / 0.8, 1e-15 / 0.8) << d;
      EXPECT_NEAR(e.grad.norm(), 1.0 / 0.8, 1e-15) << d;
      EXPECT_NEAR((e.grad * 0.8 - u).norm(), 0.0, 1e-15) << d;
      EXPECT_TRUE(e.hess.allFinite()) << d;
      if (d <= 1e-200) EXPECT_NEAR((e.hess * u).norm(), 0.0, 1e-15 * e.hess.norm());
    }
  }
}

TEST(Shapes, SmoothPolytopeIsBracketedByExactPolytope) {
  // Inside P, and contains (1 - L log m / (beta b_min)) P.
  const SmoothPolytope p = test::paper_poly(20.0);
  const double kappa = std::log(8.0) / (20.0 * (1.0 / std::sqrt(3.0)));
  std::mt19937_64 rng(5);
  for (int i = 0; i < 500; ++i) {
    const Vec3 u = test::random_unit(rng);
    double exact = 1e300;  // ray to the exact boundary
    for (int j = 0; j < p.num_halfspaces(); ++j) {
      const double d = p.normal(j).dot(u);
      if (d > 0) exact = std::min(exact, p.offset(j) / d);
    }
    const double smooth = boundary_along(p, u);
    EXPECT_LE(smooth, exact * (1 + 1e-12));
    EXPECT_GE(smooth, (1 - kappa) * exact * (1 - 1e-12));
  }
}

TEST(Shapes, PolytopeFromVerticesMergesCoplanarFaces) {
  std::vector<Vec3> V;
  for (int i = 0; i < 8; ++i) V.emplace_back(i & 1 ? 0.7 : -0.7, i & 2 ? 0.4 : -0.4, i & 4 ? 1.1 : -1.1);
  V.emplace_back(0.1, 0.05, -0.2);  // interior point, not a vertex
  V.emplace_back(0.7, 0.0, 0.3);    // on a face, not a vertex
  const SmoothPolytope p = SmoothPolytope::from_vertices(V, 30.0);
  EXPECT_EQ(p.num_halfspaces(), 6);
  EXPECT_EQ(p.vertices().size(), 8u);
  EXPECT_NEAR(p.radii().outer, std::sqrt(0.49 + 0.16 + 1.21), 1e-12);
  // Same shape from half-spaces.
  const SmoothPolytope q = test::box(0.7, 0.4, 1.1, 30.0);
  std::mt19937_64 rng(9);
  for (int i = 0; i < 50; ++i) {
    const Vec3 y = 1.5 * test::random_unit(rng);
    EXPECT_NEAR(phi_at(p, y), phi_at(q, y), 1e-12);
  }
}

TEST(Shapes, ManyFacetPolytopeFromVertices) {
  std::mt19937_64 rng(13);
  std::vector<Vec3> V;
  for (int i = 0; i < 500; ++i) V.push_back(test::random_unit(rng));
  const SmoothPolytope p = SmoothPolytope::from_vertices(V, 200.0);
  EXPECT_GT(p.num_halfspaces(), 200);
  EXPECT_NEAR(p.radii().outer, 1.0, 1e-12);
  EXPECT_GT(p.radii().inner, 0.8);
}

// ------------------------------------------------------------ convex hull

namespace {

/// The hull's claims checked by brute force, sharing nothing with it: every
/// point on or below every face plane (to `tol`), every corner on its
/// face's plane, corners counter-clockwise about the normal with no three in
/// line, and V - E + F = 2. Returns the number of distinct corners.
std::size_t check_hull(const std::vector<Vec3>& P, const ConvexHull& h, double tol) {
  std::vector<char> corner(P.size(), 0);
  std::size_t edges2 = 0;
  for (const HullFace& f : h.faces) {
    EXPECT_NEAR(f.normal.norm(), 1.0, 1e-12);
    for (std::size_t i = 0; i < P.size(); ++i) EXPECT_LE(f.normal.dot(P[i]) - f.offset, tol) << "point " << i;
    const std::size_t m = f.vertices.size();
    EXPECT_GE(m, 3u);
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3 &a = P[f.vertices[k]], &b = P[f.vertices[(k + 1) % m]], &c = P[f.vertices[(k + 2) % m]];
      EXPECT_NEAR(f.normal.dot(a), f.offset, tol);
      EXPECT_GT((b - a).cross(c - b).dot(f.normal), 0.0) << "corners " << k << ".." << k + 2 << " not a left turn";
      corner[f.vertices[k]] = 1;
    }
    edges2 += m;
  }
  const std::size_t V = static_cast<std::size_t>(std::count(corner.begin(), corner.end(), 1));
  EXPECT_EQ(edges2 % 2, 0u);
  EXPECT_EQ(static_cast<long>(V) - static_cast<long>(edges2 / 2) + static_cast<long>(h.faces.size()), 2);
  return V;
}

std::vector<Vec3> fibonacci_points(int m) {
  std::vector<Vec3> v;
  const double g = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < m; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / m, r = std::sqrt(1.0 - z * z);
    v.emplace_back(r * std::cos(g * i), r * std::sin(g * i), z);
  }
  return v;
}

}  // namespace

TEST(ConvexHull, PointsOnASphereAreAllCornersOfTriangles) {
  // Fibonacci order is a spiral from pole to pole, the worst order for a
  // hull that inserts points as given.
  const std::vector<Vec3> P = fibonacci_points(3000);
  const ConvexHull h = convex_hull(P, "test");
  EXPECT_EQ(check_hull(P, h, 1e-12), P.size());
  EXPECT_EQ(h.faces.size(), 2 * P.size() - 4);
}

TEST(ConvexHull, CloudsLatticesAndRepeatsGiveTheirExactHulls) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g;
  std::vector<Vec3> cloud;
  for (int i = 0; i < 4000; ++i) cloud.emplace_back(g(rng), g(rng), 0.01 * g(rng));  // a flat cloud
  check_hull(cloud, convex_hull(cloud, "cloud"), 1e-12);

  // A 12^3 lattice, shuffled: coplanar and collinear points everywhere; the
  // cube's 8 corners and 6 faces only.
  std::vector<Vec3> lattice;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      for (int k = 0; k < 12; ++k) lattice.emplace_back(0.1 * i - 0.3, 0.2 * j - 1.0, 0.05 * k);
  std::shuffle(lattice.begin(), lattice.end(), rng);
  const ConvexHull cube = convex_hull(lattice, "lattice");
  EXPECT_EQ(check_hull(lattice, cube, 1e-12), 8u);
  EXPECT_EQ(cube.faces.size(), 6u);

  // Every point three times over, and each scaled by 1 + 1e-13 (inside the
  // hull's tolerance): a 400-gon prism, with faces of 400 corners.
  std::vector<Vec3> prism;
  for (int r = 0; r < 3; ++r)
    for (int i = 0; i < 400; ++i) {
      const double a = 2.0 * M_PI * i / 400, s = r == 2 ? 1.0 + 1e-13 : 1.0;
      prism.emplace_back(s * std::cos(a), s * std::sin(a), 1.0);
      prism.emplace_back(s * std::cos(a), s * std::sin(a), -1.0);
    }
  const ConvexHull p = convex_hull(prism, "prism");
  EXPECT_EQ(check_hull(prism, p, 1e-12), 800u);
  EXPECT_EQ(p.faces.size(), 402u);
}

TEST(ConvexHull, OutputDependsOnlyOnThePointsNotTheirOrder) {
  std::mt19937_64 rng(4);
  std::vector<Vec3> P = fibonacci_points(500);
  for (int i = 0; i < 200; ++i) P.push_back(0.9 * test::random_unit(rng));  // inside
  const ConvexHull a = convex_hull(P, "a");
  std::vector<int> perm(P.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<Vec3> Q(P.size());
  for (std::size_t i = 0; i < P.size(); ++i) Q[i] = P[perm[i]];  // Q[i] is P[perm[i]]
  const ConvexHull b = convex_hull(Q, "b");
  ASSERT_EQ(a.faces.size(), b.faces.size());
  auto canonical = [](std::vector<int> v) {
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
    return v;
  };
  std::vector<std::vector<int>> fa, fb;
  for (const HullFace& f : a.faces) fa.push_back(f.vertices);
  for (const HullFace& f : b.faces) {
    std::vector<int> v;
    for (int i : f.vertices) v.push_back(perm[i]);
    fb.push_back(canonical(v));
  }
  std::sort(fb.begin(), fb.end());
  EXPECT_EQ(fa, fb);
}

// ----------------------------------------------------------- validation

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Shapes, RejectsBadParametersNamingFieldAndValue) {
  const double nan = std::nan(""), inf = INFINITY;
  EXPECT_NE(error_of([] { (void)Sphere(0.0); }).find("'R'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Sphere(-2.0); }).find("-2"), std::string::npos);
  EXPECT_NE(error_of([&] { (void)Sphere(nan); }).find("nan"), std::string::npos);
  EXPECT_NE(error_of([&] { (void)Superellipsoid(1, inf, 1, 2); }).find("'b'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)Superellipsoid(1, 1, 1, 0.5); }).find("'n'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SuperellipticCylinder(1, -1, 2); }).find("'h'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SuperellipticCylinder(1, 1, 0.99); }).find("0.98999"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothTruncatedCone(1, 1, 1, 1, 1.0); }).find("'beta'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothTruncatedCone(1, 0, 1, 1, 10.0); }).find("'Rt'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)test::box(1, 1, 1, 0.0); }).find("'beta'"), std::string::npos);
  EXPECT_NE(error_of([] { (void)test::box(1, 1, 1, -3.0); }).find("-3"), std::string::npos);
}

// Each family's declaration (families.hpp) is the class's: its name, its
// scalar parameters in the constructor's order (shape_params, param_names),
// and each range's edge, where the constructor refuses the value and names
// the field. The edges are written here from the paper's definitions, not
// read from the table.
TEST(Families, TheTableIsEachClasssDeclaration) {
  const auto& all = shape_families();
  ASSERT_EQ(all.size(), std::variant_size_v<Shape>);
  const std::map<std::string, std::pair<double, bool>> edge = {
      {"R", {0.0, true}},  {"a", {0.0, true}},  {"b", {0.0, true}},  {"c", {0.0, true}}, {"h", {0.0, true}},
      {"Rb", {0.0, true}}, {"Rt", {0.0, true}}, {"n", {1.0, false}}, {"L", {0.0, true}}, {"beta", {0.0, true}}};
  int scalar_families = 0;
  for (const FamilyInfo& f : all) {
    std::vector<double> theta;
    std::vector<std::string> keys;
    for (const FamilyParam* p : f.scalars()) {
      theta.push_back(p->example);
      keys.emplace_back(p->key);
      ASSERT_TRUE(edge.count(p->key)) << f.name << " " << p->key;
      EXPECT_EQ(p->lower, edge.at(p->key).first) << f.name << " " << p->key;
      EXPECT_EQ(p->lower_open, edge.at(p->key).second) << f.name << " " << p->key;
    }
    if (std::string(f.name) == SmoothPolytope::kName) {
      EXPECT_THROW(scalar_family_shape(f, theta.data()), std::invalid_argument);
      continue;
    }
    ++scalar_families;
    const Shape s = scalar_family_shape(f, theta.data());
    EXPECT_EQ(&family_info(s), &f);
    EXPECT_STREQ(family_name(s), f.name);
    EXPECT_EQ(param_names(s), keys);
    ASSERT_EQ(shape_params(s).size(), static_cast<Eigen::Index>(theta.size()));
    for (std::size_t i = 0; i < theta.size(); ++i) EXPECT_EQ(shape_params(s)[static_cast<Eigen::Index>(i)], theta[i]) << f.name;
    // Each parameter at its edge (or just below it) is refused, naming it.
    for (std::size_t i = 0; i < theta.size(); ++i) {
      std::vector<double> bad = theta;
      const auto [lo, open] = edge.at(keys[i]);
      bad[i] = open ? lo : std::nextafter(lo, -1.0);
      const std::string e = error_of([&] { (void)scalar_family_shape(f, bad.data()); });
      EXPECT_NE(e.find("field '" + keys[i] + "'"), std::string::npos) << f.name << ": " << e;
    }
  }
  EXPECT_EQ(scalar_families, 4);
}

TEST(Shapes, RejectsBadPolytopes) {
  // Origin outside (and, here, an empty polytope: x <= -1 and -x <= -1).
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {-1, -1, 1, 1, 1, 1}, 10); })
                .find("origin"),
            std::string::npos);
  // Unbounded: no half-space bounds +z.
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, -1}}, {1, 1, 1, 1, 1}, 10); }).find("unbounded"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {1, 1, 1}, 10); }).find("at least 4"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, 0, 0}}, {1, 1, 1, 1}, 10); }).find("zero"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {1, 1, 1, 1, 1, NAN}, 10); })
                .find("not finite"),
            std::string::npos);
  // Too little sharpness: the smooth body loses the origin.
  EXPECT_NE(error_of([] { (void)test::box(1, 1, 1, 1.5); }).find("too small"), std::string::npos);
  // Coplanar vertices have no interior.
  EXPECT_NE(error_of([] { SmoothPolytope::from_vertices({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, 10); }).find("coplanar"),
            std::string::npos);
  // Hull that does not hold the origin.
  EXPECT_NE(error_of([] { SmoothPolytope::from_vertices({{1, 0, 0}, {2, 0, 0}, {1, 1, 0}, {1, 0, 1}}, 10); }).find("origin"),
            std::string::npos);
}

TEST(Shapes, DescribeRoundTripsParametersAt17Digits) {
  const Superellipsoid s(0.1, 1.0 / 3.0, 2.0, 7.5);
  const std::string d = describe(s);
  EXPECT_NE(d.find("0.33333333333333331"), std::string::npos) << d;
  EXPECT_NE(d.find("superellipsoid"), std::string::npos);
}

TEST(Shapes, FastExpMatchesStdExpToAnUlp) {
  // detail::exp_nonpositive replaces std::exp in the LogSumExp families.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> wide(-708.0, 0.0), narrow(-1.0, 0.0);
  double worst = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double x = (i % 2) ? wide(rng) : narrow(rng);
    const double want = std::exp(x);
    worst = std::max(worst, std::abs(idcol::detail::exp_nonpositive(x) - want) / want);
  }
  EXPECT_LE(worst, 2.5e-16);
  EXPECT_EQ(idcol::detail::exp_nonpositive(0.0), 1.0);
  EXPECT_EQ(idcol::detail::exp_nonpositive(-800.0), 0.0);
  EXPECT_EQ(idcol::detail::exp_nonpositive(-INFINITY), 0.0);
}

// exp_any, log_positive, pow_unit and hypot_any replace glibc's calls where the
// batch lanes repeat the scalar solver's operations (alpha = e^s, the
// superquadric support point, the cylinder's radial distance). Oracles:
// glibc's own functions (correctly rounded or within about half an ulp).
TEST(Shapes, FastExpAnyMatchesStdExpOverTheWholeRange) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> wide(-708.0, 709.7), narrow(-1.0, 1.0), sub(-745.0, -708.0);
  double worst = 0.0, worst_sub = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double x = (i % 2) ? wide(rng) : narrow(rng);
    const double want = std::exp(x);
    worst = std::max(worst, std::abs(idcol::detail::exp_any(x) - want) / want);
    const double xs = sub(rng);  // subnormal results: within one subnormal step
    worst_sub = std::max(worst_sub, std::abs(idcol::detail::exp_any(xs) - std::exp(xs)));
  }
  EXPECT_LE(worst, 2.3e-16);
  EXPECT_LE(worst_sub, 2.0 * std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(idcol::detail::exp_any(0.0), 1.0);
  EXPECT_EQ(idcol::detail::exp_any(709.8), INFINITY);
  EXPECT_EQ(idcol::detail::exp_any(INFINITY), INFINITY);
  EXPECT_EQ(idcol::detail::exp_any(-746.0), 0.0);
  EXPECT_EQ(idcol::detail::exp_any(-INFINITY), 0.0);
  EXPECT_TRUE(std::isnan(idcol::detail::exp_any(NAN)));
}

TEST(Shapes, FastLogAndPowUnitMatchStdOverEveryBinade) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> binade(-1074.0, 1023.0), unit(0.0, 1.0), near1(0.5, 2.0);
  double worst_rel = 0.0, worst_abs = 0.0, worst_pow = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double x = (i % 3 == 0) ? std::exp2(binade(rng)) : (i % 3 == 1 ? unit(rng) : near1(rng));
    const double want = std::log(x), got = idcol::detail::log_positive(x);
    if (std::abs(want) > 0.1)
      worst_rel = std::max(worst_rel, std::abs(got - want) / std::abs(want));
    else
      worst_abs = std::max(worst_abs, std::abs(got - want));
    // t^k for the support point's exponents 1/(2n - 1): absolute error,
    // which bounds the point's own (its largest coordinate is 1).
    const double t = std::min(x, 1.0), k = 1.0 / (2.0 * (1 + i % 8) - 1.0);
    worst_pow = std::max(worst_pow, std::abs(idcol::detail::pow_unit(t, k) - std::pow(t, k)));
  }
  EXPECT_LE(worst_rel, 4e-16);
  EXPECT_LE(worst_abs, 3e-17);
  EXPECT_LE(worst_pow, 2.3e-16);
  EXPECT_EQ(idcol::detail::log_positive(1.0), 0.0);
  EXPECT_EQ(idcol::detail::log_positive(0.0), -INFINITY);
  EXPECT_EQ(idcol::detail::log_positive(INFINITY), INFINITY);
  EXPECT_TRUE(std::isnan(idcol::detail::log_positive(NAN)));
  EXPECT_EQ(idcol::detail::pow_unit(0.0, 1.0 / 3.0), 0.0);
  EXPECT_EQ(idcol::detail::pow_unit(1.0, 1.0 / 3.0), 1.0);
}

TEST(Shapes, FastHypotMatchesStdHypotWithoutOverflowOrUnderflow) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> binade(-1074.0, 1023.0), ratio(0.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double a = std::exp2(binade(rng)) * ((i & 1) ? -1.0 : 1.0);
    const double b = (i % 3 == 0) ? a * ratio(rng) : std::exp2(binade(rng));
    const double want = std::hypot(a, b);
    if (want >= std::numeric_limits<double>::min() && want < INFINITY)
      worst = std::max(worst, std::abs(idcol::detail::hypot_any(a, b) - want) / want);
  }
  EXPECT_LE(worst, 2.3e-16);
  EXPECT_EQ(idcol::detail::hypot_any(3.0, -4.0), 5.0);
  EXPECT_EQ(idcol::detail::hypot_any(1e308, 1e308), std::hypot(1e308, 1e308));
  EXPECT_EQ(idcol::detail::hypot_any(1e-310, 1e-310), std::hypot(1e-310, 1e-310));
  EXPECT_EQ(idcol::detail::hypot_any(0.0, 0.0), 0.0);
  EXPECT_EQ(idcol::detail::hypot_any(INFINITY, NAN), INFINITY);
  EXPECT_EQ(idcol::detail::hypot_any(NAN, -INFINITY), INFINITY);
  EXPECT_TRUE(std::isnan(idcol::detail::hypot_any(NAN, 1.0)));
}

namespace {

/// The smooth polytope's phi, grad and hess from their definition in long
/// double, sharing nothing with the face kernel: the LogSumExp smooth max
/// over all faces (no shift about the dominant normal, no padding, no
/// lanes), its softmax weights, and hess = sharp / L^2 (E[a a^T] - E[a] E[a]^T).
ShapeEval polytope_reference(const SmoothPolytope& p, const Vec3& y) {
  using LD = long double;
  const int m = p.num_halfspaces();
  const LD k = static_cast<LD>(p.beta()) / p.L();
  LD cmax = -INFINITY;
  auto c = [&](int i) {  // a_i.y - b_i in long double
    const Vec3 a = p.normal(i);
    return static_cast<LD>(a[0]) * y[0] + static_cast<LD>(a[1]) * y[1] + static_cast<LD>(a[2]) * y[2] - p.offset(i);
  };
  for (int i = 0; i < m; ++i) cmax = std::max(cmax, c(i));
  LD s0 = 0, s1[3] = {0, 0, 0}, s2[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  for (int i = 0; i < m; ++i) {
    const Vec3 a = p.normal(i);
    const LD w = std::exp(k * (c(i) - cmax));
    s0 += w;
    for (int r = 0; r < 3; ++r) {
      s1[r] += w * a[r];
      for (int c = 0; c < 3; ++c) s2[r][c] += w * a[r] * a[c];
    }
  }
  ShapeEval e;
  e.phi = static_cast<double>(cmax / p.L() + std::log(s0) / p.beta());
  for (int r = 0; r < 3; ++r) {
    e.grad[r] = static_cast<double>(s1[r] / s0 / p.L());
    for (int c = 0; c < 3; ++c)
      e.hess(r, c) = static_cast<double>(k / p.L() * (s2[r][c] / s0 - s1[r] / s0 * s1[c] / s0));
  }
  return e;
}

}  // namespace

TEST(Shapes, PolytopeFaceKernelMatchesItsDefinition) {
  // Face counts that fill whole groups of four (4, 8, 12, 16: the unrolled
  // kernels), that leave padding (6, 7) and that span several of the
  // general kernel's blocks of 64 faces; points
  // inside, near the surface and far away. The gradient's error is measured
  // in units of the normals' 1 / L (near the centre the weights spread and
  // grad = E[a] / L is a short sum of unit normals), the Hessian's in units
  // of its scale
  // beta / L^2: where one face dominates it is a small difference of such
  // terms (the reference's own, in long double, cancels there).
  std::mt19937_64 rng(21);
  std::vector<SmoothPolytope> P = {test::paper_poly(20.0), test::paper_poly(3000.0)};
  P.push_back(SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {1, 2, 0.5, 1.5, 1, 0.7}, 15.0, 0.5));
  P.push_back(SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 1, 1}}, {1, 1, 1, 1, 1, 1, 1.2}, 40.0));
  const double t = 1.0 / std::sqrt(3.0);  // a tetrahedron: 4 faces
  P.push_back(SmoothPolytope({{t, t, t}, {t, -t, -t}, {-t, t, -t}, {-t, -t, t}}, {0.5, 0.6, 0.7, 0.8}, 25.0));
  for (int n : {8, 10, 120}) {  // hulls of n points: 2 n - 4 triangles, 12, 16 and over 128 faces
    std::vector<Vec3> V;
    for (int i = 0; i < n; ++i) V.push_back(test::random_unit(rng));
    P.push_back(SmoothPolytope::from_vertices(V, 100.0));
  }
  ASSERT_GT(P.back().num_halfspaces(), 128);
  std::uniform_real_distribution<double> radius(0.0, 3.0);
  double worst_phi = 0.0, worst_grad = 0.0, worst_hess = 0.0;
  for (const SmoothPolytope& p : P)
    for (int t = 0; t < 400; ++t) {
      const Vec3 y = (t % 10 == 0 ? 100.0 : radius(rng)) * test::random_unit(rng);
      ShapeEval e, g;
      p.eval(y, e);
      const ShapeEval r = polytope_reference(p, y);
      worst_phi = std::max(worst_phi, std::abs(e.phi - r.phi) / std::max(1.0, std::abs(r.phi)));
      // The weights exp(k c_i) move by k |y| eps when the doubles c_i round:
      // that conditioning, not the kernel, bounds them far from the body.
      const double cond = std::max(1.0, p.beta() / p.L() * y.norm());
      worst_grad = std::max(worst_grad, (e.grad - r.grad).norm() * p.L() / cond);  // in units of the normals' 1 / L
      worst_hess = std::max(worst_hess, (e.hess - r.hess).norm() / (p.beta() / (p.L() * p.L())) / cond);
      p.eval_phi_grad(y, p.beta(), g);  // the kernel without the Hessian: the same phi and grad, bit for bit
      EXPECT_EQ(g.phi, e.phi);
      EXPECT_EQ(g.grad, e.grad);
    }
  EXPECT_LE(worst_phi, 1e-14);
  EXPECT_LE(worst_grad, 1e-14);
  EXPECT_LE(worst_hess, 1e-13);
  ShapeEval e;
  P[2].eval(Vec3(NAN, 0.0, 0.0), e);
  EXPECT_TRUE(std::isnan(e.phi) && e.grad.hasNaN() && e.hess.hasNaN());
  EXPECT_TRUE(std::string(idcol::detail::polytope_kernel_isa()) == "avx2" || std::string(idcol::detail::polytope_kernel_isa()) == "sse2");
}
