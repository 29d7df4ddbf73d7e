#include "idcol/shape_params.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "idcol/convex_hull.hpp"
#include "idcol/families.hpp"

namespace idcol {
namespace {

/// The superquadrics in one form: phi + 1 = psi(ybar), ybar_j = y_j / s_j,
/// psi positively homogeneous of degree 1, with component j scaled by
/// parameter group[j] and log-magnitude ell_j of its term (below).
/// With g = grad_ybar psi, w = ybar / psi (|w_j| <= 1) and P = psi hess_ybar psi
/// (all bounded; P_jk = psi s_j s_k hess_jk from the family's own Hessian):
///   d phi / d s_p   = -psi sum_{j in p} g_j w_j / s_p,
///   d G_j / d s_p   = -[j in p] g_j / s_p^2 - (1/s_j) sum_{k in p} P_jk w_k / s_p,
/// for G = grad_y phi = g / s, from d ybar_k / d s_p = -ybar_k / s_p and
/// hess_ybar psi ybar = P w. In the exponent n, with
/// mu = d log psi / dn = (1/n) sum_j g_j w_j ell_j (|w_j|^(2n) = g_j w_j),
///   d phi / dn = psi mu,   d g_j / dn = g_j (2 ell_j - (2n - 1) mu),
/// where ell_j = log|w_j| for the superellipsoid's terms and
/// ell = log(w_2^2 + w_3^2) / 2 for the cylinder's radial term.
struct Superquadric {
  Vec3 s;          // scale of each component
  int group[3];    // parameter index of each component's scale
  int n_index;     // parameter index of n
  bool radial23;   // components 2 and 3 share one radial term (cylinder)
  double n;
};

void superquadric_params(const Superquadric& q, const Vec3& y, const ShapeEval& e, ShapeParamEval& d) {
  d.dphi.setZero();
  d.dgrad.setZero();
  const double psi = e.phi + 1.0;
  if (!(psi > 0.0)) return;  // frame origin: derivatives undefined
  Vec3 w, g;
  for (int j = 0; j < 3; ++j) {
    w[j] = (y[j] / q.s[j]) / psi;
    g[j] = e.grad[j] * q.s[j];
  }
  Mat3 P;
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) P(j, k) = (psi * e.hess(j, k)) * q.s[j] * q.s[k];
  // Scales.
  for (int j = 0; j < 3; ++j) {
    const int p = q.group[j];
    const double sp = q.s[j];
    d.dphi[p] += -psi * g[j] * w[j] / sp;
    d.dgrad(j, p) += -g[j] / (sp * sp);
    for (int i = 0; i < 3; ++i) d.dgrad(i, p) += -(P(i, j) * w[j]) / (q.s[i] * sp);
  }
  // Exponent.
  double ell[3];
  for (int j = 0; j < 3; ++j) ell[j] = std::log(std::abs(w[j]));
  if (q.radial23) ell[1] = ell[2] = 0.5 * std::log(w[1] * w[1] + w[2] * w[2]);
  double mu = 0.0;
  for (int j = 0; j < 3; ++j) {
    const double t = g[j] * w[j];  // |w_j|^(2n), or the radial term's share
    if (t != 0.0) mu += t * ell[j];
  }
  mu /= q.n;
  d.dphi[q.n_index] = psi * mu;
  const double k = 2.0 * q.n - 1.0;
  for (int j = 0; j < 3; ++j)
    d.dgrad(j, q.n_index) = g[j] == 0.0 ? 0.0 : g[j] * (2.0 * ell[j] - k * mu) / q.s[j];
}

/// LogSumExp smooth maximum phi = (1/beta) log sum_j exp(beta c_j) of terms
/// c_j(theta, y) with weights pi_j (eq:smoothmax_grad). For a parameter
/// theta other than beta:
///   d phi = sum pi_j dc_j,
///   d G   = sum pi_j d(grad c_j) + beta sum pi_j (dc_j - d phi)(grad c_j - G),
/// the second term being d pi_j = beta pi_j (dc_j - d phi) in covariance
/// form; for beta itself:
///   d phi / d beta = (1/beta) sum pi_j (c_j - phi),
///   d G / d beta   = sum pi_j (c_j - cbar)(grad c_j - G),  cbar = sum pi_j c_j.

[[noreturn]] void bad_size(const char* family, int expected, long got) {
  throw std::invalid_argument(std::string("shape_with_params: ") + family + " expects " + std::to_string(expected) +
                              " parameters, got " + std::to_string(got));
}

}  // namespace

