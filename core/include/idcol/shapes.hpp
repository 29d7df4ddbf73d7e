// The five shape families of the paper (Sec. "Families of Implicit Convex
// Primitives" and Appendix A), each a strictly convex implicit body
// phi(y) <= 0 in its own frame, with phi, grad phi and hess phi evaluated
// together by one piece of code per family.
//
// Shapes are immutable and validated at construction: bad parameters throw
// std::invalid_argument naming the field and the value. Evaluation never
// throws and never allocates.
//
// Every family except the sphere has a sharpness parameter (beta for the
// LogSumExp families, n for the superquadrics). The solver's continuation
// evaluates a shape at a smoother sharpness than its own, so every family can
// be evaluated at an explicit sharpness; `eval(y, e)` uses the shape's own.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "idcol/detail/fast_math.hpp"
#include "idcol/detail/formulas/shape_eval.hpp"
#include "idcol/detail/formulas/support_bound.hpp"
#include "idcol/detail/scalar_num.hpp"
#include "idcol/types.hpp"

namespace idcol {

/// phi, grad phi and hess phi at one point of the shape's frame.
struct ShapeEval {
  double phi = 0.0;
  Vec3 grad = Vec3::Zero();
  Mat3 hess = Mat3::Zero();
};

/// Certified concentric bounding radii: the ball of radius `inner` about the
/// frame origin lies inside the body, and the ball of radius `outer` contains
/// it. Both come from closed forms, never from sampling.
struct Radii {
  double inner = 0.0;
  double outer = 0.0;
};

namespace detail {
/// Exponent n of a superquadric, with a fast path for integer n.
struct Exponent {
  double n = 1.0;
  int n_int = 1;        // n if n is an integer <= 1024, else 0
  int sqrt_depth = -1;  // k if 2n = 2^k (so S^(1/2n) is k square roots), else -1
  explicit Exponent(double n_ = 1.0);
  /// |x|^(2n) for |x| <= 1 (formulas/shape_eval.hpp, as the root below),
  /// for the support points.
  double pow_2n(double x) const { return formulas::pow_2n<ScalarNum>(*this, x); }
  /// S^(1/(2n)) for S in [1, 3].
  double root_2n(double S) const { return formulas::root_2n<ScalarNum>(*this, S); }
};
/// The exponent n = kN in {1, 2, 4, 8, 16} known at compile time, with
/// Exponent's members as constants: the evaluations (formulas/shape_eval.hpp)
/// run the same arithmetic with the constants folded and the powers and
/// roots unrolled (n = 1: the powers are 1, the factors k = 1 and d_i = 1
/// drop out, multiplications by 1 being exact), as the batch lanes compile
/// their exponents in (newton_lanes_kernel.hpp, Expo).
template <int kN>
struct FixedExponent {
  static constexpr double n = kN;
  static constexpr int n_int = kN;
  static constexpr int sqrt_depth = kN == 1 ? 1 : kN == 2 ? 2 : kN == 4 ? 3 : kN == 8 ? 4 : 5;
  static_assert(kN == 1 || kN == 2 || kN == 4 || kN == 8 || kN == 16, "2n must be a power of two");
};
/// Calls f(ex') with ex' the compile-time FixedExponent equal to ex where
/// there is one (2n = 2^k, n <= 16), else with ex itself.
template <class F>
inline void with_exponent(const Exponent& ex, F&& f) {
  switch (ex.sqrt_depth) {
    case 1: return f(FixedExponent<1>{});
    case 2: return f(FixedExponent<2>{});
    case 3: return f(FixedExponent<4>{});
    case 4: return f(FixedExponent<8>{});
    case 5: return f(FixedExponent<16>{});
    default: return f(ex);
  }
}
/// A superquadric's frame-origin case (phi = -1) reached by a point with a
/// NaN coordinate (a max over the coordinates may skip the NaN): NaN.
inline void nan_in_nan_out(const Vec3& y, ShapeEval& e) {
  if (e.phi == -1.0 && y.hasNaN()) e.phi = std::numeric_limits<double>::quiet_NaN();
}
/// A point so close to the frame origin that phi is -1 in double (`m`, its
/// distance in units of the body's size, below 2^-56) can still overflow
/// the evaluation: 1/m is infinite at a subnormal m, and the Hessian, of
/// order (2n - 1)/(m a^2), leaves the double range first (for a unit body
/// within 1e-307 of the origin). Such an evaluation answers as the frame
/// origin does, phi = -1, grad = 0, hess = 0, instead of with inf or NaN
/// (for the users' overloads: the solver never evaluates there); a finite
/// one is kept bit for bit.
inline void origin_if_overflowed(const Vec3& y, double m, ShapeEval& e) {
  if (!(m < 0x1p-56) || y.hasNaN()) return;
  if (std::isfinite(e.phi) && e.grad.allFinite() && e.hess.allFinite()) return;
  e.phi = -1.0;
  e.grad.setZero();
  e.hess.setZero();
}
}  // namespace detail

/// Sphere of radius R: phi(y) = |y|/R - 1.
class Sphere {
 public:
  static constexpr const char* kName = "sphere";
  /// phi + 1 is positively homogeneous of degree 1 in y.
  static constexpr bool kHomogeneous = true;

