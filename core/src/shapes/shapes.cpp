#include "idcol/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "idcol/convex_hull.hpp"
#include "idcol/families.hpp"
#include "idcol/detail/fast_math.hpp"
#include "idcol/detail/formulas/support.hpp"
#include "polytope_kernel.hpp"

namespace idcol {
namespace {

[[noreturn]] void fail(const char* shape, const std::string& msg) {
  throw std::invalid_argument(std::string(shape) + ": " + msg);
}

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

/// The family's scalar parameters, each checked against its range in the
/// family's table (families.hpp), in the table's order.
template <class T>
void check_scalars(std::initializer_list<double> v) {
  auto it = v.begin();
  for (const FamilyParam& p : family_info<T>().params)
    if (!p.array) check_param(T::kName, p, *it++);
}

/// |v|, as norm() gives it where the squares are normal doubles, and by
/// stableNorm() where they are not (rows of 1e300 or 1e-160).
double range_safe_norm(const Vec3& v) {
  const double sq = v.squaredNorm();
  return std::isnormal(sq) && std::isfinite(sq) ? std::sqrt(sq) : v.stableNorm();
}

/// q = n/(n-1)-norm helper: (sum s_i^(2q))^(1/(2q)), or max s_i for n = 1.
double conjugate_norm(const double* s, int k, double n) {
  double smax = 0.0;
  for (int i = 0; i < k; ++i) smax = std::max(smax, s[i]);
  if (n == 1.0) return smax;
  const double q2 = 2.0 * n / (n - 1.0);
  double acc = 0.0;
  for (int i = 0; i < k; ++i) acc += std::pow(s[i] / smax, q2);
  return smax * std::pow(acc, 1.0 / q2);
}

}  // namespace

namespace detail {
Exponent::Exponent(double n_) : n(n_) {
  // n_ >= 1 first: shapes build their Exponent before validating n, and the
  // cast of -Inf or -1e300 to int is undefined behaviour
  // (UBSan float-cast-overflow; found while writing fuzz_solve).
  n_int = (n_ >= 1.0 && n_ <= 1024.0 && n_ == std::floor(n_)) ? static_cast<int>(n_) : 0;
  sqrt_depth = -1;
  if (n_int > 0) {
    const int two_n = 2 * n_int;
    if ((two_n & (two_n - 1)) == 0) {
      int k = 0;
      while ((1 << k) < two_n) ++k;
      sqrt_depth = k;
    }
  }
}
}  // namespace detail

// ---------------------------------------------------------------- Sphere
Sphere::Sphere(double R) : R_(R), iR_(1.0 / R) { check_scalars<Sphere>({R}); }

// ---------------------------------------------------------- Superellipsoid
Superellipsoid::Superellipsoid(double a, double b, double c, double n) : ax_(a, b, c), inv_(1.0 / a, 1.0 / b, 1.0 / c), ex_(n) {
  check_scalars<Superellipsoid>({a, b, c, n});
  rad_ = radii(n);
}

Radii Superellipsoid::radii(double sharp) const {
  const double s[3] = {ax_[0], ax_[1], ax_[2]};
  return {ax_.minCoeff(), conjugate_norm(s, 3, sharp)};
}

namespace {
/// The support point of a unit superquadric ||w||_2n <= 1 in scaled
/// coordinates, for the scaled direction v (entries of any sign, not all
/// zero): the surface point whose normal is along v, w_i proportional to
/// sign(v_i) |v_i|^(1/(2n-1)), normalised onto the surface. N is 3 for the
/// superellipsoid and 2 for the cylinder (axial, radial).
template <int N>
Eigen::Matrix<double, N, 1> superquadric_support(const Eigen::Matrix<double, N, 1>& v, const detail::Exponent& ex) {
  double vv[N], w[N];
  for (int i = 0; i < N; ++i) vv[i] = v[i];
  bool bad = false;
  detail::formulas::superquadric_support<detail::ScalarNum, N>(ex, vv, w, bad);  // w = 0 for v = 0
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(w);
}
}  // namespace

Vec3 Superellipsoid::support_point(const Vec3& u, double sharp) const {
  const detail::Exponent ex = sharp == ex_.n ? ex_ : detail::Exponent(sharp);
  return ax_.cwiseProduct(superquadric_support<3>(ax_.cwiseProduct(u), ex));
}

// ------------------------------------------------- SuperellipticCylinder
Vec3 SuperellipticCylinder::support_point(const Vec3& u, double sharp) const {
  const detail::Exponent ex = sharp == ex_.n ? ex_ : detail::Exponent(sharp);
  const double w = detail::hypot_any(u[1], u[2]);
  const Eigen::Vector2d p = superquadric_support<2>(Eigen::Vector2d(h_ * u[0], R_ * w), ex);
  const double radial = w > 0.0 ? R_ * p[1] / w : 0.0;
  return Vec3(h_ * p[0], radial * u[1], radial * u[2]);
}

SuperellipticCylinder::SuperellipticCylinder(double R, double h, double n) : R_(R), h_(h), ex_(n) {
  check_scalars<SuperellipticCylinder>({R, h, n});
  rad_ = radii(n);
}

Radii SuperellipticCylinder::radii(double sharp) const {
  const double s[2] = {R_, h_};
  return {std::min(R_, h_), conjugate_norm(s, 2, sharp)};
}

// -------------------------------------------------------- SmoothPolytope
SmoothPolytope::SmoothPolytope(const std::vector<Vec3>& A, const std::vector<double>& b, double beta, double L) {
  init(A, b, beta, L);
}

void SmoothPolytope::init(const std::vector<Vec3>& A, const std::vector<double>& b, double beta, double L) {
  check_scalars<SmoothPolytope>({beta, L});
  if (A.size() != b.size())
    fail(kName, "field 'A' has " + std::to_string(A.size()) + " rows but field 'b' has " + std::to_string(b.size()) + " entries");
  const int m = static_cast<int>(A.size());
  if (m < 4) fail(kName, "needs at least 4 half-spaces to be bounded, got " + std::to_string(m));
  ax_.resize(m);
  ay_.resize(m);
  az_.resize(m);
  b_.resize(m);
  std::vector<Vec3> dual(m);
  for (int i = 0; i < m; ++i) {
    if (!A[i].allFinite())
      fail(kName, "field 'A' row " + std::to_string(i) + " = (" + num(A[i].x()) + ", " + num(A[i].y()) + ", " + num(A[i].z()) + ") is not finite");
    if (!std::isfinite(b[i])) fail(kName, "field 'b'[" + std::to_string(i) + "] = " + num(b[i]) + " is not finite");
    const double nrm = range_safe_norm(A[i]);
    if (!(nrm > 0.0)) fail(kName, "field 'A' row " + std::to_string(i) + " is zero");
    const Vec3 a = A[i] / nrm;
    const double bi = b[i] / nrm;
    if (!(bi > 0.0))
      fail(kName, "does not hold its frame origin strictly inside: half-space " + std::to_string(i) + " has b = " + num(b[i]) +
                      " <= 0 (the polytope may also be empty)");
    if (!std::isnormal(bi))
      fail(kName, "half-space " + std::to_string(i) + " has b = " + num(b[i]) + " (" + num(bi) +
                      " after normalisation), a subnormal double; offsets must be at least " + num(std::numeric_limits<double>::min()));
    ax_[i] = a.x();
    ay_[i] = a.y();
    az_[i] = a.z();
    b_[i] = bi;
    dual[i] = a / bi;
  }
  beta_ = beta;
  L_ = L;
  bmin_ = *std::min_element(b_.begin(), b_.end());

  // Bounded iff the origin is strictly inside the hull of the polar dual
  // points a_i / b_i; each dual facet n^T d = h gives the vertex n / h.
  // A frame origin very close to one face (b_min / b_max under 1e-9) puts
  // that face's dual point 10^9 times farther out than the others, and the
  // dual hull cannot resolve them: that is what a failure means then, not
  // that the polytope is unbounded.
  const int inear = static_cast<int>(std::min_element(b_.begin(), b_.end()) - b_.begin());
  const double bmax = *std::max_element(b_.begin(), b_.end());
  auto unbounded = [&](const char* why) {
    if (bmin_ < 1e-9 * bmax)
      fail(kName, "its frame origin is " + num(bmin_) + " from half-space " + std::to_string(inear) + " (after normalisation), " +
                      num(bmin_ / bmax) + " of the farthest face's offset " + num(bmax) +
                      ": too close to that face to enumerate the vertices in doubles; place the frame origin deeper inside");
    fail(kName, why);
  };
  ConvexHull dh;
  try {
    dh = convex_hull(dual, "smooth_polytope dual");
  } catch (const std::invalid_argument&) {
    unbounded("is unbounded: the half-space normals do not surround the origin");
  }
  vertices_.clear();
  rout_ = 0.0;
  for (const HullFace& f : dh.faces) {
    if (!(f.offset > 1e-12 * range_safe_norm(dual[0])))
      unbounded("is unbounded: the half-space normals do not positively span R^3");
    vertices_.push_back(f.normal / f.offset);
    rout_ = std::max(rout_, range_safe_norm(vertices_.back()));
  }
  // The smooth body must hold the origin: phi(0) = smax(-b/L) < 0.
  m_ = m;
  rad_ = radii(beta_);
  m4_ = (m + 3) / 4 * 4;
  slot_ = m4_ <= 16 ? m4_ / 4 : 0;
  faces_.assign(4 * static_cast<std::size_t>(m4_), 0.0);
  for (int i = 0; i < m4_; ++i) {
    faces_[i] = i < m ? ax_[i] : 0.0;
    faces_[m4_ + i] = i < m ? ay_[i] : 0.0;
    faces_[2 * m4_ + i] = i < m ? az_[i] : 0.0;
    faces_[3 * m4_ + i] = i < m ? b_[i] : std::numeric_limits<double>::infinity();
  }
  if (!(rad_.inner > 0.0))
    fail(kName, "field 'beta' = " + num(beta) + " is too small: the smoothed body no longer holds its frame origin (need sum exp(-beta b_i / L) < 1)");
}

SmoothPolytope SmoothPolytope::from_vertices(const std::vector<Vec3>& V, double beta, double L) {
  const ConvexHull h = convex_hull(V, "smooth_polytope vertices");
  std::vector<Vec3> A;
  std::vector<double> b;
  for (const HullFace& f : h.faces) {
    A.push_back(f.normal);
    b.push_back(f.offset);
  }
  return SmoothPolytope(A, b, beta, L);
}

SmoothPolytope SmoothPolytope::scaled(double f) const {
  SmoothPolytope s(*this);
  for (double& bi : s.b_) bi *= f;
  for (int i = 0; i < m_; ++i) s.faces_[3 * m4_ + i] *= f;
  for (Vec3& v : s.vertices_) v *= f;
  s.L_ *= f;
  s.bmin_ *= f;
  s.rout_ *= f;
  s.rad_ = {rad_.inner * f, rad_.outer * f};
  return s;
}

double SmoothPolytope::continuation_start() const {
  const double m = static_cast<double>(m_);
  return std::min(beta_, std::max(beta_ / 16.0, 4.0 * L_ * std::log(m) / bmin_));
}

Radii SmoothPolytope::radii(double sharp) const {
  // inner = -L smax_sharp(-b/L) = bmin - (L/sharp) log sum exp(-sharp (b_i - bmin)/L)
  double acc = 0.0;
  for (double bi : b_) acc += std::exp(-sharp * (bi - bmin_) / L_);
  return {bmin_ - L_ / sharp * std::log(acc), rout_};
}

Vec3 SmoothPolytope::support_point(const Vec3& u, double /*sharp*/) const {
  double q[3];
  bool bad = false;
  detail::formulas::polytope_support<detail::ScalarNum>(
      static_cast<int>(vertices_.size()), [&](int i, int k) { return vertices_[i][k]; }, 1e-9 * rout_, u, q, bad);
  return Vec3(q[0], q[1], q[2]);  // a vertex always qualifies: the one that gives the support
}

void SmoothPolytope::eval(const Vec3& y, double sharp, ShapeEval& e) const { eval_impl<true>(y, sharp, e); }

void SmoothPolytope::eval_phi_grad(const Vec3& y, double sharp, ShapeEval& e) const { eval_impl<false>(y, sharp, e); }

namespace {
/// The face loop for this CPU, chosen once when the library loads: AVX2
/// with FMA where the CPU has both (IDCOL_SIMD=none or sse2 in the
/// environment keeps SSE2); see polytope_kernel.hpp.
detail::PolytopeKernels pick_polytope_kernels() {
#if defined(IDCOL_POLYTOPE_AVX2)
  const char* env = std::getenv("IDCOL_SIMD");
  const bool capped = env && (!std::strcmp(env, "none") || !std::strcmp(env, "sse2"));
  __builtin_cpu_init();
  if (!capped && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return detail::polytope_kernels_avx2();
#endif
  return detail::polytope_kernels_sse2();
}
const detail::PolytopeKernels kPolytopeKernels = pick_polytope_kernels();
}  // namespace

const char* detail::polytope_kernel_isa() { return kPolytopeKernels.isa; }

// The kernel writes phi, grad and hess as 13 consecutive doubles.
static_assert(offsetof(ShapeEval, grad) == sizeof(double) && offsetof(ShapeEval, hess) == 4 * sizeof(double),
              "ShapeEval is phi, grad, hess without padding");

template <bool kHessian>
void SmoothPolytope::eval_impl(const Vec3& y, double sharp, ShapeEval& e) const {
  (kHessian ? kPolytopeKernels.with_hessian : kPolytopeKernels.without_hessian)[slot_](faces_.data(), m4_, y.data(), sharp, L_, &e.phi);
}

// --------------------------------------------------- SmoothTruncatedCone
SmoothTruncatedCone::SmoothTruncatedCone(double Rb, double Rt, double a, double b, double beta)
    : Rb_(Rb), Rt_(Rt), a_(a), b_(b), beta_(beta) {
  check_scalars<SmoothTruncatedCone>({Rb, Rt, a, b, beta});
  if (!(beta > std::log(3.0)))
    fail(kName, "field 'beta' = " + num(beta) + " is too small: need beta > log 3 = 1.0986 for the smoothed body to hold its frame origin");
  h_ = a + b;
  kappa_ = (Rt - Rb) / h_;
  Rfloor_ = 0.5 * std::min(Rb, Rt);
  k_ = consts();
  rad_ = radii(beta);
}

double SmoothTruncatedCone::continuation_start() const { return std::min(beta_, std::max(beta_ / 16.0, 4.0 * std::log(3.0))); }

Radii SmoothTruncatedCone::radii(double sharp) const {
  const double d = std::log(3.0) / sharp;
  const double k = std::sqrt(std::max(0.0, 1.0 - d));
  const double R0 = Rb_ + kappa_ * a_;  // R(0)
  const double side = k * R0 / std::sqrt(1.0 + k * k * kappa_ * kappa_);
  const double inner = std::min({a_ * (1.0 - d), b_ * (1.0 - d), side});
  const double outer = std::max(std::hypot(a_, Rb_), std::hypot(b_, Rt_));
  return {inner, outer};
}

Vec3 SmoothTruncatedCone::support_point(const Vec3& u, double /*sharp*/) const {
  double p[3];
  detail::formulas::cone_support<detail::ScalarNum>(Rb_, Rt_, a_, b_, u, p);
  return Vec3(p[0], p[1], p[2]);
}

void SmoothTruncatedCone::eval(const Vec3& y, double sharp, ShapeEval& e) const {
  bool leaves = false;  // the scalar layer answers every point (log_ge1)
  detail::formulas::smooth_truncated_cone<detail::ScalarNum>(k_, sharp, y[0], y[1], y[2], e, leaves);
}

// ------------------------------------------------------------- variant
const char* family_name(const Shape& s) {
  return std::visit([](const auto& x) { return std::decay_t<decltype(x)>::kName; }, s);
}

Radii radii(const Shape& s) {
  return std::visit([](const auto& x) { return x.radii(); }, s);
}

void eval(const Shape& s, const Vec3& y, ShapeEval& e) {
  std::visit([&](const auto& x) { x.eval(y, e); }, s);
}

std::string describe(const Shape& s) {
  std::ostringstream os;
  os << std::setprecision(17);
  std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        os << "{ family = \"" << T::kName << "\"";
        if constexpr (kScalarFamily<T>) {
          const auto v = FamilyParams<T>::get(x);
          std::size_t i = 0;
          for (const FamilyParam& p : family_info<T>().params) os << ", " << p.key << " = " << v[i++];
        } else {
          os << ", normals = [";
          for (int i = 0; i < x.num_halfspaces(); ++i) {
            const Vec3 a = x.normal(i);
            os << (i ? ", " : "") << "[" << a.x() << ", " << a.y() << ", " << a.z() << "]";
          }
          os << "], offsets = [";
          for (int i = 0; i < x.num_halfspaces(); ++i) os << (i ? ", " : "") << x.offset(i);
          os << "], beta = " << x.beta() << ", L = " << x.L();
        }
        os << " }";
      },
      s);
  return os.str();
}

}  // namespace idcol