void eval_params(const Sphere& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d) {
  s.eval(y, e);
  d.dphi.setZero(1);
  d.dgrad.setZero(3, 1);
  const double R = s.R();
  const double sq = y.squaredNorm();
  const double ny = std::isnormal(sq) ? std::sqrt(sq) : y.stableNorm();  // as Sphere::eval(y, e)
  if (ny == 0.0) return;
  // phi = |y|/R - 1, grad = y / (|y| R).
  d.dphi[0] = -(ny / R) / R;
  d.dgrad.col(0) = -e.grad / R;
}

void eval_params(const Superellipsoid& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d) {
  s.eval(y, e);
  d.dphi.resize(4);
  d.dgrad.resize(3, 4);
  superquadric_params({Vec3(s.a(), s.b(), s.c()), {0, 1, 2}, 3, false, s.n()}, y, e, d);
}

void eval_params(const SuperellipticCylinder& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d) {
  s.eval(y, e);
  d.dphi.resize(3);
  d.dgrad.resize(3, 3);
  // Parameters (R, h, n): component 1 is scaled by h, 2 and 3 by R.
  superquadric_params({Vec3(s.h(), s.R(), s.R()), {1, 0, 0}, 2, true, s.n()}, y, e, d);
}

void eval_params(const SmoothPolytope& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d) {
  s.eval(y, e);
  const int m = s.num_halfspaces();
  d.dphi.setZero(4 * m + 1);
  d.dgrad.setZero(3, 4 * m + 1);
  const double beta = s.beta(), L = s.L(), k = beta / L;
  // Terms u_i = (a_i^T y - b_i) / L; weights with the maximum shifted out,
  // as in SmoothPolytope::eval.
  double cmax = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) cmax = std::max(cmax, s.normal(i).dot(y) - s.offset(i));
  double S0 = 0.0;
  for (int i = 0; i < m; ++i) S0 += std::exp(k * (s.normal(i).dot(y) - s.offset(i) - cmax));
  const double logS0 = std::log(S0);
  const Vec3 abar = L * e.grad;  // sum pi_i a_i
  double ubar_minus_phi = 0.0;   // sum pi_i (u_i - phi) <= 0, for d phi / d beta
  for (int i = 0; i < m; ++i) {
    const Vec3 a = s.normal(i);
    const double b = s.offset(i);
    const double du = (a.dot(y) - b - cmax) / L;  // u_i - umax <= 0
    const double pi = std::exp(k * (a.dot(y) - b - cmax)) / S0;
    ubar_minus_phi += pi * (du - logS0 / beta);
    // Derivatives w.r.t. the unnormalised a_i, b_i of
    // phi = smax_beta((a_i^T y - b_i) / L):
    //   d phi/da_i = pi_i y / L,          d phi/db_i = -pi_i / L,
    //   d G/da_i   = pi_i I / L + (beta / L^2) pi_i (a_i - abar) y^T,
    //   d G/db_i   = -(beta / L^2) pi_i (a_i - abar).
    const Eigen::RowVector3d dphi_da = (pi / L) * y.transpose();
    const double dphi_db = -pi / L;
    const Vec3 dev = (beta / (L * L)) * pi * (a - abar);
    const Mat3 dG_da = (pi / L) * Mat3::Identity() + dev * y.transpose();
    const Vec3 dG_db = -dev;
    // Through the constructor's normalisation at |A_i| = 1 (shape_params.hpp):
    // d/dA_i = d/da_i (I - a a^T) - b d/db_i a^T, d/dB_i = d/db_i.
    const Mat3 Pt = Mat3::Identity() - a * a.transpose();
    d.dphi.segment<3>(4 * i) = (dphi_da * Pt - (b * dphi_db) * a.transpose()).transpose();
    d.dphi[4 * i + 3] = dphi_db;
    d.dgrad.middleCols<3>(4 * i) = dG_da * Pt - b * dG_db * a.transpose();
    d.dgrad.col(4 * i + 3) = dG_db;
  }
  // beta: d phi/d beta = (1/beta) sum pi_i (u_i - phi);
  // d G/d beta = (1/L) sum pi_i (u_i - ubar)(a_i - abar).
  d.dphi[4 * m] = ubar_minus_phi / beta;
  const double ubar_shift = ubar_minus_phi + logS0 / beta;  // ubar - umax
  Vec3 dGb = Vec3::Zero();
  for (int i = 0; i < m; ++i) {
    const Vec3 a = s.normal(i);
    const double c = a.dot(y) - s.offset(i) - cmax;
    const double pi = std::exp(k * c) / S0;
    dGb += pi * (c / L - ubar_shift) * (a - abar);
  }
  d.dgrad.col(4 * m) = dGb / L;
}

