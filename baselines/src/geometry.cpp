// Independent geometry (see geometry.hpp). Nothing here includes core.
#include "idcol_baselines/geometry.hpp"
#include "idcol_baselines/overloaded.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/LU>

namespace idcol::baselines::geom {

namespace {
using LD = long double;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

void need_positive(const char* family, const char* field, double v) {
  if (!std::isfinite(v) || !(v > 0.0))
    throw std::invalid_argument(std::string(family) + ": " + field + " must be finite and > 0, got " + num(v));
}
void need_exponent(const char* family, double n) {
  if (!std::isfinite(n) || !(n >= 1.0))
    throw std::invalid_argument(std::string(family) + ": n must be finite and >= 1, got " + num(n));
}

// Hoelder conjugate of p = 2n: q = 2n / (2n - 1).
double conjugate(double n) { return 2.0 * n / (2.0 * n - 1.0); }

// ||(w_1..w_k)||_q for q >= 1, scaled by the largest |w_i| so nothing overflows.
template <int K>
double qnorm(const std::array<double, K>& w, double q) {
  double m = 0.0;
  for (double x : w) m = std::max(m, std::abs(x));
  if (m == 0.0) return 0.0;
  double s = 0.0;
  for (double x : w) s += std::pow(std::abs(x) / m, q);
  return m * std::pow(s, 1.0 / q);
}

// The maximiser z of w.z over ||z||_p <= 1 (p the conjugate of q):
// z_i = sign(w_i) (|w_i| / ||w||_q)^(q-1).
template <int K>
std::array<double, K> dual_maximiser(const std::array<double, K>& w, double q) {
  std::array<double, K> z{};
  const double h = qnorm<K>(w, q);
  if (h == 0.0) return z;
  for (int i = 0; i < K; ++i) z[i] = std::copysign(std::pow(std::abs(w[i]) / h, q - 1.0), w[i]);
  return z;
}

// The frustum's side line in the (y1, r) half-plane: r = c0 + c1 y1.
struct Side { double c0, c1; };
Side side_of(const FrustumBody& f) {
  const double c1 = (f.Rt - f.Rb) / (f.a + f.b);
  return {f.Rb + c1 * f.a, c1};
}

FrustumBody frustum_of(const ConeDesc& c, double e) {
  // Every term of the cone's smax <= -e: y1 in [-a(1-e), b(1-e)], r <= sqrt(1-e) R(y1).
  const double k = std::sqrt(1.0 - e), a = c.a * (1.0 - e), b = c.b * (1.0 - e);
  auto R = [&](double y1) { return c.Rb + (c.Rt - c.Rb) * (y1 + c.a) / (c.a + c.b); };
  return FrustumBody{k * R(-a), k * R(b), a, b};
}

double poly_shrink(const PolytopeDesc& p) {
  return p.L * std::log(static_cast<double>(p.offsets.size())) / p.beta;
}
}  // namespace

// ---- descriptions ------------------------------------------------------------

SphereDesc make_sphere(double R) {
  need_positive("sphere", "R", R);
  return {R};
}

SuperellipsoidDesc make_superellipsoid(double a, double b, double c, double n) {
  need_positive("superellipsoid", "a", a);
  need_positive("superellipsoid", "b", b);
  need_positive("superellipsoid", "c", c);
  need_exponent("superellipsoid", n);
  return {a, b, c, n};
}

CylinderDesc make_cylinder(double R, double h, double n) {
  need_positive("superelliptic_cylinder", "R", R);
  need_positive("superelliptic_cylinder", "h", h);
  need_exponent("superelliptic_cylinder", n);
  return {R, h, n};
}

PolytopeDesc make_polytope(const std::vector<Vec>& A, const std::vector<double>& b, double beta, double L) {
  if (A.size() != b.size())
    throw std::invalid_argument("polytope: A has " + std::to_string(A.size()) + " rows but b has " +
                                std::to_string(b.size()) + " entries");
  if (A.size() < 4) throw std::invalid_argument("polytope: needs at least 4 half-spaces, got " + std::to_string(A.size()));
  if (!(beta > 0.0) || std::isnan(beta))  // +inf allowed: the exact polytope
    throw std::invalid_argument("polytope: beta must be > 0 (or +inf for the exact polytope), got " + num(beta));
  need_positive("polytope", "L", L);
  PolytopeDesc p;
  p.beta = beta;
  p.L = L;
  for (std::size_t i = 0; i < A.size(); ++i) {
    const double n = A[i].norm();
    if (!A[i].allFinite() || !std::isfinite(b[i]))
      throw std::invalid_argument("polytope: row " + std::to_string(i) + " has a non-finite entry (b = " + num(b[i]) + ")");
    if (!(n > 0.0)) throw std::invalid_argument("polytope: row " + std::to_string(i) + " of A is zero");
    if (!(b[i] / n > 0.0))
      throw std::invalid_argument("polytope: b[" + std::to_string(i) + "] = " + num(b[i] / n) +
                                  " after normalisation; the origin must lie strictly inside (b_i > 0)");
    p.normals.push_back(A[i] / n);
    p.offsets.push_back(b[i] / n);
  }
  return p;
}

ConeDesc make_cone(double Rb, double Rt, double a, double b, double beta) {
  need_positive("truncated_cone", "Rb", Rb);
  need_positive("truncated_cone", "Rt", Rt);
  need_positive("truncated_cone", "a", a);
  need_positive("truncated_cone", "b", b);
  if (std::isnan(beta) || !(beta > std::log(3.0)))  // +inf allowed: the exact frustum
    throw std::invalid_argument("truncated_cone: beta must be > log 3 (or +inf for the exact frustum), got " + num(beta));
  return {Rb, Rt, a, b, beta};
}

void validate(const Desc& d) {
  std::visit(Overloaded{[](const SphereDesc& s) { make_sphere(s.R); },
                        [](const SuperellipsoidDesc& e) { make_superellipsoid(e.a, e.b, e.c, e.n); },
                        [](const CylinderDesc& c) { make_cylinder(c.R, c.h, c.n); },
                        [](const PolytopeDesc& p) { make_polytope(p.normals, p.offsets, p.beta, p.L); },
                        [](const ConeDesc& t) { make_cone(t.Rb, t.Rt, t.a, t.b, t.beta); }},
             d);
}

std::string describe(const Desc& d) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> std::string { return "sphere(R=" + num(s.R) + ")"; },
          [&](const SuperellipsoidDesc& e) -> std::string {
            return "superellipsoid(a=" + num(e.a) + ", b=" + num(e.b) + ", c=" + num(e.c) + ", n=" + num(e.n) + ")";
          },
          [&](const CylinderDesc& c) -> std::string {
            return "superelliptic_cylinder(R=" + num(c.R) + ", h=" + num(c.h) + ", n=" + num(c.n) + ")";
          },
          [&](const PolytopeDesc& p) -> std::string {
            return "polytope(m=" + std::to_string(p.offsets.size()) + ", beta=" + num(p.beta) + ", L=" + num(p.L) + ")";
          },
          [&](const ConeDesc& t) -> std::string {
            return "truncated_cone(Rb=" + num(t.Rb) + ", Rt=" + num(t.Rt) + ", a=" + num(t.a) + ", b=" + num(t.b) +
                   ", beta=" + num(t.beta) + ")";
          },
      },
      d);
}