  explicit Sphere(double R);
  double R() const { return R_; }
  /// The same body with every length multiplied by f, an exact power of
  /// two (so the copy is exact away from subnormals and phi is unchanged:
  /// phi_f(f y) = phi(y)). For the solver's rescaling of problems outside
  /// the double range's safe band (detail::PairSolver); f is not checked.
  Sphere scaled(double f) const {
    Sphere s(*this);
    s.R_ *= f;
    s.iR_ = 1.0 / s.R_;
    return s;
  }

  bool has_sharpness() const { return false; }
  double sharpness() const { return 0.0; }
  double continuation_start() const { return 0.0; }
  Radii radii(double /*sharp*/ = 0.0) const { return {R_, R_}; }
  /// Support function h(u) = max over the body of u.y, for a unit u; for
  /// every family an upper bound on the body's support function in closed
  /// form (exact where the body's is). Used for the certified lower bound on
  /// alpha* behind SolverOptions::alpha_max.
  double support(const Vec3& /*u*/) const { return R_; }
  /// A point y of the body at which u.y reaches the support function, for a
  /// unit u, at the given sharpness; for the LogSumExp families a point of
  /// the exact polytope or frustum that holds the body. Used by the solver's
  /// first guess (the contact on a separating plane).
  Vec3 support_point(const Vec3& u, double /*sharp*/) const { return R_ * u; }
  /// Typical |phi| per unit relative displacement of the surface; 1 for a
  /// dimensionless phi.
  double phi_scale() const { return 1.0; }

  /// At y = 0 the gradient is undefined; eval returns phi = -1, grad = 0 and
  /// hess = 0 there. Every family's eval(y, e) returns NaN at a point with
  /// a NaN coordinate. (This overload, the solver's, takes |y| from its
  /// square, which the solver's rescaled problems keep a normal double.)
  void eval(const Vec3& y, double /*sharp*/, ShapeEval& e) const {
    // formulas/shape_eval.hpp, which the batch lanes share.
    bool origin = false;
    detail::formulas::sphere<detail::ScalarNum>(R_, iR_, y[0], y[1], y[2], e, origin);
  }
  /// For any y: where |y|^2 is not a normal double (|y| below about 1e-154,
  /// where it keeps few digits, or above 1e154, where it overflows), |y| and
  /// the direction come from y scaled by a power of two; within 1e-308 R of
  /// the origin, where the Hessian 1/(R |y|) overflows, the origin's answer
  /// (detail::origin_if_overflowed).
  void eval(const Vec3& y, ShapeEval& e) const {
    const double sq = y.squaredNorm();
    const double m = y.cwiseAbs().maxCoeff();
    if (std::isnormal(sq) || !(m > 0.0) || !y.allFinite()) return eval(y, 0.0, e);
    const int k = std::ilogb(m);
    const Vec3 ys(std::ldexp(y[0], -k), std::ldexp(y[1], -k), std::ldexp(y[2], -k));  // exact, |ys| in [1, 4)
    const double ns = ys.norm(), ny = std::ldexp(ns, k);
    const Vec3 u = ys / ns;
    e.phi = ny / R_ - 1.0;
    e.grad = u / R_;
    e.hess = (Mat3::Identity() - u * u.transpose()) * ((1.0 / R_) / ny);
    detail::origin_if_overflowed(y, m / R_, e);
  }

