// Independent geometry of iDCOL's shape families, written from the paper's
// formulas (Appendix A, app:shapes) and from closed forms, for the oracles
// and the checks that must not trust the solver. It includes nothing of core
// (`idcol/...`): its shape descriptions, phi, grad phi, exact bodies,
// vertices, support functions and gauges are its own. The one bridge from
// core's `idcol::Shape` is `core_adapter.hpp`, which reads public parameters
// only.
//
// Conventions (all in the body's own frame, origin strictly inside):
//  - phi(y) <= 0 is the body (the paper's implicit function);
//  - the exact body is the beta -> inf limit (polytope, truncated cone);
//    superellipsoids and superelliptic cylinders are their own exact bodies;
//  - h(u) = max_{y in K} u.y is the support function, s(u) a maximiser;
//  - g(y) = min{t >= 0 : y in t K} is the gauge (Minkowski functional), so
//    the body scaled by alpha about its origin is {y : g(y) <= alpha}.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace idcol::baselines::geom {

using Vec = Eigen::Vector3d;
using Mat = Eigen::Matrix3d;

/// Rigid transform X_12 = (R, p): body-2 coordinates to body-1 coordinates,
/// p = R y_2 + r. Converts from any type with public members R and p (core's
/// idcol::Pose among them) without naming it.
struct Pose {
  Mat R = Mat::Identity();
  Vec p = Vec::Zero();
  Pose() = default;
  Pose(const Mat& R_, const Vec& p_) : R(R_), p(p_) {}
  template <class X, class = decltype(std::declval<const X&>().R), class = decltype(std::declval<const X&>().p)>
  Pose(const X& x) : R(x.R), p(x.p) {}  // NOLINT: implicit on purpose, see above
};

// ---- shape descriptions (validated by the make_* functions) ----------------

/// phi = |y| / R - 1.
struct SphereDesc { double R = 1.0; };
/// phi = (sum (y_i/a_i)^(2n))^(1/2n) - 1; n = 1 is the ellipsoid.
struct SuperellipsoidDesc { double a = 1.0, b = 1.0, c = 1.0, n = 1.0; };
/// phi = ((y1/h)^(2n) + ((y2^2+y3^2)/R^2)^n)^(1/2n) - 1, axis y1.
struct CylinderDesc { double R = 1.0, h = 1.0, n = 1.0; };
/// phi = smax_beta((a_i.y - b_i)/L); rows normalised to |a_i| = 1.
struct PolytopeDesc {
  std::vector<Vec> normals;
  std::vector<double> offsets;
  double beta = 20.0, L = 1.0;
};
/// phi = smax_beta(r^2/R(y1)^2 - 1, -y1/a - 1, y1/b - 1),
/// R(y1) = Rb + (Rt - Rb)(y1 + a)/(a + b).
struct ConeDesc { double Rb = 1.0, Rt = 1.0, a = 1.0, b = 1.0, beta = 20.0; };

using Desc = std::variant<SphereDesc, SuperellipsoidDesc, CylinderDesc, PolytopeDesc, ConeDesc>;

/// Each throws std::invalid_argument naming the field and the value: every
/// number finite, lengths > 0, n >= 1, beta > 0 (cone: beta > log 3, so its
/// inner body is not empty; beta = +inf is the exact body), L > 0, at least 4 half-spaces, nonzero rows,
/// b_i > 0 after normalisation (origin strictly inside).
SphereDesc make_sphere(double R);
SuperellipsoidDesc make_superellipsoid(double a, double b, double c, double n);
CylinderDesc make_cylinder(double R, double h, double n);
PolytopeDesc make_polytope(const std::vector<Vec>& A, const std::vector<double>& b, double beta, double L = 1.0);
ConeDesc make_cone(double Rb, double Rt, double a, double b, double beta);
/// Re-checks a description built by hand (the same rules as make_*).
void validate(const Desc& d);
/// "superellipsoid(a=..., n=...)", for messages.
std::string describe(const Desc& d);

// ---- phi and grad phi --------------------------------------------------------

struct PhiGrad {
  long double phi = 0.0L;
  Vec grad = Vec::Zero();
};
/// phi and grad phi of the smooth body (the paper's, beta finite), evaluated
/// in long double from the formulas of app:shapes (smax with the max shifted
/// out, eq:smoothmax_grad; eq:phi_grad for the superquadrics, written with
/// ratios bounded by 1 so large n does not overflow).
PhiGrad eval(const Desc& d, const Vec& y);

// ---- exact bodies ------------------------------------------------------------

/// Exact convex polytope {a_i.y <= b_i} with its vertices and its faces
/// (vertex indices counter-clockwise seen from outside, one face per
/// non-redundant plane). Vertices are found by clipping each plane's face
/// polygon by every other half-space and then solving each corner from its
/// three planes; no convex hull is used.
struct PolyBody {
  std::vector<Vec> normals;
  std::vector<double> offsets;
  std::vector<Vec> vertices;
  std::vector<std::vector<int>> faces;
};
/// Throws std::invalid_argument if the half-spaces bound no polytope
/// (unbounded, or not containing the origin strictly).
PolyBody exact_polytope(const std::vector<Vec>& normals, const std::vector<double>& offsets);