// ---- phi and grad phi ----------------------------------------------------------

namespace {
// smax_beta of terms c_k with gradients g_k (Appendix A, eq:smoothmax_grad).
template <class Terms>
PhiGrad smax(const Terms& c, const std::vector<Vec>& g, double beta) {
  LD m = -std::numeric_limits<LD>::infinity();
  for (LD x : c) m = std::max(m, x);
  if (std::isinf(beta)) {  // the exact body: phi = max, grad of the (first) largest term
    std::size_t k = 0;
    while (c[k] != m) ++k;
    return PhiGrad{m, g[k]};
  }
  LD s = 0.0L;
  Eigen::Matrix<LD, 3, 1> grad = Eigen::Matrix<LD, 3, 1>::Zero();
  for (std::size_t k = 0; k < c.size(); ++k) {
    const LD w = std::exp(static_cast<LD>(beta) * (c[k] - m));
    s += w;
    grad += w * g[k].cast<LD>();
  }
  PhiGrad out;
  out.phi = m + std::log(s) / static_cast<LD>(beta);
  out.grad = (grad / s).cast<double>();
  return out;
}

// psi = (sum_k t_k^(2n))^(1/2n) and d psi / d t_k = (t_k / psi)^(2n-1), t_k >= 0,
// evaluated with the ratios t_k / max t <= 1 (eq:phi_grad by homogeneity).
template <int K>
LD psi_and_ratios(const std::array<LD, K>& t, LD n, std::array<LD, K>& dpsi) {
  LD m = 0.0L;
  for (LD x : t) m = std::max(m, x);
  dpsi.fill(0.0L);
  if (m == 0.0L) return 0.0L;
  LD s = 0.0L;
  for (LD x : t) s += std::pow(x / m, 2.0L * n);
  const LD psi = m * std::pow(s, 1.0L / (2.0L * n));
  for (int k = 0; k < K; ++k) dpsi[k] = std::pow(t[k] / psi, 2.0L * n - 1.0L);
  return psi;
}
}  // namespace

