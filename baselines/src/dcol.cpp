// DCOL's cone program and its primal-dual interior-point solver (dcol.hpp).
//
// Notation (Vandenberghe, "The CVXOPT linear and quadratic cone program
// solvers", 2010, sections 2-4, which DCOL's solver follows): variables
// x = (p, alpha, extras) in R^nx, slacks s and duals z in the cone
// K = R^no_+ x Q^n1 x Q^n2 (Q^n the second-order cone {u : u0 >= |u1|}),
//
//     minimise c'x  subject to  G x + s = h,  s in K   (c = e_alpha),
//
// with the Nesterov-Todd scaling W (W z = W^-T s = lambda), the Jordan
// product u o v (elementwise on the orthant; (u'v, u0 v1 + v0 u1) on a
// second-order cone), its identity e and degree no + (n1 > 0) + (n2 > 0).
#include "idcol_baselines/dcol.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace idcol::baselines::dcol {

namespace {

using Eigen::Dynamic;

#define IDCOL_DCOL_NOINLINE __attribute__((noinline))

#ifndef IDCOL_DCOL_STATIC
#define IDCOL_DCOL_STATIC 1
#endif

// ---------------------------------------------------------------- the primitives' blocks

/// What a primitive contributes to the cone program: its nonnegative rows
/// (Dynamic: known at run time), the size of its second-order cone (0, 3 or
/// 4) and its extra variables.
template <class P> struct Block;
template <> struct Block<Polytope> { static constexpr int kOrt = Dynamic, kSoc = 0, kExtra = 0; };
template <> struct Block<Polygon> { static constexpr int kOrt = Dynamic, kSoc = 4, kExtra = 2; };
template <> struct Block<Sphere> { static constexpr int kOrt = 0, kSoc = 4, kExtra = 0; };
template <> struct Block<Ellipsoid> { static constexpr int kOrt = 0, kSoc = 4, kExtra = 0; };
template <> struct Block<Capsule> { static constexpr int kOrt = 2, kSoc = 4, kExtra = 1; };
template <> struct Block<Cylinder> { static constexpr int kOrt = 4, kSoc = 4, kExtra = 1; };
template <> struct Block<Cone> { static constexpr int kOrt = 1, kSoc = 3, kExtra = 0; };

template <class P> int ort_rows(const P&) { return Block<P>::kOrt; }
int ort_rows(const Polytope& p) { return static_cast<int>(p.A.rows()); }
int ort_rows(const Polygon& p) { return static_cast<int>(p.A.rows()); }

/// Where a body's rows and columns go in the combined G (DCOL's layout: the
/// nonnegative rows of body 1 then body 2, then body 1's cone, then body
/// 2's; columns p, alpha, body 1's extras, body 2's extras).
struct Place { int ort0, soc0, col0; };


constexpr int kAlpha = 3;  // the column of alpha

/// The combined program's G (row-major, nx columns) and h, as the
/// primitives' fills write them.
struct Sink {
  double* G;
  double* h;
  int nx;
  double& g(int r, int c) const { return G[r * nx + c]; }
  void row3(int r, const Vec3& a) const { g(r, 0) = a(0), g(r, 1) = a(1), g(r, 2) = a(2); }
  void block3(int r0, const Mat3& M) const {
    for (int i = 0; i < 3; ++i) row3(r0 + i, M.row(i).transpose());
  }
};

// Each fill writes the primitive's rows of G and h for the body at (r, Q):
// G z - h <=_K 0 says that p lies in the body scaled by alpha about r.

// Polytope: A Q'(p - r) <= alpha b.
void fill(const Polytope& P, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  for (int i = 0; i < P.A.rows(); ++i) {
    const Vec3 a = Q * P.A.row(i).transpose();  // the row of A Q'
    o.row3(at.ort0 + i, a);
    o.g(at.ort0 + i, kAlpha) = -P.b(i);
    o.h[at.ort0 + i] = a.dot(r);
  }
}
// Polygon: A u <= alpha b for the in-plane point u, |p - r - Q[:, 0:2] u| <= alpha R.
void fill(const Polygon& P, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  for (int i = 0; i < P.A.rows(); ++i) {
    o.g(at.ort0 + i, kAlpha) = -P.b(i);
    o.g(at.ort0 + i, at.col0) = P.A(i, 0);
    o.g(at.ort0 + i, at.col0 + 1) = P.A(i, 1);
    o.h[at.ort0 + i] = 0.0;
  }
  o.g(at.soc0, kAlpha) = -P.R;
  o.h[at.soc0] = 0.0;
  for (int j = 0; j < 3; ++j) {
    o.g(at.soc0 + 1 + j, j) = -1.0;
    o.g(at.soc0 + 1 + j, at.col0) = Q(j, 0);
    o.g(at.soc0 + 1 + j, at.col0 + 1) = Q(j, 1);
    o.h[at.soc0 + 1 + j] = -r(j);
  }
}
// Sphere: |p - r| <= alpha R.
void fill(const Sphere& S, const Vec3& r, const Mat3&, const Place& at, const Sink& o) {
  o.g(at.soc0, kAlpha) = -S.R;
  o.h[at.soc0] = 0.0;
  for (int j = 0; j < 3; ++j) {
    o.g(at.soc0 + 1 + j, j) = -1.0;
    o.h[at.soc0 + 1 + j] = -r(j);
  }
}
// Ellipsoid: |U Q'(p - r)| <= alpha.
void fill(const Ellipsoid& E, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  const Mat3 UQt = E.U * Q.transpose();
  o.g(at.soc0, kAlpha) = -1.0;
  o.h[at.soc0] = 0.0;
  o.block3(at.soc0 + 1, -UQt);
  const Vec3 hv = -UQt * r;
  for (int j = 0; j < 3; ++j) o.h[at.soc0 + 1 + j] = hv(j);
}
// The axis point's rows of a capsule and a cylinder: |t| <= alpha L/2 and
// |p - r - t Q e_x| <= alpha R.
void fill_axis_ball(double R, double L, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  o.g(at.ort0, kAlpha) = -L / 2, o.g(at.ort0, at.col0) = 1.0, o.h[at.ort0] = 0.0;
  o.g(at.ort0 + 1, kAlpha) = -L / 2, o.g(at.ort0 + 1, at.col0) = -1.0, o.h[at.ort0 + 1] = 0.0;
  o.g(at.soc0, kAlpha) = -R;
  o.h[at.soc0] = 0.0;
  for (int j = 0; j < 3; ++j) {
    o.g(at.soc0 + 1 + j, j) = -1.0;
    o.g(at.soc0 + 1 + j, at.col0) = Q(j, 0);
    o.h[at.soc0 + 1 + j] = -r(j);
  }
}
void fill(const Capsule& C, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  fill_axis_ball(C.R, C.L, r, Q, at, o);
}
// Cylinder: the capsule's rows and |e_x' Q'(p - r)| <= alpha L/2.
void fill(const Cylinder& C, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  fill_axis_ball(C.R, C.L, r, Q, at, o);
  const Vec3 bx = Q.col(0);
  o.row3(at.ort0 + 2, -bx);
  o.g(at.ort0 + 2, kAlpha) = -C.L / 2;
  o.h[at.ort0 + 2] = -bx.dot(r);
  o.row3(at.ort0 + 3, bx);
  o.g(at.ort0 + 3, kAlpha) = -C.L / 2;
  o.h[at.ort0 + 3] = bx.dot(r);
}
// Cone: |(y_y, y_z)| <= tan(beta) (y_x + alpha 3H/4) and y_x <= alpha H/4,
// y = Q'(p - r).
void fill(const Cone& C, const Vec3& r, const Mat3& Q, const Place& at, const Sink& o) {
  const double tb = std::tan(C.beta);
  Mat3 EQt = Q.transpose();
  EQt.row(0) *= tb;
  o.block3(at.soc0, -EQt);
  o.g(at.soc0, kAlpha) = -tb * 3.0 * C.H / 4.0;
  const Vec3 hv = -EQt * r;
  for (int j = 0; j < 3; ++j) o.h[at.soc0 + j] = hv(j);
  const Vec3 bx = Q.col(0);
  o.row3(at.ort0, bx);
  o.g(at.ort0, kAlpha) = -C.H / 4.0;
  o.h[at.ort0] = bx.dot(r);
}

/// A body's part of d alpha / d state at the primal-dual solution: the
/// derivative of z'(G x - h) (its rows only) with respect to r (world) and
/// to a body-frame rotation Q -> Q exp([w]x). zo: its nonnegative duals,
/// zs: its cone's duals, t: its extra variables.
struct BodyGradient { Vec3 d_r = Vec3::Zero(), d_w = Vec3::Zero(); };

// A term u'y of the Lagrangian, y = Q'(p - r): d/dr = -Q u, d/dw = u x y.
void add_body_term(BodyGradient& g, const Mat3& Q, const Vec3& u, const Vec3& y) {
  g.d_r -= Q * u;
  g.d_w += u.cross(y);
}
// The ball rows of a sphere, capsule, cylinder and polygon: zv'(r + Q v - p)
// for the point v of the body frame (0 for a sphere).
void add_ball_term(BodyGradient& g, const Mat3& Q, const double* zs, const Vec3& v) {
  const Vec3 zv(zs[1], zs[2], zs[3]);
  g.d_r += zv;
  g.d_w += v.cross(Q.transpose() * zv);
}

BodyGradient gradient(const Polytope& P, const Vec3& p, const Vec3& r, const Mat3& Q, const double* zo, const double*,
                      const double*) {
  BodyGradient g;
  Vec3 u = Vec3::Zero();
  for (int i = 0; i < P.A.rows(); ++i) u += zo[i] * P.A.row(i).transpose();
  add_body_term(g, Q, u, Q.transpose() * (p - r));
  return g;
}
BodyGradient gradient(const Polygon&, const Vec3&, const Vec3&, const Mat3& Q, const double*, const double* zs, const double* t) {
  BodyGradient g;
  add_ball_term(g, Q, zs, Vec3(t[0], t[1], 0.0));
  return g;
}
BodyGradient gradient(const Sphere&, const Vec3&, const Vec3&, const Mat3& Q, const double*, const double* zs, const double*) {
  BodyGradient g;
  add_ball_term(g, Q, zs, Vec3::Zero());
  return g;
}
BodyGradient gradient(const Ellipsoid& E, const Vec3& p, const Vec3& r, const Mat3& Q, const double*, const double* zs,
                      const double*) {
  BodyGradient g;  // -zv' U y
  add_body_term(g, Q, -(E.U.transpose() * Vec3(zs[1], zs[2], zs[3])), Q.transpose() * (p - r));
  return g;
}
BodyGradient gradient(const Capsule&, const Vec3&, const Vec3&, const Mat3& Q, const double*, const double* zs, const double* t) {
  BodyGradient g;
  add_ball_term(g, Q, zs, Vec3(t[0], 0.0, 0.0));
  return g;
}
BodyGradient gradient(const Cylinder&, const Vec3& p, const Vec3& r, const Mat3& Q, const double* zo, const double* zs,
                      const double* t) {
  BodyGradient g;
  add_ball_term(g, Q, zs, Vec3(t[0], 0.0, 0.0));
  add_body_term(g, Q, Vec3(zo[3] - zo[2], 0.0, 0.0), Q.transpose() * (p - r));
  return g;
}
BodyGradient gradient(const Cone& C, const Vec3& p, const Vec3& r, const Mat3& Q, const double* zo, const double* zs,
                      const double*) {
  BodyGradient g;
  const Vec3 y = Q.transpose() * (p - r);
  add_body_term(g, Q, -Vec3(std::tan(C.beta) * zs[0], zs[1], zs[2]), y);  // -(E zs)' y
  add_body_term(g, Q, Vec3(zo[0], 0.0, 0.0), y);
  return g;
}

// ---------------------------------------------------------------- second-order cone pieces

/// u0^2 - |u1|^2.
template <int N>
inline double j_norm2(const double* u) {
  double s = u[0] * u[0];
  for (int i = 1; i < N; ++i) s -= u[i] * u[i];
  return s;
}

/// Nesterov-Todd scaling of one second-order cone of size N: W = eta Wbar,
/// Wbar = [w0 w1'; w1 I + w1 w1'/(1 + w0)] for the J-unit scaling point w
/// (Vandenberghe, section 4.1), whose inverse is J Wbar J.
template <int N>
struct SocScaling {
  double eta = 1.0;
  double w[N > 0 ? N : 1] = {};
};

template <int N>
inline void soc_scaling(const double* s, const double* z, SocScaling<N>& W) {
  const double js = j_norm2<N>(s), jz = j_norm2<N>(z);
  const double is = 1.0 / std::sqrt(js), iz = 1.0 / std::sqrt(jz);
  double d = 0.0;
  for (int i = 0; i < N; ++i) d += (s[i] * is) * (z[i] * iz);
  const double g2 = 2.0 * std::sqrt((1.0 + d) / 2.0);
  W.w[0] = (s[0] * is + z[0] * iz) / g2;
  for (int i = 1; i < N; ++i) W.w[i] = (s[i] * is - z[i] * iz) / g2;
  W.eta = std::sqrt(std::sqrt(js / jz));
}

/// out = scale Wbar v (sign = 1) or scale Wbar^-1 v (sign = -1); out may be v.
template <int N>
inline void soc_apply(const SocScaling<N>& W, const double* v, double sign, double scale, double* out) {
  double d = 0.0;
  for (int i = 1; i < N; ++i) d += W.w[i] * v[i];
  const double v0 = v[0], k = sign * v0 + d / (1.0 + W.w[0]);
  out[0] = scale * (W.w[0] * v0 + sign * d);
  for (int i = 1; i < N; ++i) out[i] = scale * (v[i] + k * W.w[i]);
}

/// The Jordan product u o v on one cone; out may be u or v.
template <int N>
inline void soc_jordan(const double* u, const double* v, double* out) {
  double d = 0.0;
  for (int i = 0; i < N; ++i) d += u[i] * v[i];
  const double u0 = u[0], v0 = v[0];
  for (int i = 1; i < N; ++i) out[i] = u0 * v[i] + v0 * u[i];
  out[0] = d;
}

/// The v solving l o v = w on one cone; out may be w.
template <int N>
inline void soc_jordan_solve(const double* l, const double* w, double* out) {
  const double rho = j_norm2<N>(l);
  double nu = 0.0;
  for (int i = 1; i < N; ++i) nu += l[i] * w[i];
  const double w0 = w[0], a = (nu / l[0] - w0) / rho, b = 1.0 / l[0];
  out[0] = (l[0] * w0 - nu) / rho;
  for (int i = 1; i < N; ++i) out[i] = a * l[i] + b * w[i];
}

/// The largest step a in (0, 1] keeping y + a d in the cone (y inside): in
/// the frame where y is the identity, d becomes rho, and y + a d stays
/// inside while a (|rho1| - rho0) < 1.
template <int N>
inline double soc_step(const double* y, const double* d) {
  const double nu = j_norm2<N>(y), sq = std::sqrt(nu);
  double yd = 0.0;
  for (int i = 1; i < N; ++i) yd += y[i] * d[i];
  const double zeta = y[0] * d[0] - yd;
  const double rho0 = zeta / nu;
  const double k = ((zeta / sq + d[0]) / (y[0] / sq + 1.0)) / nu;
  double r2 = 0.0;
  for (int i = 1; i < N; ++i) {
    const double ri = d[i] / sq - k * y[i];
    r2 += ri * ri;
  }
  const double rho1 = std::sqrt(r2);
  return rho1 > rho0 ? std::min(1.0, 1.0 / (rho1 - rho0)) : 1.0;
}

// ---------------------------------------------------------------- the interior-point kernel

// The work vectors below are written for the first nz() entries before they
// are read; GCC cannot see it where nz() is known only at run time.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

/// The solver for one structure of the cone program: NO nonnegative rows
/// (Dynamic: counted at run time, at most kMaxOrtRows), cones of sizes N1
/// and N2 (0: none), NX variables. Plain fixed-size arrays and loops whose
/// bounds are constants wherever the sizes are.
template <int NO, int N1, int N2, int NX>
class Kernel {
 public:
  static constexpr int kMaxO = NO == Dynamic ? kMaxOrtRows : NO;
  static constexpr int kMaxZ = kMaxO + N1 + N2 > 0 ? kMaxO + N1 + N2 : 1;

