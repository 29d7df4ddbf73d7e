// Bad input end to end (issue 7): every field of every family with NaN,
// +-Inf, 0, negative and absurd values; empty, unbounded and off-origin
// polytopes; bad poses for every pair of families; every SolverOptions field.
// Each rejection must name the field and the value; a bad pose must come
// back as InvalidInput with no NaN anywhere in the result.
// (test_shapes.cpp and test_solver.cpp keep their single spot checks.)
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

/// The value as the library prints it (17 significant digits).
std::string text(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no std::invalid_argument thrown>";
}

/// Values no positive length (or sharpness) may take.
const std::vector<double>& bad_positive() {
  static const std::vector<double> v = {kNaN, kInf, -kInf, 0.0, -0.0, -1.0, -1e300, -std::numeric_limits<double>::denorm_min()};
  return v;
}

/// One constructor call with field `field` set to `v` and the rest valid.
struct Field {
  std::string family, field;
  std::function<void(double)> make;
};

std::vector<Field> positive_fields() {
  return {
      {"sphere", "R", [](double v) { (void)Sphere(v); }},
      {"superellipsoid", "a", [](double v) { (void)Superellipsoid(v, 1, 1, 2); }},
      {"superellipsoid", "b", [](double v) { (void)Superellipsoid(1, v, 1, 2); }},
      {"superellipsoid", "c", [](double v) { (void)Superellipsoid(1, 1, v, 2); }},
      {"superelliptic_cylinder", "R", [](double v) { (void)SuperellipticCylinder(v, 1, 2); }},
      {"superelliptic_cylinder", "h", [](double v) { (void)SuperellipticCylinder(1, v, 2); }},
      {"smooth_truncated_cone", "Rb", [](double v) { (void)SmoothTruncatedCone(v, 1, 1, 1, 10); }},
      {"smooth_truncated_cone", "Rt", [](double v) { (void)SmoothTruncatedCone(1, v, 1, 1, 10); }},
      {"smooth_truncated_cone", "a", [](double v) { (void)SmoothTruncatedCone(1, 1, v, 1, 10); }},
      {"smooth_truncated_cone", "b", [](double v) { (void)SmoothTruncatedCone(1, 1, 1, v, 10); }},
      {"smooth_truncated_cone", "beta", [](double v) { (void)SmoothTruncatedCone(1, 1, 1, 1, v); }},
      {"smooth_polytope", "beta", [](double v) { (void)test::box(1, 1, 1, v); }},
      {"smooth_polytope", "L", [](double v) {
         (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {1, 1, 1, 1, 1, 1}, 10, v);
       }},
      {"smooth_polytope", "beta", [](double v) { (void)SmoothPolytope::from_vertices({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, v); }},
      {"smooth_polytope", "L", [](double v) { (void)SmoothPolytope::from_vertices({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, 10, v); }},
  };
}

void expect_names(const std::string& err, const std::string& family, const std::string& field, double v) {
  EXPECT_NE(err.find(family), std::string::npos) << err;
  EXPECT_NE(err.find("'" + field + "'"), std::string::npos) << "field " << field << ": " << err;
  EXPECT_NE(err.find(text(v)), std::string::npos) << "value " << text(v) << ": " << err;
}

bool result_has_nan(const SolveResult& r) {
  return std::isnan(r.alpha) || r.x_1.hasNaN() || std::isnan(r.lambda1) || std::isnan(r.lambda2) || std::isnan(r.residual_norm);
}

}  // namespace

TEST(BadInput, EveryPositiveFieldRejectsNonFiniteZeroAndNegative) {
  for (const Field& f : positive_fields())
    for (double v : bad_positive()) {
      SCOPED_TRACE(f.family + "." + f.field + " = " + text(v));
      expect_names(error_of([&] { f.make(v); }), f.family, f.field, v);
    }
}

TEST(BadInput, SubnormalSizesAreRejectedAtConstruction) {
  for (const Field& f : positive_fields())
    for (double v : {std::numeric_limits<double>::denorm_min(), 1e-310}) {
      SCOPED_TRACE(f.family + "." + f.field + " = " + text(v));
      const std::string err = error_of([&] { f.make(v); });
      expect_names(err, f.family, f.field, v);
      EXPECT_NE(err.find("subnormal"), std::string::npos) << err;
    }
  // The smallest normal double is a size like any other.
  EXPECT_NO_THROW((void)Sphere(std::numeric_limits<double>::min()));
}

// Two ellipsoids of size 1e-5 at |r| = 7e-319: alpha* ~ 2e-314 is subnormal
// and keeps only ~30 bits. Reported Converged with a relative error of 1.4e-6
// before the check; it must come back as NumericalFailure, with no NaN.
TEST(BadInput, SubnormalAlphaIsNumericalFailureNotConverged) {
  const Shape a = Superellipsoid(2.1488626945561616e-05, 0.00012251199655457482, 0.00015073802489898257, 1);
  const Shape b = Superellipsoid(3.6598303216329179e-05, 1.6846712469135238e-05, 1.9790690423668786e-05, 1);
  Pose X;
  X.R << -0.82066936086335263, 0.24074107804969774, -0.51821379128657585,  //
      0.12032927590126852, 0.95938919333382122, 0.25513377094253153,       //
      0.55858989026047889, 0.14702417846649946, -0.81630951571388533;
  X.p << 7.1067390629096585e-319, 5.71930391625827e-320, 2.4898932287815461e-319;
  ASSERT_EQ(check_pose(X), PoseCheck::Ok);
  const SolveResult r = solve(a, b, X);
  EXPECT_EQ(r.status, SolveStatus::NumericalFailure) << to_string(r.status) << " alpha " << text(r.alpha);
  EXPECT_FALSE(result_has_nan(r));
  // The same pair 1e300 times farther apart is an ordinary, normal answer.
  X.p *= 1e300;
  EXPECT_TRUE(solve(a, b, X).converged());
}

TEST(BadInput, SuperquadricExponentBelowOneOrNonFinite) {
  // -Inf and -1e300 were undefined behaviour (a float-to-int cast in
  // detail::Exponent before validation ran; UBSan float-cast-overflow).
  for (double n : {kNaN, kInf, -kInf, 0.0, 0.999999, -1.0, -1e300, 1e-300}) {
    SCOPED_TRACE(text(n));
    expect_names(error_of([&] { (void)Superellipsoid(1, 1, 1, n); }), "superellipsoid", "n", n);
    expect_names(error_of([&] { (void)SuperellipticCylinder(1, 1, n); }), "superelliptic_cylinder", "n", n);
  }
}

TEST(BadInput, SharpnessTooSmallToHoldTheOrigin) {
  // Cone: beta must exceed log 3; polytope: sum exp(-beta b_i / L) < 1.
  for (double beta : {1e-300, 0.5, 1.0, std::log(3.0)}) {
    const std::string e = error_of([&] { (void)SmoothTruncatedCone(1, 1, 1, 1, beta); });
    expect_names(e, "smooth_truncated_cone", "beta", beta);
  }
  for (double beta : {1e-300, 1.0, 1.7}) expect_names(error_of([&] { (void)test::box(1, 1, 1, beta); }), "smooth_polytope", "beta", beta);
  // The same box with a huge L is as smooth as a tiny beta.
  const std::string e = error_of([] {
    (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}, {1, 1, 1, 1, 1, 1}, 10, 1e300);
  });
  EXPECT_NE(e.find("too small"), std::string::npos) << e;
}