PhiGrad eval(const Desc& d, const Vec& y) {
  PhiGrad out;
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> PhiGrad {
            const LD n = std::sqrt(static_cast<LD>(y[0]) * y[0] + static_cast<LD>(y[1]) * y[1] + static_cast<LD>(y[2]) * y[2]);
            out.phi = n / s.R - 1.0L;
            out.grad = n > 0.0L ? Vec((y.cast<LD>() / (n * s.R)).cast<double>()) : Vec::Zero();
            return out;
          },
          [&](const SuperellipsoidDesc& e) -> PhiGrad {
            const std::array<LD, 3> ax = {e.a, e.b, e.c};
            std::array<LD, 3> t{}, dp{};
            for (int i = 0; i < 3; ++i) t[i] = std::abs(static_cast<LD>(y[i]) / ax[i]);
            out.phi = psi_and_ratios<3>(t, e.n, dp) - 1.0L;
            for (int i = 0; i < 3; ++i) out.grad[i] = static_cast<double>(std::copysign(dp[i], static_cast<LD>(y[i])) / ax[i]);
            return out;
          },
          [&](const CylinderDesc& c) -> PhiGrad {
            const LD rho = std::hypot(static_cast<LD>(y[1]), static_cast<LD>(y[2]));
            const std::array<LD, 2> t = {std::abs(static_cast<LD>(y[0]) / c.h), rho / c.R};
            std::array<LD, 2> dp{};
            out.phi = psi_and_ratios<2>(t, c.n, dp) - 1.0L;
            out.grad[0] = static_cast<double>(std::copysign(dp[0], static_cast<LD>(y[0])) / c.h);
            if (rho > 0.0L) {
              out.grad[1] = static_cast<double>(dp[1] / c.R * y[1] / rho);
              out.grad[2] = static_cast<double>(dp[1] / c.R * y[2] / rho);
            }
            return out;
          },
          [&](const PolytopeDesc& p) -> PhiGrad {
            std::vector<LD> c(p.offsets.size());
            std::vector<Vec> g(p.offsets.size());
            for (std::size_t i = 0; i < c.size(); ++i) {
              const LD ay = static_cast<LD>(p.normals[i][0]) * y[0] + static_cast<LD>(p.normals[i][1]) * y[1] +
                            static_cast<LD>(p.normals[i][2]) * y[2];
              c[i] = (ay - p.offsets[i]) / p.L;
              g[i] = p.normals[i] / p.L;
            }
            return smax(c, g, p.beta);
          },
          [&](const ConeDesc& t) -> PhiGrad {
            // Appendix A, smooth truncated cone: phi_s, phi_b, phi_t and their gradients.
            const LD h = static_cast<LD>(t.a) + t.b, kappa = (static_cast<LD>(t.Rt) - t.Rb) / h;
            const LD R = t.Rb + kappa * (static_cast<LD>(y[0]) + t.a);
            const LD r2 = static_cast<LD>(y[1]) * y[1] + static_cast<LD>(y[2]) * y[2];
            const std::array<LD, 3> c = {r2 / (R * R) - 1.0L, -static_cast<LD>(y[0]) / t.a - 1.0L, static_cast<LD>(y[0]) / t.b - 1.0L};
            const std::vector<Vec> g = {Vec(static_cast<double>(-2.0L * kappa * r2 / (R * R * R)), static_cast<double>(2.0L * y[1] / (R * R)),
                                            static_cast<double>(2.0L * y[2] / (R * R))),
                                        Vec(-1.0 / t.a, 0.0, 0.0), Vec(1.0 / t.b, 0.0, 0.0)};
            return smax(c, g, t.beta);
          },
      },
      d);
}