  /// The program's data and the iterate (row-major G).
  struct Program {
    double G[kMaxZ][NX];
    double h[kMaxZ];
    double x[NX];
    double s[kMaxZ], z[kMaxZ];
  };

  explicit Kernel(int no) : no_(no) {}
  int no() const { return NO == Dynamic ? no_ : NO; }
  int nz() const { return no() + N1 + N2; }

  /// Zeroes the first nz rows of G and h; the fills write the rest.
  void clear(Program& P) const {
    for (int i = 0; i < nz(); ++i) {
      for (int j = 0; j < NX; ++j) P.G[i][j] = 0.0;
      P.h[i] = 0.0;
    }
  }

  /// The interior-point solve of min alpha s.t. G x + s = h, s in K, from
  /// DCOL's initial point; P.x, P.s, P.z hold the last iterate. Out of line
  /// (as is step), so that each structure compiles to one function.
  IDCOL_DCOL_NOINLINE Result solve(Program& P, const Options& opt) const {
    Result res;
    if (!initial_point(P)) return finish(res, Status::NumericalFailure, P);
    const double degree = no() + (N1 > 0) + (N2 > 0);
    for (res.iterations = 0;; ++res.iterations) {
      res.gap = dot(P.s, P.z);
      res.mu = res.gap / degree;
      if (!std::isfinite(res.mu)) return finish(res, Status::NumericalFailure, P);
      if (res.mu < opt.pdip_tol) return finish(res, Status::Converged, P);
      if (res.iterations == opt.max_iterations) return finish(res, Status::IterationLimit, P);
      if (!step(P, res.mu)) return finish(res, Status::NumericalFailure, P);
    }
  }