TEST(BadInput, AbsurdButValidParametersConstructAndSolveWithoutNaN) {
  const std::vector<Shape> shapes = {
      Sphere(1e-300),
      Sphere(1e300),
      Superellipsoid(1e-150, 1e150, 1, 1),
      Superellipsoid(1, 1, 1, 1e300),  // a cube in the limit; non-integer fast path off
      Superellipsoid(1, 2, 3, 1024),
      Superellipsoid(1, 2, 3, 1025),
      SuperellipticCylinder(1e-100, 1e100, 3),
      SmoothTruncatedCone(1e-3, 1e3, 1, 1, 1e6),
      test::box(1e-3, 1, 1e3, 1e4),  // 1e-100 x 1e100 is rejected as unbounded (dual hull tolerance)
  };
  const Pose X{Eigen::AngleAxisd(0.7, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix(), Vec3(0.4, 1.1, -0.3)};
  int converged = 0;
  for (const Shape& a : shapes)
    for (const Shape& b : {Shape(Sphere(1.0)), Shape(test::paper_poly())}) {
      const SolveResult r = solve(a, b, X);
      SCOPED_TRACE(describe(a) + " vs " + describe(b) + ": " + to_string(r.status));
      // A failed solve may return a NaN iterate (README, Known limits), but
      // never a NaN status; only converged answers are checked, so count them.
      EXPECT_NE(r.status, SolveStatus::InvalidInput);
      if (r.converged()) {
        ++converged;
        EXPECT_FALSE(result_has_nan(r));
        EXPECT_TRUE(std::isfinite(r.alpha) && r.alpha > 0.0);
        EXPECT_TRUE(r.x_1.allFinite());
      }
    }
  std::printf("absurd but valid parameters: %d of %zu solves converged\n", converged, 2 * shapes.size());
  EXPECT_GE(converged, 7);  // measured: 7 of 18; fewer means a regression hidden by the skip
}

TEST(BadInput, PolytopeHalfSpacesNameTheFieldAndValue) {
  const std::vector<Vec3> A = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const std::vector<double> b(6, 1.0);
  // Non-finite offsets.
  for (double v : {kNaN, kInf, -kInf}) {
    std::vector<double> bb = b;
    bb[4] = v;
    const std::string e = error_of([&] { (void)SmoothPolytope(A, bb, 10); });
    EXPECT_NE(e.find("'b'[4]"), std::string::npos) << e;
    EXPECT_NE(e.find(text(v)), std::string::npos) << e;
  }
  // Non-finite normals: the row and its value.
  for (double v : {kNaN, kInf, -kInf}) {
    std::vector<Vec3> AA = A;
    AA[2].y() = v;
    const std::string e = error_of([&] { (void)SmoothPolytope(AA, b, 10); });
    EXPECT_NE(e.find("'A' row 2"), std::string::npos) << e;
    EXPECT_NE(e.find(text(v)), std::string::npos) << e;
  }
  // Zero and subnormal-zero rows.
  {
    std::vector<Vec3> AA = A;
    AA[5].setZero();
    EXPECT_NE(error_of([&] { (void)SmoothPolytope(AA, b, 10); }).find("'A' row 5 is zero"), std::string::npos);
  }
  // Size mismatch and too few half-spaces name both fields and counts.
  {
    const std::string e = error_of([&] { (void)SmoothPolytope(A, {1, 1, 1}, 10); });
    EXPECT_NE(e.find("'A' has 6"), std::string::npos) << e;
    EXPECT_NE(e.find("'b' has 3"), std::string::npos) << e;
    EXPECT_NE(error_of([] { (void)SmoothPolytope({}, {}, 10); }).find("got 0"), std::string::npos);
  }
  // Origin on the boundary (b = 0), outside (b < 0), and empty (x <= -1, -x <= -1).
  for (double v : {0.0, -0.5, -1e300}) {
    std::vector<double> bb = b;
    bb[1] = v;
    const std::string e = error_of([&] { (void)SmoothPolytope(A, bb, 10); });
    EXPECT_NE(e.find("origin"), std::string::npos) << e;
    EXPECT_NE(e.find(text(v)), std::string::npos) << e;
  }
  EXPECT_NE(error_of([&] { (void)SmoothPolytope(A, {-1, -1, 1, 1, 1, 1}, 10); }).find("empty"), std::string::npos);
  // Unbounded: all normals in one half-space; a slab; duplicated faces.
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}}, {1, 1, 1, 1}, 10); }).find("unbounded"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {-1, 0, 0}}, {1, 1, 2, 2}, 10); }).find("unbounded"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              (void)SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, 1}}, {1, 1, 1, 1, 1, 2}, 10);
            }).find("unbounded"),
            std::string::npos);
}

