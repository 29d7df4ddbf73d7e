// DCOL, the method iDCOL builds on, as a C++ baseline.
//
// Tracy, Howell and Manchester, "Differentiable Collision Detection for a Set
// of Convex Primitives" (ICRA 2023, arXiv 2207.00669), whose reference is the
// MIT-licensed Julia package DifferentiableCollisions.jl. This is this
// project's own C++ written from the paper's formulation; the Julia code was
// read for its conventions (quaternions scalar first, the primitives' axes
// and parameters, `pdip_tol`) and its iteration counts.
//
// The problem (eq:DCOL of the iDCOL paper): the smallest uniform scaling
// alpha of both bodies about their own origins at which they share a point x,
//
//     minimise alpha  subject to  x in S_1(alpha),  x in S_2(alpha),
//
// where each primitive's scaled set is a conic set in (x, alpha) and possibly
// extra variables (a capsule's point on its axis, a polygon's point in its
// plane): G z + s = h, s in K, K a product of one nonnegative orthant and at
// most one second-order cone per body. DCOL solves this cone program with a
// primal-dual interior-point method with Nesterov-Todd scaling and a
// Mehrotra predictor-corrector step (the one described by Vandenberghe for
// CVXOPT's coneqp), stopping when the duality measure s.z / degree falls
// below `pdip_tol`. alpha < 1: the bodies intersect; alpha > 1: separated.
//
// The primitives, each in its own body frame (origin at the body's centre of
// scaling, axis along body x where there is one):
//   Polytope  {y : A y <= b}, b > 0 (the origin strictly inside);
//   Polygon   a polygon {u in R^2 : A u <= b} in the body's xy-plane, padded
//             by a ball of radius R (a rounded plate);
//   Sphere    radius R;
//   Ellipsoid {y : y' P y <= 1}, P symmetric positive definite;
//   Capsule   the segment y = t e_x, |t| <= L/2, padded by radius R;
//   Cylinder  radius R, |y_x| <= L/2;
//   Cone      apex at y_x = -3H/4, base of radius H tan(beta) at y_x = H/4
//             (the origin at the centroid), half-angle beta.
//
// Fixed sizes, no heap: a query builds its G and h on the stack. The number
// of nonnegative rows is a template parameter of the interior-point kernel
// (every pair of primitives whose rows are known at compile time, and
// polytope pairs of up to kMaxStaticOrtRows half-spaces together); larger
// polytopes run the same kernel with rows counted at run time in storage of
// capacity kMaxOrtRows. Nothing here includes core: it is a competitor.
#pragma once

#include <string>
#include <variant>

#include <Eigen/Core>