 private:
  using VZ = double[kMaxZ];
  struct Scaling {
    double w_ort[kMaxO > 0 ? kMaxO : 1];
    double inv_w_ort[kMaxO > 0 ? kMaxO : 1];  // 1 / w_ort
    SocScaling<N1> w1;
    SocScaling<N2> w2;
  };

  static Result& finish(Result& r, Status st, const Program& P) {
    r.status = st;
    r.alpha = P.x[kAlpha];
    r.x = Vec3(P.x[0], P.x[1], P.x[2]);
    return r;
  }
  double dot(const double* a, const double* b) const {
    double s = 0.0;
    for (int i = 0; i < nz(); ++i) s += a[i] * b[i];
    return s;
  }

  /// L L' = M, lower L in place; false unless positive definite.
  static bool cholesky(double M[NX][NX]) {
    for (int j = 0; j < NX; ++j) {
      double d = M[j][j];
      for (int k = 0; k < j; ++k) d -= M[j][k] * M[j][k];
      if (!(d > 0.0)) return false;
      M[j][j] = std::sqrt(d);
      for (int i = j + 1; i < NX; ++i) {
        double v = M[i][j];
        for (int k = 0; k < j; ++k) v -= M[i][k] * M[j][k];
        M[i][j] = v / M[j][j];
      }
    }
    return true;
  }
  /// b <- (L L')^-1 b.
  static void cholesky_solve(const double L[NX][NX], double b[NX]) {
    for (int i = 0; i < NX; ++i) {
      for (int k = 0; k < i; ++k) b[i] -= L[i][k] * b[k];
      b[i] /= L[i][i];
    }
    for (int i = NX - 1; i >= 0; --i) {
      for (int k = i + 1; k < NX; ++k) b[i] -= L[k][i] * b[k];
      b[i] /= L[i][i];
    }
  }
  // The products below accumulate in locals, so that no store to the
  // output can alias an input and the compiler keeps them in registers.
  /// M = A'A (lower triangle) for the first nz rows of A.
  void gram(const double (*__restrict A)[NX], double M[NX][NX]) const {
    double acc[NX][NX] = {};
    for (int i = 0; i < nz(); ++i)
      for (int a = 0; a < NX; ++a)
        for (int b = 0; b < NX; ++b) acc[a][b] += A[i][a] * A[i][b];
    for (int a = 0; a < NX; ++a)
      for (int b = 0; b <= a; ++b) M[a][b] = acc[a][b];
  }
  /// out = A' v (NX) and out = A y (nz).
  void mul_t(const double (*__restrict A)[NX], const double* __restrict v, double out[NX]) const {
    double acc[NX] = {};
    for (int i = 0; i < nz(); ++i)
      for (int j = 0; j < NX; ++j) acc[j] += A[i][j] * v[i];
    for (int j = 0; j < NX; ++j) out[j] = acc[j];
  }
  void mul(const double (*__restrict A)[NX], const double y[NX], double* __restrict out) const {
    double yl[NX];
    for (int j = 0; j < NX; ++j) yl[j] = y[j];
    for (int i = 0; i < nz(); ++i) {
      double s = 0.0;
      for (int j = 0; j < NX; ++j) s += A[i][j] * yl[j];
      out[i] = s;
    }
  }

