// The vector-layer study (scripts/vector_layers/run.sh): each layer's
// kernels (kernel.inc, written once over a number type) against the scalar
// double instantiation, bit for bit (`check`), and one call's instructions
// under callgrind (`cg LAYER KERNEL`).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>
#include <valgrind/callgrind.h>

#include "api.hpp"

#define DECL(n) Kernels n();
#define LAYERS(X) X(scalar_sse2) X(scalar_avx2) X(vext_sse2_w2) X(vext_sse2_w4) X(vext_avx2_w4) \
  X(xsimd_sse2) X(xsimd_avx2_nofma3) X(xsimd_fma3_avx2) X(stdx_sse2_w2) X(stdx_sse2_w4) X(stdx_avx2_w4) \
  X(hwy_baseline) X(hwy_ssse3) X(hwy_sse4) X(hwy_avx2) X(hwy_dynamic) X(xsimd_dispatched)
LAYERS(DECL)
long long hwy_chosen_target();
struct Entry { const char* name; Kernels (*get)(); };
#define ENT(n) {#n, &n},
static const Entry kAll[] = {LAYERS(ENT)};

static long N = 1 << 20;  // ~10^6, a multiple of every width
struct Data {
  std::vector<double> xe, xs, mat[15];
};
static Data make_data() {
  Data d;
  std::mt19937_64 g(12345);
  std::uniform_real_distribution<double> ue(-745.0, 0.0), us(1e-3, 1e6), um(-1.0, 1.0);
  d.xe.resize(N); d.xs.resize(N);
  for (long i = 0; i < N; ++i) d.xe[i] = ue(g), d.xs[i] = us(g);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const double sp[] = {nan, -nan, -inf, -0.0, 0.0, -708.0, std::nextafter(-708.0, -1e9), std::nextafter(-708.0, 0.0),
                       -707.5, -709.0, -744.44, -745.2, -std::numeric_limits<double>::denorm_min(),
                       -std::numeric_limits<double>::min(), -1e-300, -1e-17, -0.34657359027997264 /* -ln2/2 */,
                       -0.6931471805599453, -1.0397207708399179, -700.0, -1e-10};
  // specials at the front and spread through (every lane position)
  long k = 0;
  for (int rep = 0; rep < 8; ++rep)
    for (double s : sp) d.xe[k++] = s;
  for (long i = 0; i < 4096; ++i) d.xe[(i * 7919 + 13) % N] = sp[i % (sizeof sp / sizeof *sp)];
  // exponents at the rounding boundaries n ln2 +- ln2/2
  for (long i = 0; i < 20000; ++i) {
    const long j = (100000 + i) % N;
    d.xe[j] = -(double)(i % 1021) * 0.6931471805599453 - 0.34657359027997264 + (i % 3 - 1) * 1e-13;
  }
  const double sps[] = {0.0, std::numeric_limits<double>::denorm_min(), inf, nan, 1.0, 4.0, 1e300, 1e-300};
  for (long i = 0; i < 64; ++i) d.xs[i * 3] = sps[i % 8];
  for (auto& m : d.mat) { m.resize(N); for (auto& v : m) v = um(g); }
  return d;
}
struct Out { std::vector<double> eu, ef, mv[3], dot, sq; long iters; };
static Out run_all(const Kernels& k, const Data& d) {
  Out o;
  o.eu.resize(N); o.ef.resize(N); o.dot.resize(N); o.sq.resize(N);
  for (auto& m : o.mv) m.resize(N);
  k.exp_unfused(d.xe.data(), o.eu.data(), N);
  k.exp_fused(d.xe.data(), o.ef.data(), N);
  const double* A[9]; const double* v[3]; const double* w[3]; double* out[3];
  for (int i = 0; i < 9; ++i) A[i] = d.mat[i].data();
  for (int i = 0; i < 3; ++i) v[i] = d.mat[9 + i].data(), w[i] = d.mat[12 + i].data(), out[i] = o.mv[i].data();
  k.matvec(A, v, w, out, o.dot.data(), N);
  o.iters = k.sqrt_(d.xs.data(), o.sq.data(), N);
  return o;
}
static long ndiff(const std::vector<double>& a, const std::vector<double>& b) {
  if (std::memcmp(a.data(), b.data(), a.size() * 8) == 0) return 0;
  long c = 0;
  for (size_t i = 0; i < a.size(); ++i) c += std::memcmp(&a[i], &b[i], 8) != 0;
  return c;
}
static const Entry* find(const char* n) {
  for (auto& e : kAll) if (!std::strcmp(e.name, n)) return &e;
  std::fprintf(stderr, "unknown %s\n", n); std::exit(2);
}
int main(int argc, char** argv) {
  std::string mode = argc > 1 ? argv[1] : "check";
  if (mode == "cg") N = 1 << 16;
  Data d = make_data();
  if (mode == "check") {
    std::printf("hwy SupportedTargets bits: %llx\n", hwy_chosen_target());
    Out ref = run_all(scalar_sse2(), d);
    std::printf("%-20s %5s %10s %10s %10s %10s %10s  (mismatching elements of %ld vs scalar_sse2 double)\n", "layer", "width", "exp", "exp_fma", "matvec", "dot", "sqrt", N);
    for (auto& e : kAll) {
      Kernels k = e.get();
      Out o = run_all(k, d);
      long mv = ndiff(o.mv[0], ref.mv[0]) + ndiff(o.mv[1], ref.mv[1]) + ndiff(o.mv[2], ref.mv[2]);
      std::printf("%-20s %5d %10ld %10ld %10ld %10ld %10ld  iters %ld/%ld\n", e.name, k.width, ndiff(o.eu, ref.eu), ndiff(o.ef, ref.ef), mv,
                  ndiff(o.dot, ref.dot), ndiff(o.sq, ref.sq), o.iters, ref.iters);
    }
    // sanity of the scalar reference against std::exp
    double maxrel = 0;
    for (long i = 0; i < N; ++i) { double x = d.xe[i]; if (x >= -708 && x <= 0) { double e = std::exp(x); maxrel = std::max(maxrel, std::fabs(ref.eu[i] - e) / e); } }
    std::printf("scalar exp_nonpositive max rel err vs std::exp: %.3g\n", maxrel);
    return 0;
  }
  // time / cg <layer> <kernel: exp|expf|matvec|sqrt>
  const Entry* e = find(argv[2]);
  std::string what = argv[3];
  Kernels k = e->get();
  std::vector<double> out(N), mvo[3]; for (auto& m : mvo) m.resize(N);
  const double* A[9]; const double* v[3]; const double* w[3]; double* o3[3];
  for (int i = 0; i < 9; ++i) A[i] = d.mat[i].data();
  for (int i = 0; i < 3; ++i) v[i] = d.mat[9 + i].data(), w[i] = d.mat[12 + i].data(), o3[i] = mvo[i].data();
  long n = mode == "cg" ? (1 << 16) : N;
  auto call = [&] {
    if (what == "exp") k.exp_unfused(d.xe.data(), out.data(), n);
    else if (what == "expf") k.exp_fused(d.xe.data(), out.data(), n);
    else if (what == "matvec") k.matvec(A, v, w, o3, out.data(), n);
    else k.sqrt_(d.xs.data(), out.data(), n);
  };
  if (mode == "cg") {
    call();  // warm (lazy binding, dispatch init)
    CALLGRIND_TOGGLE_COLLECT;
    call();
    CALLGRIND_TOGGLE_COLLECT;
    std::printf("n=%ld\n", n);
    return 0;
  }
  call();
  std::vector<double> t;
  for (int r = 0; r < 5; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < 5; ++rep) call();
    auto t1 = std::chrono::steady_clock::now();
    t.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / (5.0 * n));
  }
  std::sort(t.begin(), t.end());
  std::printf("%s %s ns/elem median %.3f (min %.3f max %.3f)\n", e->name, what.c_str(), t[2], t[0], t[4]);
}