namespace idcol::baselines::dcol {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
/// A quaternion scalar first, (w, x, y, z), as DCOL's state; it need not be
/// unit: the rotation is that of q / |q| (DCOL normalises it too).
using Quat = Eigen::Vector4d;

/// Nonnegative rows (half-spaces and a polygon's edges, of both bodies
/// together) a query can take; more is refused when the primitive is built.
inline constexpr int kMaxOrtRows = 256;
/// Up to this many nonnegative rows, the kernel is compiled for the exact count.
inline constexpr int kMaxStaticOrtRows = 16;

struct Polytope {
  Eigen::Matrix<double, Eigen::Dynamic, 3> A;  // rows a_i, any length
  Eigen::VectorXd b;                           // b_i > 0
};
struct Polygon {
  Eigen::Matrix<double, Eigen::Dynamic, 2> A;  // in the body's (y_x, y_y) plane
  Eigen::VectorXd b;                           // b_i > 0
  double R = 0.0;                              // padding radius, > 0
};
struct Sphere { double R = 1.0; };
struct Ellipsoid {
  Mat3 P = Mat3::Identity();  // y' P y <= 1
  Mat3 U = Mat3::Identity();  // upper Cholesky factor, P = U' U (set by make_ellipsoid)
};
struct Capsule { double R = 1.0, L = 1.0; };
struct Cylinder { double R = 1.0, L = 1.0; };
struct Cone { double H = 1.0, beta = 0.5; };

using Primitive = std::variant<Polytope, Polygon, Sphere, Ellipsoid, Capsule, Cylinder, Cone>;

/// Validated constructors: each throws std::invalid_argument naming the
/// field and the value (a non-finite entry, a radius or length <= 0, an
/// offset b_i <= 0 so that the origin is not strictly inside, a zero row, a
/// P not symmetric positive definite, a half-angle outside (0, pi/2), more
/// than kMaxOrtRows rows).
Polytope make_polytope(const Eigen::Matrix<double, Eigen::Dynamic, 3>& A, const Eigen::VectorXd& b);
Polygon make_polygon(const Eigen::Matrix<double, Eigen::Dynamic, 2>& A, const Eigen::VectorXd& b, double R);
Sphere make_sphere(double R);
Ellipsoid make_ellipsoid(const Mat3& P);
/// The ellipsoid of semi-axes (a, b, c) along body x, y, z: P = diag(1/a^2, 1/b^2, 1/c^2).
Ellipsoid make_ellipsoid_axes(double a, double b, double c);
Capsule make_capsule(double R, double L);
Cylinder make_cylinder(double R, double L);
Cone make_cone(double H, double beta);
/// Throws as the constructors do if `p` (built by hand) is not valid.
void validate(const Primitive& p);
/// "polytope(8 half-spaces)", "ellipsoid", ...
std::string describe(const Primitive& p);

/// A body's pose: world position of its origin and its attitude, world from
/// body (DCOL's r and q).
struct Pose {
  Vec3 r = Vec3::Zero();
  Quat q = Quat(1.0, 0.0, 0.0, 0.0);
};
/// The rotation of q / |q| (world from body).
Mat3 rotation(const Quat& q);

struct Options {
  /// DCOL's stopping rule: the duality measure s.z / degree below this
  /// (proximity's default in DCOL, 1e-6).
  double pdip_tol = 1e-6;
  /// Interior-point iterations before giving up (DCOL: 50).
  int max_iterations = 50;
};

enum class Status {
  Converged,       // s.z / degree < pdip_tol
  IterationLimit,  // max_iterations steps without meeting it (DCOL throws "pdip failed")
  NumericalFailure // a normal-equation factorisation failed, or a non-finite iterate
};
const char* to_string(Status s);

/// What `proximity` returns (DCOL's `proximity`: alpha and x), with the
/// iteration count and the final duality measure.
struct Result {
  Status status = Status::NumericalFailure;
  double alpha = 0.0;      // the optimal scaling; < 1 intersecting
  Vec3 x = Vec3::Zero();   // the intersection point of the scaled bodies (world)
  int iterations = 0;      // interior-point steps taken
  double mu = 0.0;         // s.z / degree at exit
  /// s.z at exit, the duality gap: for a feasible iterate alpha exceeds the
  /// optimum by at most this much, so it measures what pdip_tol buys (alpha
  /// is within about gap of alpha*, not within pdip_tol of it).
  double gap = 0.0;
  bool converged() const { return status == Status::Converged; }
};

/// DCOL's proximity: alpha and x for bodies p1 at X1 and p2 at X2.
Result proximity(const Primitive& p1, const Pose& X1, const Primitive& p2, const Pose& X2, const Options& opt = {});
/// The same with attitudes as rotation matrices (world from body), which a
/// C++ caller usually has; no quaternion is formed.
Result proximity(const Primitive& p1, const Vec3& r1, const Mat3& Q1, const Primitive& p2, const Vec3& r2, const Mat3& Q2,
                 const Options& opt = {});

/// d alpha / d state, DCOL's proximity_gradient: the derivative of the
/// optimal value of the cone program with respect to its parameters, which
/// by the envelope theorem is that of the Lagrangian's constraint part
/// z' (G(theta) x - h(theta)) at the primal-dual solution (x, z), taken
/// here in closed form for each primitive.
struct Gradient {
  Result result;
  /// With respect to (r1, q1, r2, q2) as DCOL orders its 14 entries; the
  /// quaternion parts are orthogonal to q (q enters through q / |q|).
  Eigen::Matrix<double, 14, 1> dalpha_dstate = Eigen::Matrix<double, 14, 1>::Zero();
  /// With respect to each body's body-frame twist (angular part first,
  /// r -> r + Q v, Q -> Q (I + [w]x)), iDCOL's convention: rows 0-5 body 1,
  /// 6-11 body 2.
  Eigen::Matrix<double, 12, 1> dalpha_dxi = Eigen::Matrix<double, 12, 1>::Zero();
};
/// Zero gradients unless the result converged.
Gradient proximity_gradient(const Primitive& p1, const Pose& X1, const Primitive& p2, const Pose& X2, const Options& opt = {});
Gradient proximity_gradient(const Primitive& p1, const Vec3& r1, const Mat3& Q1, const Primitive& p2, const Vec3& r2,
                            const Mat3& Q2, const Options& opt = {});

}  // namespace idcol::baselines::dcol