  /// DCOL's move into the cone: r + (1 + a) e where a is the largest
  /// violation (r unchanged if strictly inside).
  void into_cone(double* r) const {
    double a = -1.0;
    if (no() > 0) {
      double m = r[0];
      for (int i = 1; i < no(); ++i) m = std::min(m, r[i]);
      if (m <= 0.0) a = -m;
    }
    auto soc = [&](const double* u, int n) {
      double v = 0.0;
      for (int i = 1; i < n; ++i) v += u[i] * u[i];
      const double res = u[0] - std::sqrt(v);
      if (res <= 0.0) a = std::max(a, -res);
    };
    if constexpr (N1 > 0) soc(r + no(), N1);
    if constexpr (N2 > 0) soc(r + no() + N1, N2);
    if (a >= 0.0) add_identity(r, 1.0 + a);
  }
  void add_identity(double* r, double c) const {
    for (int i = 0; i < no(); ++i) r[i] += c;
    if constexpr (N1 > 0) r[no()] += c;
    if constexpr (N2 > 0) r[no() + N1] += c;
  }

  /// The initial point (DCOL's): x the least-squares solution of G x = h,
  /// s from G x - h and z from G (G'G)^-1 (-c), each moved into the cone.
  bool initial_point(Program& P) const {
    double L[NX][NX], v[NX];
    gram(P.G, L);
    if (!cholesky(L)) return false;
    mul_t(P.G, P.h, P.x);
    cholesky_solve(L, P.x);
    mul(P.G, P.x, P.s);
    for (int i = 0; i < nz(); ++i) P.s[i] -= P.h[i];
    into_cone(P.s);
    for (int j = 0; j < NX; ++j) v[j] = j == kAlpha ? -1.0 : 0.0;
    cholesky_solve(L, v);
    mul(P.G, v, P.z);
    into_cone(P.z);
    return true;
  }