// ---- exact polytope ------------------------------------------------------------

namespace {
// One corner of a face polygon and the plane that made the edge leaving it
// (-1: an edge of the starting square).
struct Corner {
  Vec x;
  int plane;
};

// The face of plane i: the square of half-size B in plane i, clipped by every
// other half-space (Sutherland-Hodgman). Counter-clockwise about normals[i].
std::vector<Corner> clip_face(const std::vector<Vec>& A, const std::vector<double>& b, int i, double B) {
  const Vec& n = A[i];
  const Vec e1 = (std::abs(n[0]) < 0.9 ? Vec::UnitX() : Vec::UnitY()).cross(n).normalized();
  const Vec e2 = n.cross(e1);  // (e1, e2, n) right-handed: increasing angle is CCW about n
  const Vec c = b[i] * n;
  std::vector<Corner> poly = {{c + B * (e1 + e2), -1}, {c + B * (-e1 + e2), -1}, {c + B * (-e1 - e2), -1}, {c + B * (e1 - e2), -1}};
  std::vector<Corner> next;
  for (int j = 0; j < static_cast<int>(A.size()) && !poly.empty(); ++j) {
    if (j == i) continue;
    next.clear();
    const std::size_t k = poly.size();
    bool cut = false;
    for (std::size_t q = 0; q < k; ++q) {
      const Corner& P = poly[q];
      const Corner& Q = poly[(q + 1) % k];
      const double dp = A[j].dot(P.x) - b[j], dq = A[j].dot(Q.x) - b[j];
      if (dp <= 0.0) next.push_back(P);
      else cut = true;
      if ((dp <= 0.0) != (dq <= 0.0)) {
        const double t = dp / (dp - dq);
        // Entering the half-space: the new corner's outgoing edge keeps P's plane;
        // leaving it: the outgoing edge lies on plane j.
        next.push_back({P.x + t * (Q.x - P.x), dp <= 0.0 ? j : P.plane});
      }
    }
    if (cut) poly.swap(next);
  }
  return poly;
}

Vec corner_from_planes(const std::vector<Vec>& A, const std::vector<double>& b, int i, int j, int k, const Vec& fallback) {
  if (j < 0 || k < 0 || j == k) return fallback;
  Mat M;
  M.row(0) = A[i];
  M.row(1) = A[j];
  M.row(2) = A[k];
  const Eigen::FullPivLU<Mat> lu(M);
  if (lu.rank() < 3 || std::abs(M.determinant()) < 1e-9) return fallback;
  const Vec x = lu.solve(Vec(b[i], b[j], b[k]));
  return (x - fallback).norm() <= 1e-6 * (1.0 + fallback.norm()) ? x : fallback;
}
}  // namespace

PolyBody exact_polytope(const std::vector<Vec>& normals, const std::vector<double>& offsets) {
  PolyBody P;
  P.normals = normals;
  P.offsets = offsets;
  const int m = static_cast<int>(normals.size());
  double bmax = 0.0;
  for (double v : offsets) bmax = std::max(bmax, v);
  double scale = 0.0;
  for (int i = 0; i < m; ++i) {
    // A face that still touches the square is cut off by nothing: either the
    // square was too small or the polytope is unbounded. Grow to 1e12 b_max.
    // An empty face is either a redundant half-space or a face that lies
    // wholly outside the square about the foot point b_i n_i: a long thin
    // face of a 1000:1 polytope, nearly parallel to its long axis, can be far
    // from that point. Grow for it too, and call it redundant only at 1e12.
    std::vector<Corner> face;
    for (double B = 4.0 * bmax;; B *= 64.0) {
      face = clip_face(normals, offsets, i, B);
      bool open = false;
      for (const Corner& c : face) open = open || c.plane < 0;
      if (!open && !face.empty()) break;
      if (B > 1e12 * bmax) {
        if (face.empty()) break;
        throw std::invalid_argument("polytope: unbounded (the face of half-space " + std::to_string(i) +
                                    " is cut off by no other half-space within 1e12 b_max)");
      }
    }
    // Each corner is where the edge arriving (plane of the previous corner)
    // meets the edge leaving it (its own plane): solve the three planes.
    std::vector<Vec> pts;
    const std::size_t k = face.size();
    for (std::size_t q = 0; q < k; ++q) {
      const Vec x = corner_from_planes(normals, offsets, i, face[(q + k - 1) % k].plane, face[q].plane, face[q].x);
      scale = std::max(scale, x.norm());
      pts.push_back(x);
    }
    std::vector<int> idx;
    for (const Vec& x : pts) {
      int found = -1;
      for (int v = 0; v < static_cast<int>(P.vertices.size()); ++v)
        if ((P.vertices[v] - x).norm() <= 1e-9 * std::max(1.0, std::max(scale, bmax))) found = v;
      if (found < 0) {
        found = static_cast<int>(P.vertices.size());
        P.vertices.push_back(x);
      }
      if (idx.empty() || (idx.back() != found && idx.front() != found)) idx.push_back(found);
    }
    if (idx.size() >= 3) P.faces.push_back(idx);
  }
  if (P.vertices.size() < 4 || P.faces.size() < 4)
    throw std::invalid_argument("polytope: the half-spaces bound no solid (" + std::to_string(P.vertices.size()) +
                                " vertices, " + std::to_string(P.faces.size()) + " faces)");
  return P;
}