TEST(BadInput, PolytopeVertexListsNameTheProblem) {
  const std::vector<Vec3> tet = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  EXPECT_NE(error_of([] { (void)SmoothPolytope::from_vertices({}, 10); }).find("got 0"), std::string::npos);
  EXPECT_NE(error_of([&] { (void)SmoothPolytope::from_vertices({tet[0], tet[1], tet[2]}, 10); }).find("got 3"), std::string::npos);
  for (double v : {kNaN, kInf, -kInf}) {
    std::vector<Vec3> V = tet;
    V[3].z() = v;
    const std::string e = error_of([&] { (void)SmoothPolytope::from_vertices(V, 10); });
    EXPECT_NE(e.find("[3]"), std::string::npos) << e;
    EXPECT_NE(e.find(text(v)), std::string::npos) << e;
  }
  // All the same point, collinear, coplanar: no interior.
  EXPECT_NE(error_of([&] { (void)SmoothPolytope::from_vertices({tet[0], tet[0], tet[0], tet[0], tet[0]}, 10); }).find("coplanar"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothPolytope::from_vertices({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}, 10); }).find("coplanar"),
            std::string::npos);
  // Hull that misses the origin, and one that has it on a face.
  std::vector<Vec3> shifted = tet;
  for (Vec3& v : shifted) v.x() += 5.0;
  EXPECT_NE(error_of([&] { (void)SmoothPolytope::from_vertices(shifted, 10); }).find("origin"), std::string::npos);
  EXPECT_NE(error_of([] { (void)SmoothPolytope::from_vertices({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 10); }).find("origin"),
            std::string::npos);
}