  void scaling(const Program& P, Scaling& W) const {
    for (int i = 0; i < no(); ++i) {
      W.w_ort[i] = std::sqrt(P.s[i] / P.z[i]);
      W.inv_w_ort[i] = 1.0 / W.w_ort[i];
    }
    if constexpr (N1 > 0) soc_scaling<N1>(P.s + no(), P.z + no(), W.w1);
    if constexpr (N2 > 0) soc_scaling<N2>(P.s + no() + N1, P.z + no() + N1, W.w2);
  }
  /// out = W v or W^-1 v (inverse); out may be v.
  void apply(const Scaling& W, const double* v, double* out, bool inverse) const {
    if (inverse)
      for (int i = 0; i < no(); ++i) out[i] = v[i] * W.inv_w_ort[i];
    else
      for (int i = 0; i < no(); ++i) out[i] = v[i] * W.w_ort[i];
    const double sign = inverse ? -1.0 : 1.0;
    if constexpr (N1 > 0) soc_apply<N1>(W.w1, v + no(), sign, inverse ? 1.0 / W.w1.eta : W.w1.eta, out + no());
    if constexpr (N2 > 0) soc_apply<N2>(W.w2, v + no() + N1, sign, inverse ? 1.0 / W.w2.eta : W.w2.eta, out + no() + N1);
  }
  /// Gt = W^-1 G, column by column on the cones.
  void scale_columns(const Scaling& W, const double G[][NX], double Gt[][NX]) const {
    for (int i = 0; i < no(); ++i)
      for (int j = 0; j < NX; ++j) Gt[i][j] = G[i][j] * W.inv_w_ort[i];
    auto cone = [&](const auto& Wk, int r0, auto n) {
      constexpr int N = decltype(n)::value;
      for (int j = 0; j < NX; ++j) {
        double c[N];
        for (int i = 0; i < N; ++i) c[i] = G[r0 + i][j];
        soc_apply<N>(Wk, c, -1.0, 1.0 / Wk.eta, c);
        for (int i = 0; i < N; ++i) Gt[r0 + i][j] = c[i];
      }
    };
    if constexpr (N1 > 0) cone(W.w1, no(), std::integral_constant<int, N1>{});
    if constexpr (N2 > 0) cone(W.w2, no() + N1, std::integral_constant<int, N2>{});
  }
  /// out = u o v; out = l \ w (the v with l o v = w). out may alias.
  void jordan(const double* u, const double* v, double* out) const {
    for (int i = 0; i < no(); ++i) out[i] = u[i] * v[i];
    if constexpr (N1 > 0) soc_jordan<N1>(u + no(), v + no(), out + no());
    if constexpr (N2 > 0) soc_jordan<N2>(u + no() + N1, v + no() + N1, out + no() + N1);
  }
  void jordan_solve(const double* l, const double* w, double* out) const {
    for (int i = 0; i < no(); ++i) out[i] = w[i] / l[i];
    if constexpr (N1 > 0) soc_jordan_solve<N1>(l + no(), w + no(), out + no());
    if constexpr (N2 > 0) soc_jordan_solve<N2>(l + no() + N1, w + no() + N1, out + no() + N1);
  }
  double max_step(const double* y, const double* d) const {
    double a = 1.0;
    for (int i = 0; i < no(); ++i)
      if (d[i] < 0.0) a = std::min(a, -y[i] / d[i]);
    if constexpr (N1 > 0) a = std::min(a, soc_step<N1>(y + no(), d + no()));
    if constexpr (N2 > 0) a = std::min(a, soc_step<N2>(y + no() + N1, d + no() + N1));
    return a;
  }