 private:
  double R_;
  double iR_;  // 1 / R
};

/// Superellipsoid (a, b, c, n):
///   phi(y) = ((y1/a)^(2n) + (y2/b)^(2n) + (y3/c)^(2n))^(1/(2n)) - 1,
/// n >= 1 real (n = 1 is an exact ellipsoid). Integer n takes a fast path.
///
/// Evaluation is overflow-free for any n and any |y|: with psi = phi + 1 and
/// w = ybar/psi (so |w_i| <= 1), grad_ybar psi = w^(2n-1) and
/// hess_ybar psi = (2n-1)/psi (diag(w^(2n-2)) - g g^T); psi itself is computed
/// as m * (sum (ybar_i/m)^(2n))^(1/2n) with m = max |ybar_i|.
/// No epsilon regularisation is used (epsilon = 0): the formulation needs none
/// to stay finite, and it would change the geometry.
class Superellipsoid {
 public:
  static constexpr const char* kName = "superellipsoid";
  static constexpr bool kHomogeneous = true;

  Superellipsoid(double a, double b, double c, double n);
  double a() const { return ax_[0]; }
  double b() const { return ax_[1]; }
  double c() const { return ax_[2]; }
  double n() const { return ex_.n; }
  /// The same body with every length multiplied by f, an exact power of
  /// two (so the copy is exact away from subnormals and phi is unchanged:
  /// phi_f(f y) = phi(y)). For the solver's rescaling of problems outside
  /// the double range's safe band (detail::PairSolver); f is not checked.
  Superellipsoid scaled(double f) const {
    Superellipsoid s(*this);
    s.ax_ *= f;
    s.inv_ /= f;
    s.rad_ = {rad_.inner * f, rad_.outer * f};
    return s;
  }

  bool has_sharpness() const { return ex_.n != 1.0; }
  double sharpness() const { return ex_.n; }
  double continuation_start() const { return 1.0; }
  /// inner = min(a,b,c); outer = (sum a_i^(2q))^(1/2q) with q = n/(n-1) the
  /// Hoelder conjugate of n (max(a,b,c) for n = 1). Both are exact.
  Radii radii(double sharp) const;
  Radii radii() const { return rad_; }
  double phi_scale() const { return 1.0; }
  /// Exact: the dual norm ||diag(a, b, c) u||_q, q = 2n / (2n - 1).
  double support(const Vec3& u) const {
    return detail::formulas::superellipsoid_support_value<detail::ScalarNum>(ax_, ex_.n, u);
  }
  /// Exact: the surface point whose normal is u.
  Vec3 support_point(const Vec3& u, double sharp) const;

  void eval(const Vec3& y, double sharp, ShapeEval& e) const {
    if (sharp == ex_.n) return eval_impl(y, ex_, e);
    return eval_impl(y, detail::Exponent(sharp), e);
  }
  /// NaN at a point with a NaN coordinate. (The overload above, the
  /// solver's, says -1 there as at the frame origin: checking costs its hot
  /// loop 1% of a cold solve, and the solver stops on a non-finite residual
  /// before it could read one.)
  /// Finite within the double range's underflow of the origin too
  /// (detail::origin_if_overflowed; the solver's overload gives inf or NaN
  /// there, where it never evaluates).
  void eval(const Vec3& y, ShapeEval& e) const {
    eval_impl(y, ex_, e);
    detail::nan_in_nan_out(y, e);
    detail::origin_if_overflowed(y, y.cwiseAbs().cwiseProduct(inv_).maxCoeff(), e);
  }

 private:
  void eval_impl(const Vec3& y, const detail::Exponent& ex, ShapeEval& e) const {
    detail::with_exponent(ex, [&](const auto& x) { eval_core(y, x, e); });
  }
  /// The evaluation (formulas/shape_eval.hpp, which the batch lanes share)
  /// at a compile-time exponent (detail::with_exponent).
  template <class Ex>
  void eval_core(const Vec3& y, const Ex& ex, ShapeEval& e) const {
    bool origin = false;
    detail::formulas::superellipsoid<detail::ScalarNum>(inv_.data(), ex, y[0], y[1], y[2], e, origin);
  }
  /// At any other exponent: out of line, so that the compile-time cases
  /// need no stack frame for this one's calls to std::pow.
  [[gnu::noinline]] void eval_core(const Vec3& y, const detail::Exponent& ex, ShapeEval& e) const {
    eval_core<detail::Exponent>(y, ex, e);
  }

  Vec3 ax_;
  Vec3 inv_;
  detail::Exponent ex_;
  Radii rad_;
};

/// Superelliptic cylinder (R, h, n), axis along y1:
///   phi(y) = ((y1/h)^(2n) + ((y2^2 + y3^2)/R^2)^n)^(1/(2n)) - 1.
/// Same overflow-free evaluation as the superellipsoid; no epsilon
/// regularisation (epsilon = 0).
class SuperellipticCylinder {
 public:
  static constexpr const char* kName = "superelliptic_cylinder";
  static constexpr bool kHomogeneous = true;