void eval_params(const SmoothTruncatedCone& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d) {
  s.eval(y, e);
  d.dphi.setZero(5);
  d.dgrad.setZero(3, 5);
  const double Rb = s.Rb(), Rt = s.Rt(), a = s.a(), b = s.b(), beta = s.beta();
  const double h = a + b, kappa = (Rt - Rb) / h, Rfloor = 0.5 * std::min(Rb, Rt);
  const double t = (y[0] + a) / h;
  double R = Rb + kappa * (y[0] + a), kap = kappa;
  // dR/dtheta and dkappa/dtheta at fixed y, theta = (Rb, Rt, a, b).
  double dR[4] = {1.0 - t, t, kappa * (1.0 - t), -kappa * t};
  double dk[4] = {-1.0 / h, 1.0 / h, -kappa / h, -kappa / h};
  if (R < Rfloor) {  // the floor of SmoothTruncatedCone::eval: R = min(Rb, Rt)/2
    R = Rfloor;
    kap = 0.0;
    dR[0] = Rb <= Rt ? 0.5 : 0.0;
    dR[1] = Rb <= Rt ? 0.0 : 0.5;
    dR[2] = dR[3] = 0.0;
    for (double& v : dk) v = 0.0;
  }
  const double iR = 1.0 / R, iR2 = iR * iR, iR3 = iR2 * iR;
  const double r2 = y[1] * y[1] + y[2] * y[2];
  // Terms c_j and their gradients, as in SmoothTruncatedCone::eval.
  const double c[3] = {r2 * iR2 - 1.0, -y[0] / a - 1.0, y[0] / b - 1.0};
  const Vec3 gc[3] = {Vec3(-2.0 * kap * r2 * iR3, 2.0 * y[1] * iR2, 2.0 * y[2] * iR2), Vec3(-1.0 / a, 0.0, 0.0),
                      Vec3(1.0 / b, 0.0, 0.0)};
  const double cmax = std::max({c[0], c[1], c[2]});
  double pi[3], S = 0.0;
  for (int j = 0; j < 3; ++j) S += (pi[j] = std::exp(beta * (c[j] - cmax)));
  for (double& p : pi) p /= S;
  const Vec3& G = e.grad;
  for (int p = 0; p < 4; ++p) {
    double dc[3];
    Vec3 dgc[3];
    dc[0] = -2.0 * r2 * iR3 * dR[p];
    dgc[0] = Vec3(-2.0 * r2 * (dk[p] * iR3 - 3.0 * kap * iR3 * iR * dR[p]), -4.0 * y[1] * iR3 * dR[p],
                  -4.0 * y[2] * iR3 * dR[p]);
    dc[1] = p == 2 ? y[0] / (a * a) : 0.0;
    dgc[1] = Vec3(p == 2 ? 1.0 / (a * a) : 0.0, 0.0, 0.0);
    dc[2] = p == 3 ? -y[0] / (b * b) : 0.0;
    dgc[2] = Vec3(p == 3 ? -1.0 / (b * b) : 0.0, 0.0, 0.0);
    double dphi = 0.0;
    for (int j = 0; j < 3; ++j) dphi += pi[j] * dc[j];
    Vec3 dG = Vec3::Zero();
    for (int j = 0; j < 3; ++j) dG += pi[j] * dgc[j] + (beta * pi[j] * (dc[j] - dphi)) * (gc[j] - G);
    d.dphi[p] = dphi;
    d.dgrad.col(p) = dG;
  }
  // beta, with c_j - phi = (c_j - cmax) - log(S)/beta <= 0.
  double cbar_shift = 0.0;  // cbar - cmax
  for (int j = 0; j < 3; ++j) cbar_shift += pi[j] * (c[j] - cmax);
  d.dphi[4] = (cbar_shift - std::log(S) / beta) / beta;
  Vec3 dGb = Vec3::Zero();
  for (int j = 0; j < 3; ++j) dGb += pi[j] * ((c[j] - cmax) - cbar_shift) * (gc[j] - G);
  d.dgrad.col(4) = dGb;
}