  /// One predictor-corrector step (Vandenberghe's section 5.3, with the
  /// normal equations of G~ = W^-1 G): false if the factorisation fails or
  /// the iterate stops being finite.
  IDCOL_DCOL_NOINLINE bool step(Program& P, double mu) const {
    const int nz = this->nz();
    Scaling W;
    scaling(P, W);
    VZ lambda, ll, Winv_rz, tmp;
    apply(W, P.z, lambda, false);
    jordan(lambda, lambda, ll);
    double bx[NX];
    mul_t(P.G, P.z, bx);
    for (int j = 0; j < NX; ++j) bx[j] = -bx[j] - (j == kAlpha ? 1.0 : 0.0);
    mul(P.G, P.x, tmp);
    for (int i = 0; i < nz; ++i) tmp[i] += P.s[i] - P.h[i];  // rz = s + G x - h
    apply(W, tmp, Winv_rz, true);
    double Gt[kMaxZ][NX], L[NX][NX];
    scale_columns(W, P.G, Gt);
    gram(Gt, L);
    if (!cholesky(L)) return false;
    // The linearised KKT system for a right-hand side ds of the
    // complementarity row, lambda o (W dz + W^-T ds) = ds.
    auto direction = [&](const double* ds, double dx[NX], double* dz, double* dsl) {
      VZ l_ds, bz;
      jordan_solve(lambda, ds, l_ds);
      for (int i = 0; i < nz; ++i) bz[i] = -Winv_rz[i] - l_ds[i];  // W^-1 (-rz - W (lambda \ ds))
      mul_t(Gt, bz, dx);
      for (int j = 0; j < NX; ++j) dx[j] += bx[j];
      cholesky_solve(L, dx);
      mul(Gt, dx, dz);
      for (int i = 0; i < nz; ++i) dz[i] -= bz[i];
      apply(W, dz, dz, true);
      apply(W, dz, dsl, false);
      for (int i = 0; i < nz; ++i) dsl[i] = l_ds[i] - dsl[i];
      apply(W, dsl, dsl, false);
    };
    // Affine (predictor) direction, its step and the centring weight.
    double dx[NX];
    VZ dz, ds;
    for (int i = 0; i < nz; ++i) tmp[i] = -ll[i];
    direction(tmp, dx, dz, ds);
    const double aa = std::min(max_step(P.s, ds), max_step(P.z, dz));
    double num = 0.0;
    for (int i = 0; i < nz; ++i) num += (P.s[i] + aa * ds[i]) * (P.z[i] + aa * dz[i]);
    const double rho = std::clamp(num / dot(P.s, P.z), 0.0, 1.0), sigma = rho * rho * rho;
    // Combined (centring and second-order correction) direction.
    VZ a1, a2;
    apply(W, ds, a1, true);
    apply(W, dz, a2, false);
    jordan(a1, a2, tmp);
    for (int i = 0; i < nz; ++i) tmp[i] = -ll[i] - tmp[i];
    add_identity(tmp, sigma * mu);
    direction(tmp, dx, dz, ds);
    const double a = std::min(1.0, 0.99 * std::min(max_step(P.s, ds), max_step(P.z, dz)));
    double sum = 0.0;
    for (int j = 0; j < NX; ++j) sum += (P.x[j] += a * dx[j]);
    for (int i = 0; i < nz; ++i) sum += (P.s[i] += a * ds[i]) + (P.z[i] += a * dz[i]);
    return std::isfinite(sum);
  }

  int no_;
};

// ---------------------------------------------------------------- one pair

template <class P1, class P2>
struct Pair {
  static constexpr int kO1 = Block<P1>::kOrt, kO2 = Block<P2>::kOrt;
  static constexpr int kStaticRows = (kO1 == Dynamic || kO2 == Dynamic) ? Dynamic : kO1 + kO2;
  static constexpr int N1 = Block<P1>::kSoc, N2 = Block<P2>::kSoc;
  static constexpr int E1 = Block<P1>::kExtra;
  static constexpr int NX = 4 + E1 + Block<P2>::kExtra;
  const P1& p1;
  const P2& p2;
  const Vec3 &r1, &r2;
  const Mat3 &Q1, &Q2;