  SuperellipticCylinder(double R, double h, double n);
  double R() const { return R_; }
  double h() const { return h_; }
  double n() const { return ex_.n; }
  /// The same body with every length multiplied by f, an exact power of
  /// two (so the copy is exact away from subnormals and phi is unchanged:
  /// phi_f(f y) = phi(y)). For the solver's rescaling of problems outside
  /// the double range's safe band (detail::PairSolver); f is not checked.
  SuperellipticCylinder scaled(double f) const {
    SuperellipticCylinder s(*this);
    s.R_ *= f;
    s.h_ *= f;
    s.ih_ = 1.0 / s.h_;
    s.iR_ = 1.0 / s.R_;
    s.rad_ = {rad_.inner * f, rad_.outer * f};
    return s;
  }

  bool has_sharpness() const { return ex_.n != 1.0; }
  double sharpness() const { return ex_.n; }
  double continuation_start() const { return 1.0; }
  /// inner = min(R, h); outer = (h^(2q) + R^(2q))^(1/2q), q = n/(n-1). Exact.
  Radii radii(double sharp) const;
  Radii radii() const { return rad_; }
  double phi_scale() const { return 1.0; }
  /// Exact: ||(h |u1|, R |(u2, u3)|)||_q, q = 2n / (2n - 1).
  double support(const Vec3& u) const {
    return detail::formulas::cylinder_support_value<detail::ScalarNum>(h_, R_, ex_.n, u);
  }
  /// Exact: the surface point whose normal is u.
  Vec3 support_point(const Vec3& u, double sharp) const;

  void eval(const Vec3& y, double sharp, ShapeEval& e) const {
    if (sharp == ex_.n) return eval_impl(y, ex_, e);
    return eval_impl(y, detail::Exponent(sharp), e);
  }
  /// NaN at a point with a NaN coordinate, finite within the underflow of
  /// the origin (see Superellipsoid::eval).
  void eval(const Vec3& y, ShapeEval& e) const {
    eval_impl(y, ex_, e);
    detail::nan_in_nan_out(y, e);
    detail::origin_if_overflowed(y, std::max(std::abs(y[0] * ih_), detail::hypot_any(y[1] * iR_, y[2] * iR_)), e);
  }

 private:
  void eval_impl(const Vec3& y, const detail::Exponent& ex, ShapeEval& e) const {
    detail::with_exponent(ex, [&](const auto& x) { eval_core(y, x, e); });
  }
  /// As Superellipsoid's: compile-time exponents inline, any other out of line.
  template <class Ex>
  void eval_core(const Vec3& y, const Ex& ex, ShapeEval& e) const {
    bool origin = false;
    detail::formulas::superelliptic_cylinder<detail::ScalarNum>(ih_, iR_, ex, y[0], y[1], y[2], e, origin);
  }
  [[gnu::noinline]] void eval_core(const Vec3& y, const detail::Exponent& ex, ShapeEval& e) const {
    eval_core<detail::Exponent>(y, ex, e);
  }

  double R_, h_;
  double ih_ = 1.0 / h_, iR_ = 1.0 / R_;  // 1/h and 1/R, as the batch lanes form them
  detail::Exponent ex_;
  Radii rad_;
};

/// Smooth polytope: phi(y) = smax_beta((a_i^T y - b_i) / L), i = 1..m, the
/// LogSumExp smooth maximum (Appendix A, eq:smoothmax_grad,
/// eq:smoothmax_hessian) evaluated with the max shifted out, so it never
/// overflows. Rows a_i are normalised at construction (b_i scaled with them).
/// L is a characteristic length (default 1, in the scene's length unit), so
/// beta/L is the sharpness in inverse length.
///
/// The smooth body lies inside the exact polytope P and contains the shrunk
/// polytope (1 - L log(m) / (beta b_min)) P.
class SmoothPolytope {
 public:
  static constexpr const char* kName = "smooth_polytope";
  static constexpr bool kHomogeneous = false;