// ---- outer and inner bodies ------------------------------------------------------

Convex outer_body(const Desc& d) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> Convex { return s; },
          [&](const SuperellipsoidDesc& e) -> Convex { return e; },
          [&](const CylinderDesc& c) -> Convex { return c; },
          [&](const PolytopeDesc& p) -> Convex { return exact_polytope(p.normals, p.offsets); },
          [&](const ConeDesc& t) -> Convex { return FrustumBody{t.Rb, t.Rt, t.a, t.b}; },
      },
      d);
}

bool has_inner_body(const Desc& d) {
  if (const auto* p = std::get_if<PolytopeDesc>(&d)) {
    const double s = poly_shrink(*p);
    return *std::min_element(p->offsets.begin(), p->offsets.end()) > s;
  }
  return true;
}

Convex inner_body(const Desc& d) {
  if (const auto* p = std::get_if<PolytopeDesc>(&d)) {
    if (!has_inner_body(d)) throw std::invalid_argument("inner_body: " + describe(d) + " has no inner polytope (b_min <= L log(m)/beta)");
    const double s = poly_shrink(*p);
    std::vector<double> b = p->offsets;
    for (double& v : b) v -= s;
    return exact_polytope(p->normals, b);
  }
  if (const auto* t = std::get_if<ConeDesc>(&d)) return frustum_of(*t, std::log(3.0) / t->beta);
  return outer_body(d);
}

bool is_exact(const Desc& d) {
  if (const auto* p = std::get_if<PolytopeDesc>(&d)) return std::isinf(p->beta);
  if (const auto* t = std::get_if<ConeDesc>(&d)) return std::isinf(t->beta);
  return true;
}

Convex sharp_limit(const Desc& d) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> Convex {
            throw std::invalid_argument("sharp_limit: " + describe(Desc(s)) + " has no sharpness to take to its limit");
          },
          [&](const SuperellipsoidDesc& e) -> Convex { return BoxBody{Vec(e.a, e.b, e.c)}; },
          [&](const CylinderDesc& c) -> Convex { return FrustumBody{c.R, c.R, c.h, c.h}; },
          [&](const PolytopeDesc& p) -> Convex { return exact_polytope(p.normals, p.offsets); },
          [&](const ConeDesc& t) -> Convex { return FrustumBody{t.Rb, t.Rt, t.a, t.b}; },
      },
      d);
}

// ---- support, support point, gauge, radii ------------------------------------------

double support(const Convex& K, const Vec& u) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> double { return s.R * u.norm(); },
          [&](const SuperellipsoidDesc& e) -> double {
            return qnorm<3>({e.a * u[0], e.b * u[1], e.c * u[2]}, conjugate(e.n));  // dual norm
          },
          [&](const CylinderDesc& c) -> double { return qnorm<2>({c.h * u[0], c.R * std::hypot(u[1], u[2])}, conjugate(c.n)); },
          [&](const PolyBody& p) -> double {
            double h = -kInf;
            for (const Vec& v : p.vertices) h = std::max(h, v.dot(u));
            return h;
          },
          [&](const FrustumBody& f) -> double {
            // The frustum is the hull of its two rim circles.
            const double ut = std::hypot(u[1], u[2]);
            return std::max(-f.a * u[0] + f.Rb * ut, f.b * u[0] + f.Rt * ut);
          },
          [&](const BoxBody& b) -> double { return b.h.dot(u.cwiseAbs()); },
      },
      K);
}