void eval_params(const Shape& s, const Vec3& y, ShapeEval& e, ShapeParamEval& d) {
  std::visit([&](const auto& x) { eval_params(x, y, e, d); }, s);
}

// The scalar families' parameters are their table's (families.hpp): names,
// order, powers of length and constructor. The polytope's are its face rows
// and offsets, then beta (L held fixed).
int num_params(const Shape& s) {
  return std::visit(
      [](const auto& x) -> int {
        using T = std::decay_t<decltype(x)>;
        if constexpr (kScalarFamily<T>) return FamilyParams<T>::kCount;
        else return 4 * x.num_halfspaces() + 1;
      },
      s);
}

std::vector<std::string> param_names(const Shape& s) {
  return std::visit(
      [](const auto& x) -> std::vector<std::string> {
        using T = std::decay_t<decltype(x)>;
        std::vector<std::string> n;
        if constexpr (kScalarFamily<T>) {
          for (const FamilyParam* p : family_info<T>().scalars()) n.emplace_back(p->key);
        } else {
          for (int i = 0; i < x.num_halfspaces(); ++i) {
            const std::string k = std::to_string(i);
            n.insert(n.end(), {"A" + k + ".x", "A" + k + ".y", "A" + k + ".z", "b" + k});
          }
          n.push_back("beta");
        }
        return n;
      },
      s);
}

VecX shape_params(const Shape& s) {
  return std::visit(
      [](const auto& x) -> VecX {
        using T = std::decay_t<decltype(x)>;
        VecX t;
        if constexpr (kScalarFamily<T>) {
          const auto v = FamilyParams<T>::get(x);
          t = Eigen::Map<const VecX>(v.data(), FamilyParams<T>::kCount);
        } else {
          const int m = x.num_halfspaces();
          t.resize(4 * m + 1);
          for (int i = 0; i < m; ++i) {
            t.template segment<3>(4 * i) = x.normal(i);
            t[4 * i + 3] = x.offset(i);
          }
          t[4 * m] = x.beta();
        }
        return t;
      },
      s);
}

VecX param_length_powers(const Shape& s) {
  return std::visit(
      [](const auto& x) -> VecX {
        using T = std::decay_t<decltype(x)>;
        if constexpr (kScalarFamily<T>) {
          VecX p(FamilyParams<T>::kCount);
          Eigen::Index i = 0;
          for (const FamilyParam& q : family_info<T>().params) p[i++] = q.length_power;  // a scalar family has no arrays
          return p;
        } else {
          const int m = x.num_halfspaces();
          VecX p = VecX::Zero(4 * m + 1);
          for (int i = 0; i < m; ++i) p[4 * i + 3] = 1.0;
          return p;
        }
      },
      s);
}