  /// Half-space form A y <= b. Throws std::invalid_argument if a number is
  /// not finite, a row is zero, beta <= 0 or L <= 0, fewer than 4 half-spaces
  /// are given, the polytope does not hold its frame origin strictly inside
  /// (some b_i <= 0 after normalisation; this includes every empty polytope),
  /// the polytope is unbounded, or the smooth body does not hold the origin
  /// (sum exp(-beta b_i / L) >= 1).
  SmoothPolytope(const std::vector<Vec3>& A, const std::vector<double>& b, double beta, double L = 1.0);
  /// Convex hull of a vertex list; coplanar hull triangles are merged into
  /// one half-space per face.
  static SmoothPolytope from_vertices(const std::vector<Vec3>& vertices, double beta, double L = 1.0);

  int num_halfspaces() const { return m_; }
  Vec3 normal(int i) const { return Vec3(ax_[i], ay_[i], az_[i]); }
  double offset(int i) const { return b_[i]; }
  double beta() const { return beta_; }
  double L() const { return L_; }
  /// Vertices of the exact polytope (deduplicated).
  const std::vector<Vec3>& vertices() const { return vertices_; }
  /// The same body with every length multiplied by f, an exact power of
  /// two (so the copy is exact away from subnormals and phi is unchanged:
  /// phi_f(f y) = phi(y)). For the solver's rescaling of problems outside
  /// the double range's safe band (detail::PairSolver); f is not checked.
  /// (L scales with the body, beta is unchanged.) Allocates the copy.
  SmoothPolytope scaled(double f) const;

  bool has_sharpness() const { return true; }
  double sharpness() const { return beta_; }
  /// Smoothest continuation stage: shrinks P by at most 1/4.
  double continuation_start() const;
  /// inner = -L * smax_beta(-b/L) = -L phi(0) (exact for the smooth body's
  /// largest ball under |a_i^T y| <= |y|); outer = max vertex norm of the
  /// exact polytope, which contains the smooth body.
  Radii radii(double sharp) const;
  Radii radii() const { return rad_; }
  /// phi has units of length / L here; a relative surface displacement of 1
  /// changes it by about b_min / L.
  double phi_scale() const { return bmin_ / L_; }
  /// The exact polytope's support, max over its vertices of u.v: it holds
  /// the smooth body.
  double support(const Vec3& u) const {
    return detail::formulas::polytope_support_value<detail::ScalarNum>(
        static_cast<int>(vertices_.size()), [&](int i, int k) { return vertices_[static_cast<std::size_t>(i)][k]; }, u);
  }
  /// The mean of the exact polytope's vertices that reach its support (to
  /// 1e-9 of the outer radius): the centre of the face or edge that u is
  /// normal to, or a vertex.
  Vec3 support_point(const Vec3& u, double sharp) const;

  void eval(const Vec3& y, double sharp, ShapeEval& e) const;
  void eval(const Vec3& y, ShapeEval& e) const { eval(y, beta_, e); }
  /// phi and grad phi only (e.hess is left as it was), the same values as
  /// eval() gives: for the solver's ray searches, which need no Hessian.
  void eval_phi_grad(const Vec3& y, double sharp, ShapeEval& e) const;

  /// The faces as the face loop reads them: four columns [a_x | a_y | a_z |
  /// b] of face_block_rows() entries each, the half-spaces then padding
  /// faces (a = 0, b = +inf) up to a multiple of four. For the SIMD batch
  /// path, which repeats that loop; valid while the shape lives.
  const double* face_block() const { return faces_.data(); }
  int face_block_rows() const { return m4_; }

 private:
  SmoothPolytope() = default;
  template <bool kHessian>
  void eval_impl(const Vec3& y, double sharp, ShapeEval& e) const;
  void init(const std::vector<Vec3>& A, const std::vector<double>& b, double beta, double L);

  std::vector<double> ax_, ay_, az_, b_;  // structure of arrays, sized once
  // The same faces for the face loop (polytope_kernel.hpp), in one block
  // [a_x | a_y | a_z | b] of four columns of m4_ entries: the m_ half-spaces,
  // then up to three padding faces a = 0, b = +inf up to a multiple of four,
  // whose term exp(-inf) is exactly 0, so that the loop runs in whole groups
  // of four.
  std::vector<double> faces_;
  int m_ = 0, m4_ = 0;
  int slot_ = 0;  // the face kernel: unrolled for m4_ = 4 slot_ faces, 0 for any count
  std::vector<Vec3> vertices_;
  double beta_ = 1.0, L_ = 1.0, bmin_ = 1.0, rout_ = 1.0;
  Radii rad_;
};

/// Smooth truncated cone (Rb, Rt, a, b, beta), axis along y1, base (radius
/// Rb) at y1 = -a and top (radius Rt) at y1 = b:
///   phi = smax_beta(r^2/R(y1)^2 - 1, -y1/a - 1, y1/b - 1),
///   R(y1) = Rb + (Rt - Rb)(y1 + a)/(a + b).
/// R(y1) vanishes beyond one end of the frustum; to keep phi finite there,
/// the side term uses max(R(y1), min(Rb, Rt)/2), which equals R(y1) on the
/// whole axial range of the body, so the body and phi near it are unchanged.
/// The side term grows like |y|^2 / R^3, so evaluation is finite for |y| up
/// to about 1e100 (in units of the cone's size), not to the double range.
class SmoothTruncatedCone {
 public:
  static constexpr const char* kName = "smooth_truncated_cone";
  static constexpr bool kHomogeneous = false;