  /// Builds the program, solves it with the kernel of NO nonnegative rows,
  /// and (grad != nullptr) forms the gradient at the solution.
  template <int NO>
  IDCOL_DCOL_NOINLINE Result run(const Options& opt, Gradient* grad) const {
    using K = Kernel<NO, N1, N2, NX>;
    const int o1 = ort_rows(p1), o2 = ort_rows(p2), no = o1 + o2;
    const K k(no);
    typename K::Program P;
    k.clear(P);
    const Sink out{&P.G[0][0], P.h, NX};
    fill(p1, r1, Q1, Place{0, no, 4}, out);
    fill(p2, r2, Q2, Place{o1, no + N1, 4 + E1}, out);
    const Result res = k.solve(P, opt);
    if (grad) {
      grad->result = res;
      if (res.converged()) {
        const Vec3 p(P.x[0], P.x[1], P.x[2]);
        const BodyGradient g1 = gradient(p1, p, r1, Q1, P.z, P.z + no, P.x + 4);
        const BodyGradient g2 = gradient(p2, p, r2, Q2, P.z + o1, P.z + no + N1, P.x + 4 + E1);
        grad->dalpha_dxi << g1.d_w, Q1.transpose() * g1.d_r, g2.d_w, Q2.transpose() * g2.d_r;
      }
    }
    return res;
  }
};

/// The pairs whose nonnegative rows are known only at run time and whose
/// kernel is nevertheless compiled for each count up to kMaxStaticOrtRows:
/// a polytope with a polytope, a sphere or an ellipsoid (the pairs the exact
/// baselines serve); every other such pair counts its rows at run time.
template <class P1, class P2>
inline constexpr bool kStaticDispatch =
    IDCOL_DCOL_STATIC && ((std::is_same_v<P1, Polytope> && (std::is_same_v<P2, Polytope> || Block<P2>::kOrt == 0)) ||
                          (std::is_same_v<P2, Polytope> && Block<P1>::kOrt == 0));

/// Calls f(std::integral_constant<int, NO>) with NO = rows where
/// 1 <= rows <= kMaxStaticOrtRows, else with NO = Dynamic.
template <class F, int... I>
Result with_rows(int rows, const F& f, std::integer_sequence<int, I...>) {
  Result r;
  const bool done = ((rows == I + 1 ? (r = f(std::integral_constant<int, I + 1>{}), true) : false) || ...);
  return done ? r : f(std::integral_constant<int, Dynamic>{});
}

template <class P1, class P2>
Result run_pair(const Pair<P1, P2>& pair, const Options& opt, Gradient* grad) {
  if constexpr (Pair<P1, P2>::kStaticRows != Dynamic) {
    return pair.template run<Pair<P1, P2>::kStaticRows>(opt, grad);
  } else if constexpr (!kStaticDispatch<P1, P2>) {
    return pair.template run<Dynamic>(opt, grad);
  } else {
    const int rows = ort_rows(pair.p1) + ort_rows(pair.p2);
    auto f = [&](auto NO) { return pair.template run<decltype(NO)::value>(opt, grad); };
    return with_rows(rows, f, std::make_integer_sequence<int, kMaxStaticOrtRows>{});
  }
}

Result dispatch(const Primitive& p1, const Vec3& r1, const Mat3& Q1, const Primitive& p2, const Vec3& r2, const Mat3& Q2,
                const Options& opt, Gradient* grad) {
  if (!(opt.pdip_tol > 0.0) || !std::isfinite(opt.pdip_tol))
    throw std::invalid_argument("dcol::Options: pdip_tol must be finite and > 0, got " + std::to_string(opt.pdip_tol));
  if (opt.max_iterations < 1)
    throw std::invalid_argument("dcol::Options: max_iterations must be >= 1, got " + std::to_string(opt.max_iterations));
  return std::visit(
      [&](const auto& a, const auto& b) {
        using A = std::decay_t<decltype(a)>;
        using B = std::decay_t<decltype(b)>;
        return run_pair(Pair<A, B>{a, b, r1, r2, Q1, Q2}, opt, grad);
      },
      p1, p2);
}

Mat3 rotation_of(const Quat& q) {
  const Quat u = q / q.norm();
  return Eigen::Quaterniond(u(0), u(1), u(2), u(3)).toRotationMatrix();
}

/// d alpha / dq from the body-frame rotation gradient g_w: with q = |q| qh
/// and qh = (w, v), a change dq turns the attitude by w = (2/|q|) M dq,
/// M = [-v, w I - [v]x] (the vector part of conj(qh) * dq, doubled).
Eigen::Vector4d quaternion_gradient(const Quat& q, const Vec3& g_w) {
  const double n = q.norm();
  const double w = q(0) / n;
  const Vec3 v = q.tail<3>() / n;
  Eigen::Matrix<double, 3, 4> M;
  M.col(0) = -v;
  M.rightCols<3>() = w * Mat3::Identity();
  M(0, 2) += v(2), M(0, 3) -= v(1);
  M(1, 1) -= v(2), M(1, 3) += v(0);
  M(2, 1) += v(1), M(2, 2) -= v(0);
  return (2.0 / n) * M.transpose() * g_w;
}

void quaternion_form(Gradient& g, const Quat& q1, const Mat3& Q1, const Quat& q2, const Mat3& Q2) {
  const auto& d = g.dalpha_dxi;
  g.dalpha_dstate << Q1 * d.segment<3>(3), quaternion_gradient(q1, d.segment<3>(0)), Q2 * d.segment<3>(9),
      quaternion_gradient(q2, d.segment<3>(6));
}

Quat quat_of(const Mat3& Q) {
  const Eigen::Quaterniond q(Q);
  return Quat(q.w(), q.x(), q.y(), q.z());
}

// ---------------------------------------------------------------- validation

void check(bool ok, const std::string& what, double value) {
  if (!ok) throw std::invalid_argument("dcol: " + what + ", got " + std::to_string(value));
}

template <class MA>
void check_rows(const char* name, const MA& A, const Eigen::VectorXd& b) {
  const std::string n(name);
  check(A.rows() >= 1 && A.rows() <= kMaxOrtRows, n + ": the number of rows must be in [1, " + std::to_string(kMaxOrtRows) + "]",
        static_cast<double>(A.rows()));
  check(b.size() == A.rows(), n + ": b must have one entry per row of A (" + std::to_string(A.rows()) + ")",
        static_cast<double>(b.size()));
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const std::string row = n + ": row " + std::to_string(i);
    check(A.row(i).allFinite() && A.row(i).norm() > 0.0, row + " of A must be finite and nonzero (norm)", A.row(i).norm());
    check(std::isfinite(b(i)) && b(i) > 0.0, row + ": b must be finite and > 0 (the origin strictly inside)", b(i));
  }
}
void check_positive(const std::string& what, double v) { check(std::isfinite(v) && v > 0.0, what + " must be finite and > 0", v); }

