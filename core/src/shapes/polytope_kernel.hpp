// The smooth polytope's loop over its faces (SmoothPolytope::eval): the face
// values c_i = a_i.y - b_i, their maximum, the LogSumExp weights
// w_i = exp(k (c_i - c_max)), the weighted moments of the normals about the
// dominant one, and from them phi, grad phi and hess phi
// (eq:smoothmax_grad, eq:smoothmax_hessian).
//
// Compiled once per instruction set and picked at run time (shapes.cpp):
// polytope_kernel_sse2.cpp (the x86-64 baseline, and any other target) and
// polytope_kernel_avx2.cpp (-mavx2 -mfma, for CPUs with both). Both run the
// same operations in the same order: four partial sums per moment (faces
// i = 0, 1, 2, 3 mod 4), summed as (s0 + s1) + (s2 + s3), the same exp.
// With SSE2 a vector of four is two instructions, with AVX2 one. The AVX2
// kernel fuses multiplies and adds where the code asks for it (mul_add: the
// exp's argument reduction and polynomial, the face values, the second
// moments), so its results differ from the SSE2 kernel's by rounding (about
// 1e-16 relative per evaluation; over the paper sweep the solver's alpha*
// by up to 9e-16 and x by up to 5e-14 relative, the same iteration counts).
// The kernels with and without the Hessian give the same phi and grad on
// one CPU, and one CPU always gives the same bits. Each face's arithmetic
// (its value, its weight by exp_nonpositive, its moments) is the formulas'
// (formulas/shape_eval.hpp: polytope_face_value, PolytopeFaceSums), which
// the Newton lanes run too, one face for W poses; this file keeps only the
// layout: four faces a vector, blocks of faces, the maximum.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "idcol/detail/formulas/shape_eval.hpp"  // templates only: instantiated here over KernelNum, this unit's own
#if defined(__FMA__)
#include <immintrin.h>
#endif