  /// Throws unless all of Rb, Rt, a, b are finite and > 0 and beta > log 3
  /// (below that the smooth body does not hold its frame origin).
  SmoothTruncatedCone(double Rb, double Rt, double a, double b, double beta);
  double Rb() const { return Rb_; }
  double Rt() const { return Rt_; }
  double a() const { return a_; }
  double b() const { return b_; }
  double beta() const { return beta_; }
  /// The same body with every length multiplied by f, an exact power of
  /// two (so the copy is exact away from subnormals and phi is unchanged:
  /// phi_f(f y) = phi(y)). For the solver's rescaling of problems outside
  /// the double range's safe band (detail::PairSolver); f is not checked.
  SmoothTruncatedCone scaled(double f) const {
    SmoothTruncatedCone s(*this);
    s.Rb_ *= f;
    s.Rt_ *= f;
    s.a_ *= f;
    s.b_ *= f;
    s.h_ *= f;
    s.Rfloor_ *= f;
    s.k_ = s.consts();
    s.rad_ = {rad_.inner * f, rad_.outer * f};
    return s;
  }

  bool has_sharpness() const { return true; }
  double sharpness() const { return beta_; }
  double continuation_start() const;
  /// outer = max(hypot(a, Rb), hypot(b, Rt)), the exact frustum's. inner: the
  /// smooth body contains {max c_j <= -log(3)/beta}, whose inscribed ball
  /// about the origin has radius min(a(1-d), b(1-d), k R(0)/sqrt(1 + k^2 kappa^2)),
  /// d = log(3)/beta, k = sqrt(1-d), kappa = (Rt - Rb)/(a + b).
  Radii radii(double sharp) const;
  Radii radii() const { return rad_; }
  double phi_scale() const { return 1.0; }
  /// The exact frustum's support (the larger of its two end discs'): it
  /// holds the smooth body.
  double support(const Vec3& u) const {
    return detail::formulas::cone_support_value<detail::ScalarNum>(Rb_, Rt_, a_, b_, u);
  }
  /// The exact frustum's: a rim point of the end disc that reaches support(u)
  /// (the disc's centre when u is along the axis).
  Vec3 support_point(const Vec3& u, double sharp) const;

  void eval(const Vec3& y, double sharp, ShapeEval& e) const;
  void eval(const Vec3& y, ShapeEval& e) const { eval(y, beta_, e); }
  /// The constants eval reads (formulas/shape_eval.hpp), which the SIMD
  /// lanes evaluate it with.
  const detail::formulas::ConeConsts& eval_consts() const { return k_; }

 private:
  detail::formulas::ConeConsts consts() const { return {Rb_, kappa_, a_, b_, Rfloor_, -1.0 / a_, 1.0 / b_}; }

  double Rb_, Rt_, a_, b_, beta_;
  double h_, kappa_, Rfloor_;
  detail::formulas::ConeConsts k_;  // what the evaluation reads (formulas/shape_eval.hpp)
  Radii rad_;
};

namespace detail {
/// The instruction set of the smooth polytope's face loop on this CPU:
/// "avx2" (AVX2 with FMA) or "sse2". They differ by rounding only.
const char* polytope_kernel_isa();
}  // namespace detail

/// One of the five families. A solve visits this once and then runs code
/// specialised for the pair.
using Shape = std::variant<Sphere, Superellipsoid, SuperellipticCylinder, SmoothPolytope, SmoothTruncatedCone>;

/// Family name ("sphere", "superellipsoid", ...).
const char* family_name(const Shape& s);
/// The shape's parameters at 17 significant digits, ready to paste into a test
/// or a scene file.
std::string describe(const Shape& s);
Radii radii(const Shape& s);
void eval(const Shape& s, const Vec3& y, ShapeEval& e);

}  // namespace idcol