Shape shape_with_params(const Shape& like, const VecX& t) {
  const int p = num_params(like);
  return std::visit(
      [&](const auto& x) -> Shape {
        using T = std::decay_t<decltype(x)>;
        if (t.size() != p) bad_size(T::kName, p, static_cast<long>(t.size()));
        if constexpr (kScalarFamily<T>) {
          return FamilyParams<T>::make(t.data());
        } else {
          const int m = x.num_halfspaces();
          std::vector<Vec3> A(m);
          std::vector<double> b(m);
          for (int i = 0; i < m; ++i) {
            A[i] = t.segment<3>(4 * i);
            b[i] = t[4 * i + 3];
          }
          return SmoothPolytope(A, b, t[4 * m], x.L());
        }
      },
      like);
}

Eigen::MatrixXd polytope_vertex_jacobian(const std::vector<Vec3>& V, const SmoothPolytope& P) {
  const ConvexHull hull = convex_hull(V, "polytope_vertex_jacobian vertices");
  const int m = P.num_halfspaces(), k = static_cast<int>(V.size());
  if (static_cast<int>(hull.faces.size()) != m)
    throw std::invalid_argument("polytope_vertex_jacobian: the hull of the vertices has " + std::to_string(hull.faces.size()) +
                                " faces but the polytope has " + std::to_string(m) +
                                " half-spaces: it was not built from these vertices");
  auto skew3 = [](const Vec3& v) {
    Mat3 S;
    S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
    return S;
  };
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(4 * m + 1, 3 * k + 1);
  for (int f = 0; f < m; ++f) {
    const HullFace& F = hull.faces[f];
    if (F.vertices.size() != 3)
      throw std::invalid_argument("polytope_vertex_jacobian: face " + std::to_string(f) + " has " +
                                  std::to_string(F.vertices.size()) +
                                  " coplanar vertices; vertex derivatives need every hull face to be a triangle "
                                  "(otherwise a perturbation changes the hull's faces)");
    const double scale = std::max(1.0, std::abs(F.offset));
    if ((F.normal - P.normal(f)).norm() > 1e-9 || std::abs(F.offset - P.offset(f)) > 1e-9 * scale)
      throw std::invalid_argument("polytope_vertex_jacobian: face " + std::to_string(f) +
                                  " of the hull differs from half-space " + std::to_string(f) +
                                  " of the polytope: it was not built from these vertices");
    int i0 = F.vertices[0], i1 = F.vertices[1], i2 = F.vertices[2];
    if ((V[i1] - V[i0]).cross(V[i2] - V[i0]).dot(F.normal) < 0.0) std::swap(i1, i2);  // outward N
    const Vec3 e1 = V[i1] - V[i0], e2 = V[i2] - V[i0];
    const Vec3 N = e1.cross(e2);
    const double nN = N.norm();
    const Vec3 a = N / nN;
    const Mat3 Pn = (Mat3::Identity() - a * a.transpose()) / nN;
    // dN = (dv1 - dv0) x e2 + e1 x (dv2 - dv0).
    const Mat3 dN[3] = {skew3(e2) - skew3(e1), -skew3(e2), skew3(e1)};
    const int idx[3] = {i0, i1, i2};
    for (int j = 0; j < 3; ++j) {
      const Mat3 da = Pn * dN[j];
      D.block<3, 3>(4 * f, 3 * idx[j]) += da;
      // b = a^T v0: db = v0^T da + a^T dv0.
      Eigen::RowVector3d db = V[i0].transpose() * da;
      if (j == 0) db += a.transpose();
      D.block<1, 3>(4 * f + 3, 3 * idx[j]) += db;
    }
  }
  D(4 * m, 3 * k) = 1.0;
  return D;
}

}  // namespace idcol