namespace idcol::detail {

/// phi, grad phi and (with the Hessian) hess phi at y, sharpness `sharp`,
/// rounding length L (SmoothPolytope::eval): `faces` holds four columns of
/// m4 entries (a_x, a_y, a_z, b; m4 a multiple of 4, padded with a = 0,
/// b = +inf, whose c_i = -inf never wins the maximum and weighs exactly 0),
/// and `e` receives phi, grad (3) and hess (9, column-major; untouched
/// without the Hessian) in a row, as ShapeEval holds them.
using PolytopeKernelFn = void (*)(const double* faces, int m4, const double* y, double sharp, double L, double* e);

// Internal linkage: each per-instruction-set translation unit keeps its own
// copy (one shared inline definition would be compiled for one of them).
// The four-lane helpers are inlined into the kernels, so that their vector
// arguments never cross a call: GCC's note that such a call's ABI differs
// without AVX does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
namespace {
namespace polytope_kernel {

// Two-input lane shuffles: GCC's builtin takes a vector of indices,
// clang's a list.
#if defined(__clang__)
#define IDCOL_SHUFFLE2(a, b, i, j) __builtin_shufflevector(a, b, i, j)
#define IDCOL_SHUFFLE4(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define IDCOL_SHUFFLE2(a, b, i, j) __builtin_shuffle(a, b, v2i{i, j})
#define IDCOL_SHUFFLE4(a, b, i, j, k, l) __builtin_shuffle(a, b, v4i{i, j, k, l})
#endif

#if defined(IDCOL_POLYTOPE_PAIRS)
// A vector of four as two of two (SSE2): GCC lowers a 32-byte vector
// without AVX through memory, two SSE2 registers it keeps in registers.
using v2d = double __attribute__((vector_size(16)));
using v2i = std::int64_t __attribute__((vector_size(16)));
struct v4d {
  v2d lo, hi;
  double operator[](int i) const { return i < 2 ? lo[i] : hi[i - 2]; }
};
struct v4i {
  v2i lo, hi;
};
[[gnu::always_inline]] inline v4d operator+(v4d a, v4d b) { return {a.lo + b.lo, a.hi + b.hi}; }
[[gnu::always_inline]] inline v4d operator-(v4d a, v4d b) { return {a.lo - b.lo, a.hi - b.hi}; }
[[gnu::always_inline]] inline v4d operator*(v4d a, v4d b) { return {a.lo * b.lo, a.hi * b.hi}; }
[[gnu::always_inline]] inline v4d operator+(v4d a, double s) { return {a.lo + s, a.hi + s}; }
[[gnu::always_inline]] inline v4d operator-(v4d a, double s) { return {a.lo - s, a.hi - s}; }
[[gnu::always_inline]] inline v4d operator*(v4d a, double s) { return {a.lo * s, a.hi * s}; }
[[gnu::always_inline]] inline v4d& operator+=(v4d& a, v4d b) { return a = a + b; }
[[gnu::always_inline]] inline v4d mul_add(v4d a, v4d b, v4d c) { return a * b + c; }
[[gnu::always_inline]] inline v4d load(const double* p) {
  v4d v;
  std::memcpy(&v.lo, p, sizeof v.lo);
  std::memcpy(&v.hi, p + 2, sizeof v.hi);
  return v;
}
[[gnu::always_inline]] inline void store(double* p, v4d v) {
  std::memcpy(p, &v.lo, sizeof v.lo);
  std::memcpy(p + 2, &v.hi, sizeof v.hi);
}
[[gnu::always_inline]] inline v4d splat(double x) { return {v2d{x, x}, v2d{x, x}}; }
[[gnu::always_inline]] inline v4i operator>=(v4d a, double s) { return {a.lo >= s, a.hi >= s}; }
[[gnu::always_inline]] inline v4i operator+(v4i a, std::int64_t s) { return {a.lo + s, a.hi + s}; }
[[gnu::always_inline]] inline v4i operator<<(v4i a, int s) { return {a.lo << s, a.hi << s}; }
[[gnu::always_inline]] inline v4i as_bits(v4d a) { return {(v2i)a.lo, (v2i)a.hi}; }
[[gnu::always_inline]] inline v4d from_bits(v4i a) { return {(v2d)a.lo, (v2d)a.hi}; }
[[gnu::always_inline]] inline v4i gt(v4d a, v4d b) { return {a.lo > b.lo, a.hi > b.hi}; }
[[gnu::always_inline]] inline v4d sel(v4i m, v4d a, v4d b) { return {m.lo ? a.lo : b.lo, m.hi ? a.hi : b.hi}; }
/// The lane sums (x0 + x1) + (x2 + x3) of four vectors at once.
[[gnu::always_inline]] inline v4d sum4(v4d a, v4d b, v4d c, v4d d) {
  auto pair = [](v4d x, v4d y) {
    const v2d lo = IDCOL_SHUFFLE2(x.lo, y.lo, 0, 2) + IDCOL_SHUFFLE2(x.lo, y.lo, 1, 3);
    const v2d hi = IDCOL_SHUFFLE2(x.hi, y.hi, 0, 2) + IDCOL_SHUFFLE2(x.hi, y.hi, 1, 3);
    return lo + hi;
  };
  return {pair(a, b), pair(c, d)};
}
#else
using v4d = double __attribute__((vector_size(32)));
using v4i = std::int64_t __attribute__((vector_size(32)));
[[gnu::always_inline]] inline v4d load(const double* p) {
  v4d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store(double* p, v4d v) { std::memcpy(p, &v, sizeof v); }
[[gnu::always_inline]] inline v4d splat(double x) { return v4d{x, x, x, x}; }
[[gnu::always_inline]] inline v4i gt(v4d a, v4d b) { return a > b; }
[[gnu::always_inline]] inline v4d sel(v4i m, v4d a, v4d b) { return m ? a : b; }
[[gnu::always_inline]] inline v4i as_bits(v4d a) { return (v4i)a; }
[[gnu::always_inline]] inline v4d from_bits(v4i a) { return (v4d)a; }
#if defined(__FMA__)
/// a b + c rounded once: the kernels use it where they mean to (no
/// contraction elsewhere: -ffp-contract=off).
[[gnu::always_inline]] inline v4d mul_add(v4d a, v4d b, v4d c) { return _mm256_fmadd_pd(a, b, c); }
#else
[[gnu::always_inline]] inline v4d mul_add(v4d a, v4d b, v4d c) { return a * b + c; }
#endif
/// The lane sums (x0 + x1) + (x2 + x3) of four vectors at once.
[[gnu::always_inline]] inline v4d sum4(v4d a, v4d b, v4d c, v4d d) {
  const v4d t = IDCOL_SHUFFLE4(a, b, 0, 4, 2, 6) + IDCOL_SHUFFLE4(a, b, 1, 5, 3, 7);  // a0+a1, b0+b1, a2+a3, b2+b3
  const v4d u = IDCOL_SHUFFLE4(c, d, 0, 4, 2, 6) + IDCOL_SHUFFLE4(c, d, 1, 5, 3, 7);
  return IDCOL_SHUFFLE4(t, u, 0, 1, 4, 5) + IDCOL_SHUFFLE4(t, u, 2, 3, 6, 7);
}
#endif

// The lanes are summed in one order on every instruction set: (x0 + x1) + (x2 + x3).

/// The number layer of the formulas written once (formulas/*.hpp) for the
/// face loop: T = four faces at one point, this unit's own type (the rule
/// below). Fused where this unit has FMA (kFused).
struct Face4Num {
  using T = v4d;
  using Mask = v4i;
  using Bits = v4i;
  static v4d splat(double x) { return polytope_kernel::splat(x); }
  static v4d sel(v4i m, v4d a, v4d b) { return polytope_kernel::sel(m, a, b); }
  template <bool kFused>
  static v4d mul_add(v4d a, v4d b, v4d c) {
    if constexpr (kFused)
      return polytope_kernel::mul_add(a, b, c);
    else
      return a * b + c;
  }
  static v4i bits(v4d a) { return as_bits(a); }
  static v4d from_bits(v4i a) { return polytope_kernel::from_bits(a); }
};
#if defined(__FMA__)
constexpr bool kFused = true;  // mul_add is one rounding
#else
constexpr bool kFused = false;
#endif

/// The number layer of the formulas written once (formulas/*.hpp) for this
/// translation unit: T = double, as detail::ScalarNum, but its own type in
/// this unit's internal namespace, so that the formulas it instantiates are
/// this instruction set's alone (the rule above).
struct KernelNum {
  using T = double;
  using Mask = bool;
  using Bits = std::uint64_t;
  static double splat(double x) { return x; }
  static double sel(bool m, double a, double b) { return m ? a : b; }
  static bool not_(bool m) { return !m; }
  static double log(double a) { return std::log(a); }
  static Bits bits(double x) {
    Bits b;
    std::memcpy(&b, &x, sizeof b);
    return b;
  }
  static double from_bits(Bits b) {
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
  }
  static bool leaves(bool m, bool& /*bad*/) { return m; }
  // The kernel's output e: phi, grad (3), hess (9, column-major) in a row.
  static double& phi(double* e) { return e[0]; }
  static double& grad(double* e, int i) { return e[1 + i]; }
  static double& hess(double* e, int i, int j) { return e[4 + i + 3 * j]; }
};

/// Faces per block: a polytope of up to this many faces computes c_i once,
/// a larger one again per block for its weights. A multiple of 4.
constexpr int kBlock = 64;

/// kGroups > 0: a polytope of exactly 4 kGroups faces, whose loops the
/// compiler unrolls (the same operations in the same order as kGroups = 0,
/// any count).
/// Long: one pass over the faces in blocks, its sums kept in registers from
/// the first face to the reductions; split, they would go through memory.
template <bool kHessian, int kGroups>
inline void eval(const double* cols, int m_any, const double* y, double sharp, double L, double* e) {
  const int m = kGroups > 0 ? 4 * kGroups : m_any;
  struct {
    const double *ax, *ay, *az, *b;
  } f{cols, cols + m, cols + 2 * m, cols + 3 * m};
  const double k = sharp / L;
  const v4d vy0 = splat(y[0]), vy1 = splat(y[1]), vy2 = splat(y[2]);
  alignas(32) double cb[kBlock];
  // c_i of the faces i0 .. i0 + n - 1 into cb, and their maximum (a select,
  // not a max instruction: a NaN c_i is never taken, as by a > b).
  auto faces = [&](int i0, int n) {
    v4d vmax = splat(-std::numeric_limits<double>::infinity());
    for (int i = 0; i < n; i += 4) {
      const int j = i0 + i;
      const v4d c = formulas::polytope_face_value<Face4Num, kFused>(load(f.ax + j), load(f.ay + j), load(f.az + j),
                                                                    load(f.b + j), vy0, vy1, vy2);
      store(cb + i, c);
      vmax = sel(gt(c, vmax), c, vmax);
    }
    const double a = vmax[0] > vmax[1] ? vmax[0] : vmax[1], b = vmax[2] > vmax[3] ? vmax[2] : vmax[3];
    return a > b ? a : b;
  };
  double cmax = -std::numeric_limits<double>::infinity();
  int imax = 0;
  for (int i0 = 0; i0 < m; i0 += kBlock) {
    const int n = m - i0 < kBlock ? m - i0 : kBlock;
    const double bmax = faces(i0, n);
    if (bmax > cmax) {  // the first face that reaches the block's maximum
      cmax = bmax;
      int i = 0;
      while (cb[i] != bmax) ++i;
      imax = i0 + i;
    }
  }
  if (cmax == -std::numeric_limits<double>::infinity()) {  // no face compared: y has a NaN
    const double nan = std::numeric_limits<double>::quiet_NaN();
    e[0] = e[1] = e[2] = e[3] = nan;  // phi, grad
    if constexpr (kHessian)
      for (int i = 4; i < 13; ++i) e[i] = nan;
    return;
  }
  const v4d sx = splat(f.ax[imax]), sy = splat(f.ay[imax]), sz = splat(f.az[imax]);
  const v4d vk = splat(k), vc = splat(cmax);
  formulas::PolytopeFaceSums<Face4Num, kFused, kHessian> S;
  for (int i0 = 0; i0 < m; i0 += kBlock) {
    const int n = m - i0 < kBlock ? m - i0 : kBlock;
    if (m > kBlock) faces(i0, n);  // a single block still holds its c_i
    for (int i = 0; i < n; i += 4) {
      const int j = i0 + i;
      S.add(vk, load(cb + i), vc, load(f.ax + j), load(f.ay + j), load(f.az + j), sx, sy, sz);
    }
  }
  // phi, grad and hess from the sums (formulas::polytope_from_sums, which
  // the lanes share), each sum's four partial sums as (s0 + s1) + (s2 + s3).
  const v4d s1 = sum4(S.s0, S.s1x, S.s1y, S.s1z);
  const double m1[3] = {s1[1], s1[2], s1[3]};
  double m2[6] = {};
  if constexpr (kHessian) {
    const v4d s2 = sum4(S.sxx, S.sxy, S.sxz, S.syy), s3 = sum4(S.syz, S.szz, S.syz, S.szz);
    m2[0] = s2[0], m2[1] = s2[1], m2[2] = s2[2], m2[3] = s2[3], m2[4] = s3[0], m2[5] = s3[1];
  }
  const double astar[3] = {sx[0], sy[0], sz[0]};
  bool bad = false;
  formulas::polytope_from_sums<KernelNum, kHessian>(s1[0], m1, m2, cmax, astar, L, sharp, e, bad);
}

}  // namespace polytope_kernel
}  // namespace
#undef IDCOL_SHUFFLE2
#undef IDCOL_SHUFFLE4
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

/// The kernels of one instruction set: with and without the second moments.
/// Index [g] holds the kernel unrolled for 4 g faces (g = 1..4), [0] the
/// one for any count (SmoothPolytope::kernel_slot picks one at construction).
struct PolytopeKernels {
  PolytopeKernelFn with_hessian[5];
  PolytopeKernelFn without_hessian[5];
  const char* isa;
};
PolytopeKernels polytope_kernels_sse2();
PolytopeKernels polytope_kernels_avx2();

}  // namespace idcol::detail