TEST(BadInput, BadPosesGiveInvalidInputWithoutNaNForEveryPair) {
  const auto shapes = test::catalogue();
  const Mat3 R0 = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 p0(0.7, -0.2, 1.3);
  std::vector<std::pair<std::string, Pose>> bad;
  for (double v : {kNaN, kInf, -kInf}) {
    Pose X{R0, p0};
    X.p.y() = v;
    bad.push_back({"p.y = " + text(v), X});
    X = Pose{R0, p0};
    X.R(1, 2) = v;
    bad.push_back({"R(1,2) = " + text(v), X});
  }
  bad.push_back({"R scaled by 1 + 1e-6", Pose{R0 * (1.0 + 1e-6), p0}});
  bad.push_back({"R sheared", Pose{R0 + 1e-4 * Mat3::Ones(), p0}});
  bad.push_back({"R = 0", Pose{Mat3::Zero(), p0}});
  bad.push_back({"R = -R0 (det -1)", Pose{-R0, p0}});
  Mat3 mirror = R0;
  mirror.col(1) *= -1.0;
  bad.push_back({"one axis mirrored (det -1)", Pose{mirror, p0}});
  bad.push_back({"det -1 and r = 0", Pose{-Mat3::Identity(), Vec3::Zero()}});
  bad.push_back({"NaN pose with r = 0", Pose{Mat3::Constant(kNaN), Vec3::Zero()}});

  for (const auto& a : shapes)
    for (const auto& b : shapes)
      for (const auto& [what, X] : bad) {
        SCOPED_TRACE(a.name + " vs " + b.name + ", " + what);
        WarmStart warm;
        for (int pass = 0; pass < 2; ++pass) {  // cold, then with a (still invalid) warm start
          const SolveResult r = solve(a.shape, b.shape, X, {}, &warm);
          EXPECT_EQ(r.status, SolveStatus::InvalidInput) << to_string(r.status);
          EXPECT_FALSE(result_has_nan(r));
          EXPECT_FALSE(solution_sensitivity(r).valid);
          EXPECT_FALSE(contact_kinematics(r).valid);
        }
      }
}

