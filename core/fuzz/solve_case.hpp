// Decoding of fuzz bytes into one contact query, and the properties every
// query must have. Shared by the libFuzzer target (fuzz_solve.cpp, clang
// only) and the GoogleTest replay of the corpus (core/tests/
// test_fuzz_regressions.cpp, any compiler), so a crash found by the fuzzer
// is replayed by ctest under the ordinary sanitizer build too.
//
// Byte layout: a stream read front to back; when the bytes run out every
// read returns zero, so every input (even the empty one) decodes to a query.
//   shape 1, shape 2   family byte, then that family's parameters
//   pose               rotation mode + data, translation mode + data
//   options            a flag byte, then any overridden fields
// Each double is read through `real()`: a tag byte picks a special value
// (0, -0, NaN, +-Inf, 1e+-300, subnormals, DBL_MAX, ...), a "sensible"
// value in [0.05, 20] from two bytes, or eight raw bytes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "idcol/derivatives.hpp"
#include "idcol/options.hpp"
#include "idcol/shapes.hpp"
#include "idcol/solver.hpp"

namespace idcol::fuzz {

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : p_(data), n_(size) {}
  uint8_t byte() { return i_ < n_ ? p_[i_++] : 0; }
  uint16_t u16() {
    const unsigned lo = byte(), hi = byte();
    return static_cast<uint16_t>(lo | (hi << 8));
  }
  double raw_double() {
    uint64_t bits = 0;
    for (int k = 0; k < 8; ++k) bits |= static_cast<uint64_t>(byte()) << (8 * k);
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  /// A double biased towards values that break numerics and values that
  /// make valid shapes (so the solver, not only validation, is exercised).
  double real() {
    static const double kSpecial[] = {0.0,
                                      -0.0,
                                      std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::infinity(),
                                      -std::numeric_limits<double>::infinity(),
                                      1e-300,
                                      1e300,
                                      -1.0,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::min(),
                                      std::numeric_limits<double>::max(),
                                      std::numeric_limits<double>::lowest(),
                                      1.0,
                                      1.0 + 1e-15,
                                      1e-10,
                                      1e10,
                                      1024.0,
                                      1025.0,
                                      -1e300,
                                      1e-8};
    constexpr int kNumSpecial = sizeof kSpecial / sizeof kSpecial[0];
    const uint8_t tag = byte();
    if (tag < 2 * kNumSpecial) return kSpecial[tag % kNumSpecial];
    if (tag < 230) return 0.05 + 19.95 * (u16() / 65535.0);  // sensible
    if (tag < 245) return std::ldexp(1.0 + u16() / 65536.0, static_cast<int>(byte()) - 128);  // any scale
    return raw_double();
  }
  /// A unit-ish direction; may be zero or non-finite if the bytes say so.
  /// Reads are sequenced explicitly: argument evaluation order differs
  /// between gcc and clang, and the corpus must decode the same under both.
  Vec3 vec3() {
    const double x = real() - 10.0, y = real() - 10.0, z = real() - 10.0;
    return Vec3(x, y, z);
  }
  size_t consumed() const { return i_; }

 private:
  const uint8_t* p_;
  size_t n_;
  size_t i_ = 0;
};

/// Builds a shape from the stream. Returns nullopt when construction throws
/// std::invalid_argument (the documented reaction to bad parameters); any
/// other exception escapes and is a finding. `error` receives the message.
inline std::optional<Shape> read_shape(ByteReader& in, std::string* error = nullptr) {
  try {
    switch (in.byte() % 7) {
      case 0: return Shape(Sphere(in.real()));
      case 1: {
        const double a = in.real(), b = in.real(), c = in.real(), n = in.real();
        return Shape(Superellipsoid(a, b, c, n));
      }
      case 2: {
        const double R = in.real(), h = in.real(), n = in.real();
        return Shape(SuperellipticCylinder(R, h, n));
      }
      case 3: {
        const double Rb = in.real(), Rt = in.real(), a = in.real(), b = in.real(), beta = in.real();
        return Shape(SmoothTruncatedCone(Rb, Rt, a, b, beta));
      }
      case 4: {  // half-spaces from raw normals and offsets
        const int m = in.byte() % 21;  // 0..20: fewer than 4 is rejected
        std::vector<Vec3> A(m);
        std::vector<double> b(m);
        for (int i = 0; i < m; ++i) {
          A[i] = in.vec3();
          b[i] = in.real();
        }
        const double beta = in.real(), L = in.real();
        return Shape(SmoothPolytope(A, b, beta, L));
      }
      case 5: {  // a box or octahedron with fuzzed offsets and a fuzzed extra face
        const bool octa = in.byte() & 1;
        std::vector<Vec3> A;
        if (octa) {
          for (int s = 0; s < 8; ++s) A.emplace_back(s & 1 ? -1 : 1, s & 2 ? -1 : 1, s & 4 ? -1 : 1);
        } else {
          A = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        }
        std::vector<double> b;
        for (size_t i = 0; i < A.size(); ++i) b.push_back(in.real());
        if (in.byte() & 1) {
          A.push_back(in.vec3());
          b.push_back(in.real());
        }
        const double beta = in.real();
        return Shape(SmoothPolytope(A, b, beta, 1.0));
      }
      default: {  // vertex list
        const int m = in.byte() % 17;  // 0..16
        std::vector<Vec3> V(m);
        for (int i = 0; i < m; ++i) V[i] = in.vec3();
        const double beta = in.real(), L = in.real();
        return Shape(SmoothPolytope::from_vertices(V, beta, L));
      }
    }
  } catch (const std::invalid_argument& e) {
    if (error) *error = e.what();
    return std::nullopt;
  }
}

inline Pose read_pose(ByteReader& in) {
  Pose X;
  const uint8_t rmode = in.byte() % 6;
  if (rmode >= 1 && rmode <= 4) {
    const double qw = in.real() - 10.0, qx = in.real() - 10.0, qy = in.real() - 10.0, qz = in.real() - 10.0;
    Eigen::Quaterniond q(qw, qx, qy, qz);
    const double nq = q.norm();
    if (std::isfinite(nq) && nq > 0.0) q.coeffs() /= nq;
    X.R = q.toRotationMatrix();  // not orthonormal when q was not normalisable
    if (rmode == 2) X.R.col(in.byte() % 3) *= -1.0;           // reflection, det -1
    if (rmode == 3) {  // off by 2^-k
      const int i = in.byte() % 3, j = in.byte() % 3;
      X.R(i, j) += std::ldexp(1.0, -(in.byte() % 64));
    }
    if (rmode == 4) {  // one arbitrary entry
      const int i = in.byte() % 3, j = in.byte() % 3;
      X.R(i, j) = in.real();
    }
  } else if (rmode == 5) {
    for (int i = 0; i < 9; ++i) X.R(i / 3, i % 3) = in.real();
  }
  switch (in.byte() % 4) {
    case 0: X.p.setZero(); break;  // concentric
    case 1: X.p = in.vec3(); break;
    case 2: {  // |r| = 10^k, k in [-320, 310]: subnormal up to overflow of the norm
      Vec3 u = in.vec3();
      const double nu = u.norm();
      if (std::isfinite(nu) && nu > 0.0) u /= nu;
      X.p = u * std::pow(10.0, static_cast<int>(in.u16() % 631) - 320);
      break;
    }
    default:
      for (int i = 0; i < 3; ++i) X.p[i] = in.raw_double();
  }
  return X;
}

/// Options: defaults unless the flag byte says otherwise. Returns nullopt
/// when validate() rejects them. Iteration budgets are capped so that a
/// single query stays fast: an absurd budget is the caller's choice of
/// running time, not a hang.
inline std::optional<SolverOptions> read_options(ByteReader& in) {
  SolverOptions o;
  const uint8_t flags = in.byte();
  if (flags & 1) o.tolerance = in.real() * 1e-10;
  if (flags & 2) {
    o.max_iterations = in.byte() % 80;
    o.max_restarts = in.byte() % 12;
  }
  if (flags & 4) {
    o.surrogate_factor = in.real();
    o.max_step_s = in.real();
    o.max_step_x = in.real();
  }
  if (flags & 8) {
    o.armijo_c = in.real() * 0.025;
    o.backtrack_factor = in.real() * 0.05;
    o.max_backtracks = in.byte() % 40;
  }
  if (flags & 16) {
    o.lambda_fraction_to_boundary = in.real() * 0.05;
    o.lambda_fraction_to_boundary_restart = in.real() * 0.05;
    o.min_pivot_ratio = in.real() * 1e-13;
  }
  if (flags & 32) {
    o.lm_initial_damping = in.real() * 1e-6;
    o.lm_max_trials = in.byte() % 16;
    o.lm_stall_limit = in.byte() % 4;
    o.lm_min_progress = in.real() * 1e-3;
    o.bound_margin = in.real() * 1e-3;
  }
  if (flags & 64) {
    const auto c = in.byte();
    o.continuation = c & 1;
    o.support_guess = !(c & 2);
    o.rounding_continuation = in.byte() & 1;
    o.warm_fallback_to_cold = in.byte() & 1;
    o.continuation_ratio = in.real() * 0.2;
  }
  try {
    o.validate();
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
  return o;
}

namespace detail {
inline bool has_nan(double v) { return std::isnan(v); }
template <class M>
bool has_nan(const Eigen::MatrixBase<M>& m) {
  return m.hasNaN();
}
inline std::string fmt(const Pose& X) {
  std::ostringstream os;
  os.precision(17);
  os << "R = [" << X.R.row(0) << "; " << X.R.row(1) << "; " << X.R.row(2) << "], p = [" << X.p.transpose() << "]";
  return os.str();
}
}  // namespace detail

/// Checks the documented contract of one result. Returns "" or what broke.
inline std::string check_result(const Pose& X, const SolveResult& r) {
  using detail::has_nan;
  const PoseCheck pc = check_pose(X);
  // No NaN with a status that claims an answer or rejects the input. A
  // failed solve (NumericalFailure, ...) returns its last iterate, which may
  // be NaN; the status says so.
  const bool answer = r.status == SolveStatus::Converged || r.status == SolveStatus::Concentric ||
                      r.status == SolveStatus::InvalidInput;
  if (answer && (has_nan(r.alpha) || has_nan(r.x_1) || has_nan(r.lambda1) || has_nan(r.lambda2) || has_nan(r.residual_norm)))
    return std::string("NaN in the result, status ") + to_string(r.status);
  if (pc != PoseCheck::Ok) {
    if (r.status != SolveStatus::InvalidInput) return std::string("bad pose (") + to_string(pc) + ") gave " + to_string(r.status);
    return "";
  }
  if (r.status == SolveStatus::InvalidInput) return "valid pose reported InvalidInput";
  if ((X.p.array() == 0.0).all() != (r.status == SolveStatus::Concentric)) return std::string("r = 0 <=> Concentric broken: ") + to_string(r.status);
  if (r.status == SolveStatus::Concentric && (r.alpha != 0.0 || !r.x_1.isZero())) return "Concentric with alpha or x nonzero";
  if (r.iterations < 0 || r.restarts < 0) return "negative iteration count";
  if (r.converged()) {
    if (!std::isfinite(r.alpha) || !(r.alpha > 0.0)) return "Converged with alpha not finite and > 0";
    if (!r.x_1.allFinite()) return "Converged with non-finite x";
    if (!std::isfinite(r.lambda1) || !std::isfinite(r.lambda2) || !(r.lambda1 > 0.0) || !(r.lambda2 > 0.0))
      return "Converged with multipliers not finite and > 0";
    if (!std::isfinite(r.residual_norm)) return "Converged with non-finite residual";
  }
  return "";
}

/// Derivatives of a converged result: finite, or flagged (valid = false, or
/// Conditioning::reliable = false) as derivatives.hpp documents.
inline std::string check_derivatives_of(const SolveResult& r) {
  if (!r.converged()) return "";
  const SolutionSensitivity s = solution_sensitivity(r);
  if (!s.valid) return "solution_sensitivity invalid on a converged result";
  const bool flagged = !s.cond.reliable;
  if (!s.dz_dxi.allFinite() && !flagged) return "non-finite sensitivity not flagged unreliable";
  const Row6 ga = alpha_gradient(r), gg = gap_gradient(r);
  if ((!ga.allFinite() || !gg.allFinite()) && !flagged) return "non-finite alpha/gap gradient not flagged";
  const ContactKinematics k = contact_kinematics(r);
  if (!k.valid) return "contact_kinematics invalid on a converged result";
  const bool k_fits = k.p1_1.allFinite() && k.p2_1.allFinite() && std::isfinite(k.gap);
  if (k.representable != k_fits) return "contact_kinematics representable flag wrong";
  if (k.nhat_1.hasNaN()) return "contact_kinematics normal not finite";
  if (!k.representable) {
    // Only where the exact values leave the double range (radii 1e300 and
    // 1.8e308 found it): eq:witness and eq:gap in long double, whose range
    // holds them, from the same alpha, x and r.
    const long double a = r.alpha, r0 = r.internal.r[0], r1 = r.internal.r[1], r2 = r.internal.r[2];
    const long double nr = std::sqrt(r0 * r0 + r1 * r1 + r2 * r2);
    long double big = std::fabs(nr - nr / a);
    for (int i = 0; i < 3; ++i) {
      const long double ri = r.internal.r[i], xi = r.x_1[i];
      big = std::max({big, std::fabs(xi / a), std::fabs(ri + (xi - ri) / a)});
    }
    if (!(big > 0.999 * static_cast<long double>(std::numeric_limits<double>::max())))
      return "contact_kinematics not finite although it fits";
    return "";
  }
  const ContactKinematicsDerivatives kd = contact_kinematics_derivatives(r, s);
  if (!kd.valid) return "contact_kinematics_derivatives invalid";
  if (!flagged && (!kd.dp1_1_dxi.allFinite() || !kd.dp2_1_dxi.allFinite() || !kd.dnhat_1_dxi.allFinite() || !kd.dgap_dxi.allFinite()))
    return "non-finite kinematics derivatives not flagged";
  const HertzModel hm;
  const ContactWrench w = contact_wrench(r, hm);
  if (!w.valid) return "contact_wrench invalid";
  // k delta^p genuinely overflows for a penetration depth beyond ~1e205
  // (bodies of size 1e243 found it), and a moment |r| f_n beyond 1.8e308
  // (|r| = 1.8e84 against a body of 4.6e233 found it). The wrench then says
  // so (representable = false); it never says so where the wrench fits.
  const bool fits = std::isfinite(w.f_n) && w.F1_1.allFinite() && w.F2_2.allFinite();
  if (w.representable != fits) return "contact_wrench representable flag wrong";
  if (!w.representable) {
    const double arm = std::max({1.0, r.x_1.norm(), r.internal.r.norm()});
    if (std::isfinite(w.f_n) && !(w.f_n > 1e300 / arm)) return "contact_wrench not finite although it fits";
    return "";
  }
  const ContactWrenchDerivatives wd = contact_wrench_derivatives(r, s, hm);
  if (!flagged && (!wd.df_n_dxi.allFinite() || !wd.dF1_1_dxi.allFinite() || !wd.dF2_2_dxi.allFinite()))
    return "non-finite wrench derivatives not flagged";
  return "";
}

/// The whole property for one input. Returns "" or a description that
/// includes the shapes and pose at 17 digits, ready to paste into a test.
inline std::string run_case(const uint8_t* data, size_t size) {
  ByteReader in(data, size);
  const std::optional<Shape> s1 = read_shape(in);
  if (!s1) return "";
  const std::optional<Shape> s2 = read_shape(in);
  if (!s2) return "";
  const Pose X = read_pose(in);
  const std::optional<SolverOptions> opt = read_options(in);
  if (!opt) return "";
  auto where = [&] { return "\n  body1 " + describe(*s1) + "\n  body2 " + describe(*s2) + "\n  X_12 " + detail::fmt(X); };

  // Derivatives are taken of every converged result below.
  SolverOptions o = *opt;
  o.derivatives = true;
  WarmStart warm;
  const SolveResult r = solve(*s1, *s2, X, o, &warm);
  std::string err = check_result(X, r);
  if (err.empty()) err = check_derivatives_of(r);
  if (!err.empty()) return "cold solve: " + err + where();
  // Again from the warm start the first solve left (if it converged), at a
  // pose nudged along r, as a sequence of queries would.
  Pose X2 = X;
  X2.p *= 1.0 + 1e-3;
  const SolveResult r2 = solve(*s1, *s2, X2, o, &warm);
  err = check_result(X2, r2);
  if (err.empty()) err = check_derivatives_of(r2);
  if (!err.empty()) return "warm solve: " + err + where();
  return "";
}

}  // namespace idcol::fuzz