/// Exact truncated cone (frustum), axis y1, radius Rb at y1 = -a, Rt at y1 = b;
/// Rb == Rt and a == b is the exact cylinder (the n -> inf limit of a
/// superelliptic cylinder of radius R = Rb, half-length h = a).
struct FrustumBody { double Rb = 1.0, Rt = 1.0, a = 1.0, b = 1.0; };

/// The box |y_i| <= h_i: the n -> inf limit of a superellipsoid of semi-axes h.
struct BoxBody { Vec h = Vec::Ones(); };

/// A convex body with a closed-form support function and gauge.
using Convex = std::variant<SphereDesc, SuperellipsoidDesc, CylinderDesc, PolyBody, FrustumBody, BoxBody>;

/// The smallest exact body holding the described body (the body itself for
/// sphere, superellipsoid and cylinder; P for a smooth polytope, the frustum
/// for a smooth cone: smax >= max, so phi <= 0 implies every term <= 0).
Convex outer_body(const Desc& d);
/// A closed-form body inside the described body (the body itself for the
/// homogeneous families). Smooth polytope: a_i.y <= b_i - L log(m)/beta;
/// smooth cone: every term <= -log(3)/beta, i.e. the frustum with
/// a' = a(1-e), b' = b(1-e), radius sqrt(1-e) R(y1), e = log 3 / beta
/// (smax <= max + log(m)/beta). has_inner is false when that set does not
/// hold the origin strictly (some b_i <= L log(m)/beta).
bool has_inner_body(const Desc& d);
Convex inner_body(const Desc& d);
/// Whether outer_body == inner_body (no smoothing gap).
bool is_exact(const Desc& d);
/// The body the family tends to as its sharpness grows (beta -> inf, or
/// n -> inf for the superquadrics), which the smoothing study measures the
/// smooth body against: P for a smooth polytope, the frustum for a smooth
/// cone, the box |y_i| <= a_i for a superellipsoid, the exact cylinder
/// (a FrustumBody with Rb = Rt = R, a = b = h) for a superelliptic cylinder.
/// Throws std::invalid_argument for a sphere, which has no sharpness.
Convex sharp_limit(const Desc& d);

/// Support function h(u) = max_{y in K} u.y (u need not be unit).
double support(const Convex& K, const Vec& u);
/// A maximiser s(u) of u.y over K (for a polytope, a vertex).
Vec support_point(const Convex& K, const Vec& u);
/// Gauge g(y) = min{t >= 0 : y in t K}.
double gauge(const Convex& K, const Vec& y);
/// Radial function rho(u) = sup{t >= 0 : t u in K} for a unit u (1 / g(u)),
/// written directly for the sharp bodies (box, frustum, polytope: the
/// smallest t at which t u meets a face).
double radial(const Convex& K, const Vec& u);
/// For y in K, its distance to K's boundary (0 outside), in closed form for
/// the bodies made of planes and cones of revolution (sphere, box, frustum,
/// polytope: the smallest distance to a face's plane or to the frustum's
/// side). Throws std::invalid_argument for the curved superquadrics
/// (superellipsoid, superelliptic cylinder), which have none.
double depth(const Convex& K, const Vec& y);
/// Whether distance() has a closed form for K: sphere, box and frustum.
bool has_distance(const Convex& K);
/// Euclidean distance from y to K (0 inside) where has_distance(K): the box
/// by clamping, the frustum (a solid of revolution) in y's meridian
/// half-plane, where it is the distance to a trapezoid. Throws
/// std::invalid_argument otherwise (a polytope needs the LP oracle).
double distance(const Convex& K, const Vec& y);
/// Unit directions from the origin to where a smooth body departs most from
/// K: a polytope's or box's vertices and edge midpoints, 64 points on each
/// rim circle of a frustum (or cylinder); none for a smooth body.
std::vector<Vec> feature_directions(const Convex& K);
/// "box (half-extents ...)", "cylinder (R ..., half-length ..., axis y1)",
/// "frustum (Rb ..., Rt ..., a ..., b ..., axis y1)", "exact polytope (m
/// half-spaces, v vertices)", numbers at 17 significant digits.
std::string describe(const Convex& K);

/// Certified radii of K: inner = min over unit u of h(u), computed in closed
/// form (sphere R, superellipsoid min axis, cylinder min(R, h), polytope
/// min b_i, frustum min(a, b, distance to the side line)); outer = max over
/// unit u of h(u) (max axis, hypot(R, h) for n = inf bound... see .cpp).
std::array<double, 2> radii(const Convex& K);

}  // namespace idcol::baselines::geom