TEST(BadInput, PoseToleranceEdgeIsOrthonormalToOneInABillion) {
  const Shape a = Sphere(1.0), b = Sphere(0.5);
  const Mat3 R0 = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  // |R^T R - I|_F ~ 2 sqrt(3) eps for R (1 + eps).
  EXPECT_TRUE(solve(a, b, Pose{R0 * (1.0 + 1e-11), Vec3(2, 0, 0)}).converged());
  EXPECT_EQ(solve(a, b, Pose{R0 * (1.0 + 1e-8), Vec3(2, 0, 0)}).status, SolveStatus::InvalidInput);
}

TEST(BadInput, EverySolverOptionsFieldHasItsOwnError) {
  struct Opt {
    const char* field;
    std::function<void(SolverOptions&, double)> set;
    std::vector<double> bad;
  };
  const std::vector<double> nonfinite = {kNaN, kInf, -kInf};
  auto with = [&](std::vector<double> v) {
    v.insert(v.end(), nonfinite.begin(), nonfinite.end());
    return v;
  };
  const std::vector<Opt> opts = {
      {"tolerance", [](SolverOptions& o, double v) { o.tolerance = v; }, with({0.0, -1e-10})},
      {"max_iterations", [](SolverOptions& o, double v) { o.max_iterations = static_cast<int>(v); }, {0, -5}},
      {"max_restarts", [](SolverOptions& o, double v) { o.max_restarts = static_cast<int>(v); }, {-1}},
      {"surrogate_factor", [](SolverOptions& o, double v) { o.surrogate_factor = v; }, with({0.999, 0.0, -2.0})},
      {"armijo_c", [](SolverOptions& o, double v) { o.armijo_c = v; }, with({0.0, 0.5, -1e-4})},
      {"backtrack_factor", [](SolverOptions& o, double v) { o.backtrack_factor = v; }, with({0.0, 1.0, 1.5})},
      {"max_backtracks", [](SolverOptions& o, double v) { o.max_backtracks = static_cast<int>(v); }, {-1}},
      {"max_step_s", [](SolverOptions& o, double v) { o.max_step_s = v; }, with({0.0, -1.0})},
      {"max_step_x", [](SolverOptions& o, double v) { o.max_step_x = v; }, with({0.0, -1.0})},
      {"lambda_fraction_to_boundary", [](SolverOptions& o, double v) { o.lambda_fraction_to_boundary = v; }, with({0.0, 1.0})},
      {"lambda_fraction_to_boundary_restart", [](SolverOptions& o, double v) { o.lambda_fraction_to_boundary_restart = v; },
       with({0.0, 1.0})},
      {"min_pivot_ratio", [](SolverOptions& o, double v) { o.min_pivot_ratio = v; }, with({-1e-13, 1.0})},
      {"lm_initial_damping", [](SolverOptions& o, double v) { o.lm_initial_damping = v; }, with({0.0, -1e-6})},
      {"lm_max_trials", [](SolverOptions& o, double v) { o.lm_max_trials = static_cast<int>(v); }, {0, -1}},
      {"lm_stall_limit", [](SolverOptions& o, double v) { o.lm_stall_limit = static_cast<int>(v); }, {-1}},
      {"lm_min_progress", [](SolverOptions& o, double v) { o.lm_min_progress = v; }, with({-1e-3, 1.0})},
      {"bound_margin", [](SolverOptions& o, double v) { o.bound_margin = v; }, with({-1e-3})},
      {"continuation_ratio", [](SolverOptions& o, double v) { o.continuation_ratio = v; }, with({1.0, 0.5})},
  };
  for (const Opt& f : opts)
    for (double v : f.bad) {
      SCOPED_TRACE(std::string(f.field) + " = " + text(v));
      SolverOptions o;
      f.set(o, v);
      const std::string e = error_of([&] { o.validate(); });
      EXPECT_NE(e.find(std::string("'") + f.field + "'"), std::string::npos) << e;
      EXPECT_NE(e.find(text(v)), std::string::npos) << e;
      // ContactPair validates at construction with the same message.
      EXPECT_EQ(error_of([&] { ContactPair p(Sphere(1), Sphere(1), o); }), e);
    }
  EXPECT_NO_THROW(SolverOptions{}.validate());
}