struct Validator {
  void operator()(const Polytope& p) const { check_rows("polytope", p.A, p.b); }
  void operator()(const Polygon& p) const {
    check_rows("polygon", p.A, p.b);
    check_positive("polygon: R", p.R);
  }
  void operator()(const Sphere& s) const { check_positive("sphere: R", s.R); }
  void operator()(const Ellipsoid& e) const {
    check(e.P.allFinite() && (e.P - e.P.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * e.P.cwiseAbs().maxCoeff(),
          "ellipsoid: P must be finite and symmetric (largest asymmetry)", (e.P - e.P.transpose()).cwiseAbs().maxCoeff());
    const Eigen::LLT<Mat3> llt(e.P);
    check(llt.info() == Eigen::Success && e.P.diagonal().minCoeff() > 0.0, "ellipsoid: P must be positive definite (smallest diagonal)",
          e.P.diagonal().minCoeff());
    check((e.U.transpose() * e.U - e.P).cwiseAbs().maxCoeff() <= 1e-12 * e.P.cwiseAbs().maxCoeff(),
          "ellipsoid: U must be P's upper Cholesky factor (use make_ellipsoid; error)", (e.U.transpose() * e.U - e.P).cwiseAbs().maxCoeff());
  }
  void operator()(const Capsule& c) const {
    check_positive("capsule: R", c.R);
    check_positive("capsule: L", c.L);
  }
  void operator()(const Cylinder& c) const {
    check_positive("cylinder: R", c.R);
    check_positive("cylinder: L", c.L);
  }
  void operator()(const Cone& c) const {
    check_positive("cone: H", c.H);
    check(std::isfinite(c.beta) && c.beta > 0.0 && c.beta < M_PI / 2, "cone: beta must be in (0, pi/2)", c.beta);
  }
};

}  // namespace

// ---------------------------------------------------------------- public

Polytope make_polytope(const Eigen::Matrix<double, Eigen::Dynamic, 3>& A, const Eigen::VectorXd& b) {
  Polytope p{A, b};
  validate(p);
  return p;
}
Polygon make_polygon(const Eigen::Matrix<double, Eigen::Dynamic, 2>& A, const Eigen::VectorXd& b, double R) {
  Polygon p{A, b, R};
  validate(p);
  return p;
}
Sphere make_sphere(double R) {
  Sphere s{R};
  validate(s);
  return s;
}
Ellipsoid make_ellipsoid(const Mat3& P) {
  Ellipsoid e;
  e.P = P;
  const Eigen::LLT<Mat3> llt(P);
  e.U = llt.matrixU();
  validate(e);
  return e;
}
Ellipsoid make_ellipsoid_axes(double a, double b, double c) {
  check_positive("ellipsoid: a", a);
  check_positive("ellipsoid: b", b);
  check_positive("ellipsoid: c", c);
  return make_ellipsoid(Eigen::Vector3d(1.0 / (a * a), 1.0 / (b * b), 1.0 / (c * c)).asDiagonal());
}
Capsule make_capsule(double R, double L) {
  Capsule c{R, L};
  validate(c);
  return c;
}
Cylinder make_cylinder(double R, double L) {
  Cylinder c{R, L};
  validate(c);
  return c;
}
Cone make_cone(double H, double beta) {
  Cone c{H, beta};
  validate(c);
  return c;
}
void validate(const Primitive& p) { std::visit(Validator{}, p); }

std::string describe(const Primitive& p) {
  struct Name {
    std::string operator()(const Polytope& q) const { return "polytope(" + std::to_string(q.A.rows()) + " half-spaces)"; }
    std::string operator()(const Polygon& q) const { return "polygon(" + std::to_string(q.A.rows()) + " edges)"; }
    std::string operator()(const Sphere&) const { return "sphere"; }
    std::string operator()(const Ellipsoid&) const { return "ellipsoid"; }
    std::string operator()(const Capsule&) const { return "capsule"; }
    std::string operator()(const Cylinder&) const { return "cylinder"; }
    std::string operator()(const Cone&) const { return "cone"; }
  };
  return std::visit(Name{}, p);
}

Mat3 rotation(const Quat& q) { return rotation_of(q); }

const char* to_string(Status s) {
  switch (s) {
    case Status::Converged: return "Converged";
    case Status::IterationLimit: return "IterationLimit";
    case Status::NumericalFailure: return "NumericalFailure";
  }
  return "?";
}

Result proximity(const Primitive& p1, const Vec3& r1, const Mat3& Q1, const Primitive& p2, const Vec3& r2, const Mat3& Q2,
                 const Options& opt) {
  return dispatch(p1, r1, Q1, p2, r2, Q2, opt, nullptr);
}
Result proximity(const Primitive& p1, const Pose& X1, const Primitive& p2, const Pose& X2, const Options& opt) {
  return proximity(p1, X1.r, rotation_of(X1.q), p2, X2.r, rotation_of(X2.q), opt);
}

Gradient proximity_gradient(const Primitive& p1, const Vec3& r1, const Mat3& Q1, const Primitive& p2, const Vec3& r2,
                            const Mat3& Q2, const Options& opt) {
  Gradient g;
  dispatch(p1, r1, Q1, p2, r2, Q2, opt, &g);
  if (g.result.converged()) quaternion_form(g, quat_of(Q1), Q1, quat_of(Q2), Q2);
  return g;
}
Gradient proximity_gradient(const Primitive& p1, const Pose& X1, const Primitive& p2, const Pose& X2, const Options& opt) {
  const Mat3 Q1 = rotation_of(X1.q), Q2 = rotation_of(X2.q);
  Gradient g;
  dispatch(p1, X1.r, Q1, p2, X2.r, Q2, opt, &g);
  if (g.result.converged()) quaternion_form(g, X1.q, Q1, X2.q, Q2);
  return g;
}

}  // namespace idcol::baselines::dcol