Vec support_point(const Convex& K, const Vec& u) {
  const double ut = std::hypot(u[1], u[2]);
  const Vec dir_t = ut > 0.0 ? Vec(0.0, u[1] / ut, u[2] / ut) : Vec::Zero();
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> Vec {
            const double n = u.norm();
            return n > 0.0 ? Vec(s.R * u / n) : Vec(s.R, 0.0, 0.0);
          },
          [&](const SuperellipsoidDesc& e) -> Vec {
            const auto z = dual_maximiser<3>({e.a * u[0], e.b * u[1], e.c * u[2]}, conjugate(e.n));
            return Vec(e.a * z[0], e.b * z[1], e.c * z[2]);
          },
          [&](const CylinderDesc& c) -> Vec {
            const auto z = dual_maximiser<2>({c.h * u[0], c.R * ut}, conjugate(c.n));
            return Vec(c.h * z[0], 0.0, 0.0) + c.R * z[1] * dir_t;
          },
          [&](const PolyBody& p) -> Vec {
            int best = 0;
            for (int v = 1; v < static_cast<int>(p.vertices.size()); ++v)
              if (p.vertices[v].dot(u) > p.vertices[best].dot(u)) best = v;
            return p.vertices[best];
          },
          [&](const FrustumBody& f) -> Vec {
            if (-f.a * u[0] + f.Rb * ut >= f.b * u[0] + f.Rt * ut) return Vec(-f.a, 0.0, 0.0) + f.Rb * dir_t;
            return Vec(f.b, 0.0, 0.0) + f.Rt * dir_t;
          },
          [&](const BoxBody& b) -> Vec {
            return Vec(std::copysign(b.h[0], u[0]), std::copysign(b.h[1], u[1]), std::copysign(b.h[2], u[2]));
          },
      },
      K);
}

double gauge(const Convex& K, const Vec& y) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> double { return y.norm() / s.R; },
          [&](const SuperellipsoidDesc& e) -> double { return qnorm<3>({y[0] / e.a, y[1] / e.b, y[2] / e.c}, 2.0 * e.n); },
          [&](const CylinderDesc& c) -> double { return qnorm<2>({y[0] / c.h, std::hypot(y[1], y[2]) / c.R}, 2.0 * c.n); },
          [&](const PolyBody& p) -> double {
            double g = 0.0;
            for (std::size_t i = 0; i < p.offsets.size(); ++i) g = std::max(g, p.normals[i].dot(y) / p.offsets[i]);
            return g;
          },
          [&](const FrustumBody& f) -> double {
            // Frustum = {y1 >= -a} n {y1 <= b} n {r <= c0 + c1 y1}; the gauge of an
            // intersection is the max of the gauges: t >= -y1/a, y1/b, (r - c1 y1)/c0.
            const Side s = side_of(f);
            return std::max({0.0, -y[0] / f.a, y[0] / f.b, (std::hypot(y[1], y[2]) - s.c1 * y[0]) / s.c0});
          },
          [&](const BoxBody& b) -> double { return y.cwiseAbs().cwiseQuotient(b.h).maxCoeff(); },
      },
      K);
}

std::array<double, 2> radii(const Convex& K) {
  // Superquadrics: with z_i = (y_i/a_i)^2 the body is sum z_i^n <= 1 and
  // |y|^2 = sum a_i^2 z_i, a linear function of z. Its max over the body is
  // the dual norm ||(a_i^2)||_{n/(n-1)} (max a_i^2 at n = 1), its min on the
  // boundary min a_i^2 (there sum z_i >= sum z_i^n = 1).
  auto outer_sq = [](std::initializer_list<double> a2, double n) {
    double m = 0.0;
    for (double x : a2) m = std::max(m, x);
    if (n == 1.0) return m;
    const double q = n / (n - 1.0);
    double s = 0.0;
    for (double x : a2) s += std::pow(x / m, q);
    return m * std::pow(s, 1.0 / q);
  };
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> std::array<double, 2> { return {s.R, s.R}; },
          [&](const SuperellipsoidDesc& e) -> std::array<double, 2> {
            return {std::min({e.a, e.b, e.c}), std::sqrt(outer_sq({e.a * e.a, e.b * e.b, e.c * e.c}, e.n))};
          },
          [&](const CylinderDesc& c) -> std::array<double, 2> {
            return {std::min(c.R, c.h), std::sqrt(outer_sq({c.h * c.h, c.R * c.R}, c.n))};
          },
          [&](const PolyBody& p) -> std::array<double, 2> {
            double rout = 0.0;
            for (const Vec& v : p.vertices) rout = std::max(rout, v.norm());
            return {*std::min_element(p.offsets.begin(), p.offsets.end()), rout};
          },
          [&](const FrustumBody& f) -> std::array<double, 2> {
            const Side s = side_of(f);
            // Distance from the origin to the side segment (y1, c0 + c1 y1), y1 in [-a, b].
            const double y1 = std::clamp(-s.c0 * s.c1 / (1.0 + s.c1 * s.c1), -f.a, f.b);
            const double dside = std::hypot(y1, s.c0 + s.c1 * y1);
            return {std::min({f.a, f.b, dside}), std::max(std::hypot(f.a, f.Rb), std::hypot(f.b, f.Rt))};
          },
          [&](const BoxBody& b) -> std::array<double, 2> { return {b.h.minCoeff(), b.h.norm()}; },
      },
      K);
}

// ---- radial function, depth, distance, features ------------------------------------

namespace {
/// Distance from (px, py) to the segment [(ax, ay), (bx, by)] in the plane.
double segment_distance(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0.0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(px - (ax + t * dx), py - (ay + t * dy));
}

/// m unit directions to points spread evenly on the circle y1 = const of radius R.
void rim_directions(double y1, double R, int m, std::vector<Vec>& out) {
  const double pi = std::acos(-1.0);
  for (int k = 0; k < m; ++k) {
    const double ph = 2.0 * pi * (k + 0.5) / m;
    out.push_back(Vec(y1, R * std::cos(ph), R * std::sin(ph)).normalized());
  }
}

std::string g17(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

[[noreturn]] void no_closed_form(const char* what, const Convex& K) {
  throw std::invalid_argument(std::string(what) + ": no closed form for " + describe(K));
}
}  // namespace

double radial(const Convex& K, const Vec& u) {
  return std::visit(
      Overloaded{
          [&](const PolyBody& p) -> double {
            double t = kInf;
            for (std::size_t i = 0; i < p.normals.size(); ++i) {
              const double c = p.normals[i].dot(u);
              if (c > 0.0) t = std::min(t, p.offsets[i] / c);
            }
            return t;
          },
          [&](const FrustumBody& f) -> double {
            const Side s = side_of(f);  // t |u_t| <= c0 + c1 t u1 on the side
            const double u1 = u[0], ut = std::hypot(u[1], u[2]);
            double t = kInf;
            if (u1 > 0.0) t = std::min(t, f.b / u1);
            if (u1 < 0.0) t = std::min(t, f.a / -u1);
            const double den = ut - s.c1 * u1;
            if (den > 0.0) t = std::min(t, s.c0 / den);
            return t;
          },
          [&](const BoxBody& b) -> double {
            double t = kInf;
            for (int i = 0; i < 3; ++i)
              if (u[i] != 0.0) t = std::min(t, b.h[i] / std::abs(u[i]));
            return t;
          },
          [&](const auto&) -> double { return 1.0 / gauge(K, u); },
      },
      K);
}

double depth(const Convex& K, const Vec& y) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> double { return std::max(0.0, s.R - y.norm()); },
          [&](const PolyBody& p) -> double {
            double d = kInf;
            for (std::size_t i = 0; i < p.normals.size(); ++i) d = std::min(d, p.offsets[i] - p.normals[i].dot(y));
            return std::max(d, 0.0);
          },
          [&](const FrustumBody& f) -> double {
            const Side s = side_of(f);
            const double rho = std::hypot(y[1], y[2]);
            const double side = (s.c0 + s.c1 * y[0] - rho) / std::sqrt(1.0 + s.c1 * s.c1);
            return std::max(0.0, std::min({y[0] + f.a, f.b - y[0], side}));
          },
          [&](const BoxBody& b) -> double { return std::max(0.0, (b.h - y.cwiseAbs()).minCoeff()); },
          [&](const auto&) -> double { no_closed_form("depth", K); },
      },
      K);
}

bool has_distance(const Convex& K) {
  return std::holds_alternative<SphereDesc>(K) || std::holds_alternative<FrustumBody>(K) ||
         std::holds_alternative<BoxBody>(K);
}

double distance(const Convex& K, const Vec& y) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> double { return std::max(0.0, y.norm() - s.R); },
          [&](const FrustumBody& f) -> double {
            // The nearest point of a convex solid of revolution to y lies in
            // y's meridian half-plane (y1, r >= 0), where the body is the
            // trapezoid -a <= y1 <= b, r <= c0 + c1 y1.
            const Side s = side_of(f);
            const double p1 = y[0], pr = std::hypot(y[1], y[2]);
            if (p1 >= -f.a && p1 <= f.b && pr <= f.Rb + s.c1 * (p1 + f.a)) return 0.0;
            // its boundary away from the axis: base cap, side, top cap
            return std::min({segment_distance(p1, pr, -f.a, 0.0, -f.a, f.Rb), segment_distance(p1, pr, -f.a, f.Rb, f.b, f.Rt),
                             segment_distance(p1, pr, f.b, f.Rt, f.b, 0.0)});
          },
          [&](const BoxBody& b) -> double { return (y.cwiseAbs() - b.h).cwiseMax(0.0).norm(); },
          [&](const auto&) -> double { no_closed_form("distance", K); },
      },
      K);
}

std::vector<Vec> feature_directions(const Convex& K) {
  std::vector<Vec> d;
  std::visit(
      Overloaded{
          [&](const PolyBody& p) {
            for (const Vec& v : p.vertices) d.push_back(v.normalized());
            // edge midpoints: pairs of vertices on two common planes
            for (std::size_t i = 0; i < p.vertices.size(); ++i)
              for (std::size_t j = i + 1; j < p.vertices.size(); ++j) {
                int shared = 0;
                for (std::size_t k = 0; k < p.normals.size(); ++k)
                  if (std::abs(p.normals[k].dot(p.vertices[i]) - p.offsets[k]) < 1e-9 &&
                      std::abs(p.normals[k].dot(p.vertices[j]) - p.offsets[k]) < 1e-9)
                    ++shared;
                if (shared >= 2) d.push_back((0.5 * (p.vertices[i] + p.vertices[j])).normalized());
              }
          },
          [&](const FrustumBody& f) {
            rim_directions(-f.a, f.Rb, 64, d);
            rim_directions(f.b, f.Rt, 64, d);
          },
          [&](const BoxBody& b) {
            const Vec& h = b.h;
            for (int s = 0; s < 8; ++s)
              d.push_back(Vec((s & 1) ? -h[0] : h[0], (s & 2) ? -h[1] : h[1], (s & 4) ? -h[2] : h[2]).normalized());
            for (int i = 0; i < 3; ++i)  // edge midpoints
              for (int s = 0; s < 4; ++s) {
                Vec v = h;
                v[i] = 0.0;
                v[(i + 1) % 3] *= (s & 1) ? -1.0 : 1.0;
                v[(i + 2) % 3] *= (s & 2) ? -1.0 : 1.0;
                d.push_back(v.normalized());
              }
          },
          [&](const auto&) {},
      },
      K);
  return d;
}

std::string describe(const Convex& K) {
  return std::visit(
      Overloaded{
          [&](const SphereDesc& s) -> std::string { return describe(Desc(s)); },
          [&](const SuperellipsoidDesc& e) -> std::string { return describe(Desc(e)); },
          [&](const CylinderDesc& c) -> std::string { return describe(Desc(c)); },
          [&](const PolyBody& p) -> std::string {
            return "exact polytope (" + std::to_string(p.normals.size()) + " half-spaces, " +
                   std::to_string(p.vertices.size()) + " vertices)";
          },
          [&](const FrustumBody& f) -> std::string {
            if (f.Rb == f.Rt && f.a == f.b) return "cylinder (R " + g17(f.Rb) + ", half-length " + g17(f.a) + ", axis y1)";
            return "frustum (Rb " + g17(f.Rb) + ", Rt " + g17(f.Rt) + ", a " + g17(f.a) + ", b " + g17(f.b) + ", axis y1)";
          },
          [&](const BoxBody& b) -> std::string {
            return "box (half-extents " + g17(b.h[0]) + ", " + g17(b.h[1]) + ", " + g17(b.h[2]) + ")";
          },
      },
      K);
}

}  // namespace idcol::baselines::geom
