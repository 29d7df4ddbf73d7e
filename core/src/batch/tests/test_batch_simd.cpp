// The SIMD batch path against the loop of solve(): every row's status,
// alpha* and x* are the scalar solver's, on every pair (the pairs the lanes
// cover and those they send to the loop), cold and warm, with lanes that
// leave the fast path (bad poses, concentric poses, poses far from the
// pair's scale, 1000:1 ellipsoids whose closed form the residual test
// refuses, poses near contact), for every instruction set this CPU has.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <tuple>
#include <vector>

#include "examples/paper_shapes.hpp"
#include "src/batch/batch_simd.hpp"
#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

/// Sweep-like poses (|r| log-uniform over the pair's scale, any rotation),
/// then a random walk, then the rows that must leave the fast path.
std::vector<Pose> poses_for(const Shape& a, const Shape& b, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  const Radii ra = radii(a), rb = radii(b);
  const double rmin = 0.1 * std::min(ra.inner, rb.inner), rmax = 2.0 * std::max(ra.outer, rb.outer);
  std::vector<Pose> P;
  for (std::size_t k = 0; k < n / 2; ++k) P.push_back(test::random_pose(rng, rmin, rmax));
  std::normal_distribution<double> g(0.0, 1.0);
  Pose X{test::random_rotation(rng), 0.5 * (rmin + rmax) * test::random_unit(rng)};
  while (P.size() < n) {
    Vec6 xi;
    for (int j = 0; j < 6; ++j) xi[j] = 0.05 * g(rng);
    X = X * se3_exp(xi);
    const double r = X.p.norm();
    if (r < rmin || r > rmax) X.p *= 0.5 * (rmin + rmax) / r;
    P.push_back(X);
  }
  // Rows off the fast path, spread over lane positions.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  P[3].p[1] = nan;                 // InvalidInput
  P[10].R.col(0) *= -1.0;          // a reflection
  P[17].p.setZero();               // concentric
  P[22].p *= 1e9;                  // far beyond the pair's scale
  P[29].p *= 1e-9;                 // deep inside
  P[30].R(0, 0) += 1e-10;          // orthonormal within the pose tolerance only
  P[31].R(1, 1) += 5e-10;
  return P;
}

/// A batch's outputs; with `kinematics`, the contact kinematics too (NaN
/// where a row has none).
struct Rows {
  std::vector<double> alpha, x;
  std::vector<std::int32_t> status, iterations;
  std::vector<double> gap, normal, p1, p2;
  explicit Rows(std::size_t n, bool kinematics = false) : alpha(n), x(3 * n), status(n), iterations(n) {
    if (!kinematics) return;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    gap.assign(n, nan), normal.assign(3 * n, nan), p1.assign(3 * n, nan), p2.assign(3 * n, nan);
  }
  BatchOutput out() {
    BatchOutput o{alpha, x, status, iterations, {}};
    o.gap = gap, o.normal_1 = normal, o.p1_1 = p1, o.p2_1 = p2;
    return o;
  }
};

/// The loop of solve() the batch repeats; with `kinematics`,
/// contact_kinematics() of each converged row.
Rows loop(const Shape& a, const Shape& b, const std::vector<Pose>& P, const BatchOptions& o, bool kinematics = false) {
  Rows r(P.size(), kinematics);
  WarmStart ws;
  for (std::size_t k = 0; k < P.size(); ++k) {
    if (k % o.warm_chain == 0) ws.reset();
    const SolveResult s = solve(a, b, P[k], o.solver, o.warm_start ? &ws : nullptr);
    r.alpha[k] = s.alpha;
    for (int j = 0; j < 3; ++j) r.x[3 * k + j] = s.x_1[j];
    r.status[k] = static_cast<std::int32_t>(s.status);
    r.iterations[k] = s.iterations;
    if (!kinematics || !s.converged()) continue;
    const ContactKinematics c = contact_kinematics(s);
    r.gap[k] = c.gap;
    for (int j = 0; j < 3; ++j) r.normal[3 * k + j] = c.nhat_1[j], r.p1[3 * k + j] = c.p1_1[j], r.p2[3 * k + j] = c.p2_1[j];
  }
  return r;
}

bool close(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b));
}

struct Tally {
  long rows = 0, differ = 0, bits_differ = 0;
};

/// Batch (threads 1 and 3, poses as Pose objects; one thread, poses as
/// row-major arrays) against the loop; every difference is a failure.
Tally compare(const std::string& name, const Shape& a, const Shape& b, const std::vector<Pose>& P, BatchOptions o) {
  Tally t;
  const Rows want = loop(a, b, P, o);
  // The rows as row-major R and p too (the layout of a NumPy caller).
  std::vector<double> R(9 * P.size()), p(3 * P.size());
  for (std::size_t k = 0; k < P.size(); ++k)
    for (int i = 0; i < 3; ++i) {
      p[3 * k + i] = P[k].p[i];
      for (int j = 0; j < 3; ++j) R[9 * k + 3 * i + j] = P[k].R(i, j);
    }
  const Shape* pa = &a;
  const Shape* pb = &b;
  for (int threads : {1, 3, -1}) {
    o.threads = threads < 0 ? 1 : threads;
    Rows got(P.size());
    if (threads < 0)
      solve_batch(Span<const Shape* const>(&pa, 1), Span<const Shape* const>(&pb, 1), Span<const double>(R),
                  Span<const double>(p), o, got.out());
    else
      solve_batch(a, b, P, o, got.out());
    for (std::size_t k = 0; k < P.size(); ++k) {
      ++t.rows;
      bool same = got.status[k] == want.status[k] && close(got.alpha[k], want.alpha[k]);
      for (int j = 0; j < 3; ++j) same = same && close(got.x[3 * k + j], want.x[3 * k + j]);
      if (!same) {
        ++t.differ;
        ADD_FAILURE() << name << (o.warm_start ? " warm" : " cold") << " row " << k << ": status " << got.status[k] << " vs "
                      << want.status[k] << ", alpha " << got.alpha[k] << " vs " << want.alpha[k];
      }
      bool bits = got.alpha[k] == want.alpha[k] || (std::isnan(got.alpha[k]) && std::isnan(want.alpha[k]));
      for (int j = 0; j < 3; ++j) bits = bits && (got.x[3 * k + j] == want.x[3 * k + j] || std::isnan(want.x[3 * k + j]));
      t.bits_differ += !bits;
    }
  }
  return t;
}

/// compare() (every difference a failure), the iteration counts too, and
/// the rows that the lanes answer on one thread (the count is per thread).
std::size_t same_rows_and_lane_count(const std::string& name, const Shape& a, const Shape& b, const std::vector<Pose>& P,
                                     BatchOptions o) {
  const Tally t = compare(name, a, b, P, o);
  EXPECT_EQ(t.differ, 0) << name;
  EXPECT_EQ(t.bits_differ, 0) << name;
  const Rows want = loop(a, b, P, o);
  const std::size_t before = detail::batch_simd_lane_rows();
  Rows got(P.size());
  o.threads = 1;
  solve_batch(a, b, P, o, got.out());
  const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
  long iter_differ = 0;
  for (std::size_t k = 0; k < P.size(); ++k) iter_differ += got.iterations[k] != want.iterations[k];
  EXPECT_EQ(iter_differ, 0) << name;
  return lane_rows;
}

std::vector<test::Named> all_shapes() {
  std::vector<test::Named> S = test::paper_shapes();
  S.push_back({"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)});
  S.push_back({"Ellip2", Superellipsoid(1.2, 0.3, 0.7, 1.0)});
  S.push_back({"Plate", Superellipsoid(1000.0, 1.0, 30.0, 1.0)});  // 1000:1, off the fast path often
  S.push_back({"Sphere", Sphere(0.8)});
  return S;
}

/// The pairs the option tests run: the paper's SE-SEC, superquadrics with
/// n = 3 and 1, a sharp cone beside the paper's cylinder, and the paper's
/// polytope beside its superellipsoid (the first body named "Poly").
std::vector<std::pair<test::Named, test::Named>> option_test_pairs() {
  const std::vector<test::Named> P8 = test::paper_shapes();
  EXPECT_EQ(P8[0].name, "Poly");
  return {{P8[2], P8[3]},
          {{"SE3", Superellipsoid(1.2, 0.4, 0.9, 3.0)}, {"SEC1", SuperellipticCylinder(0.7, 0.3, 1.0)}},
          {{"TC2", SmoothTruncatedCone(0.6, 0.25, 0.8, 1.9, 120.0)}, P8[3]},
          {P8[0], P8[2]}};
}

/// Whether the lanes of `isa` take no smooth polytope on this CPU: SSE2
/// lanes, which cannot repeat the polytope face kernel when it fuses
/// multiply-adds (AVX2).
bool lanes_take_no_polytope(const char* isa) {
  return std::string(isa) == "sse2" && std::string(detail::polytope_kernel_isa()) == "avx2";
}

/// Options that reach the lanes' constants: a tighter tolerance, another
/// surrogate factor and trust-region margin.
SolverOptions tight_options() {
  SolverOptions s;
  s.tolerance = 1e-12, s.surrogate_factor = 1.7, s.bound_margin = 1e-2;
  return s;
}

class BatchSimd : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override { setenv("IDCOL_SIMD", GetParam(), 1); }
  void TearDown() override { unsetenv("IDCOL_SIMD"); }
};

TEST_P(BatchSimd, EveryRowIsTheScalarSolversAnswer) {
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  const auto S = all_shapes();
  Tally all;
  std::size_t lane_rows = 0;
  unsigned seed = 1;
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j)
      for (bool warm : {false, true}) {
        BatchOptions o;
        o.warm_start = warm;
        o.warm_chain = 97;  // chain starts at every lane position
        const bool ell = (S[i].name.rfind("Ell", 0) == 0 || S[i].name == "Plate") &&
                         (S[j].name.rfind("Ell", 0) == 0 || S[j].name == "Plate");
        const std::vector<Pose> P = poses_for(S[i].shape, S[j].shape, ell ? 1203 : 203, seed++);
        BatchOptions o2 = o;
        o2.solver = tight_options();
        for (const BatchOptions* opt : {&o, &o2}) {
          if (opt == &o2 && !ell) continue;
          const std::size_t before = detail::batch_simd_lane_rows();
          const Tally t = compare(S[i].name + "-" + S[j].name, S[i].shape, S[j].shape, P, *opt);
          lane_rows += detail::batch_simd_lane_rows() - before;
          all.rows += t.rows, all.differ += t.differ, all.bits_differ += t.bits_differ;
        }
      }
  EXPECT_EQ(all.differ, 0);
  // Stronger than the contract: each lane repeats the scalar arithmetic in
  // Eigen's order (batch_simd_kernel.hpp), so the answers agree to the bit.
  EXPECT_EQ(all.bits_differ, 0) << "the lanes round differently from the scalar solver";
  // Of the ellipsoid pairs' rows, about half are answered in lanes (the
  // others take Newton steps: deep poses, 1000:1 plates).
  if (std::string(GetParam()) == "none") EXPECT_EQ(lane_rows, 0u);
  else EXPECT_GT(lane_rows, 5000u) << "the lanes answered too few rows to test them";
  std::printf("[%s] %ld rows, %zu answered in lanes (the rest by the loop), %ld differ, %ld not bit-identical\n", GetParam(),
              all.rows, lane_rows, all.differ, all.bits_differ);
}

// Warm chains as long as the default (1024 rows) still fill the lanes: the
// batch hands the lanes blocks of whole lane groups of chains. (Blocks of
// one chain each, as solve_batch cut them before, sent every warm row to
// the scalar loop.)
TEST_P(BatchSimd, WarmChainsOfTheDefaultLengthRunInLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const Shape a = Superellipsoid(0.5, 1.0, 1.5, 1.0), b = Superellipsoid(1.2, 0.3, 0.7, 1.0);
  BatchOptions o;
  o.warm_start = true;
  ASSERT_EQ(o.warm_chain, 1024u);
  const std::vector<Pose> P = poses_for(a, b, 12 * o.warm_chain, 5);
  const std::size_t before = detail::batch_simd_lane_rows();
  Rows got(P.size());
  solve_batch(a, b, P, o, got.out());
  const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
  EXPECT_GT(lane_rows, P.size() / 2) << "of " << P.size() << " warm rows";
  const Tally t = compare("Ellip-Ellip2", a, b, P, o);
  EXPECT_EQ(t.differ, 0);
  EXPECT_EQ(t.bits_differ, 0);
}

// More chains than lanes rotate through the lanes: each kernel call takes
// the next row of each of the next W chains with rows left, so the calls
// stay full (10 chains on 8 lanes: 1600 rows in 200 calls, where groups of
// 8 and 2 chains in lockstep made 320), and each chain's rows still run in
// order, each warm-started from the one before: every answer is the loop's.
TEST_P(BatchSimd, MoreWarmChainsThanLanesKeepTheLanesFull) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::size_t W = static_cast<std::size_t>(detail::batch_simd_lanes());
  const std::vector<test::Named> S = {{"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
                                      {"Ellip2", Superellipsoid(1.2, 0.3, 0.7, 1.0)},
                                      {"SE8", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                      {"SEC8", SuperellipticCylinder(1.0, 2.0, 8.0)}};
  unsigned seed = 400;
  // Chains of 40 rows: one block of solve_batch's; of 1100: a block a lane
  // group of chains, the last block taking the chains left after it.
  for (const auto& [i, j, length] : std::vector<std::tuple<int, int, std::size_t>>{{0, 1, 40}, {2, 3, 40}, {0, 1, 1100}})
    for (std::size_t chains : {W + 1, W + 2, 2 * W - 1, 2 * W, 3 * W + 2}) {
      const std::string name = S[i].name + "-" + S[j].name + " " + std::to_string(chains) + " chains of " + std::to_string(length);
      BatchOptions o;
      o.warm_start = true;
      o.warm_chain = length;
      std::vector<Pose> P = poses_for(S[i].shape, S[j].shape, 2 * chains * o.warm_chain, seed++);
      P.erase(P.begin(), P.begin() + static_cast<long>(P.size() / 2));  // the random walk only
      P.resize(P.size() - 7);  // the last chain shorter
      same_rows_and_lane_count(name, S[i].shape, S[j].shape, P, o);
      o.threads = 1;
      Rows got(P.size());
      const std::size_t before = detail::batch_simd_warm_calls();
      solve_batch(S[i].shape, S[j].shape, P, o, got.out());
      const std::size_t calls = detail::batch_simd_warm_calls() - before;
      // Full calls but for the last rows of the rotation (at most one call a
      // chain while fewer than W chains have rows left).
      EXPECT_LE(calls, (P.size() + W - 1) / W + chains) << name;
      std::printf("[%s] %s: %zu rows in %zu calls of %zu lanes\n", GetParam(), name.c_str(), P.size(), calls, W);
    }
}

// Warm chains of two superquadrics (superellipsoids and superelliptic
// cylinders with an integer n) run in the Newton lanes (newton_lanes_kernel.hpp):
// on a random walk nearly every row after a chain's first is answered in
// lanes, and every answer is the loop's to the bit. n = 3 takes S^(1/2n)
// by std::pow, n = 8 by square roots; an ellipsoid beside a cylinder is no
// ellipsoid pair and goes to these lanes too.
TEST_P(BatchSimd, WarmSuperquadricChainsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> S = {{"SE8", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                      {"SEC8", SuperellipticCylinder(1.0, 2.0, 8.0)},
                                      {"SE3", Superellipsoid(1.2, 0.4, 0.9, 3.0)},
                                      {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
                                      {"SEC1", SuperellipticCylinder(0.7, 0.3, 1.0)}};
  unsigned seed = 90;
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j) {
      if (S[i].name == "Ellip" && S[j].name == "Ellip") continue;  // the closed-form lanes' pair
      BatchOptions o;
      o.warm_start = true;
      o.warm_chain = 300;
      std::vector<Pose> P = poses_for(S[i].shape, S[j].shape, 2 * 8 * o.warm_chain, seed++);
      P.erase(P.begin(), P.begin() + static_cast<long>(P.size() / 2));  // the random walk only
      const Tally t = compare(S[i].name + "-" + S[j].name, S[i].shape, S[j].shape, P, o);
      EXPECT_EQ(t.differ, 0) << S[i].name << "-" << S[j].name;
      EXPECT_EQ(t.bits_differ, 0) << S[i].name << "-" << S[j].name;
      // The count is per thread: one thread.
      const std::size_t before = detail::batch_simd_lane_rows();
      Rows got(P.size());
      o.threads = 1;
      solve_batch(S[i].shape, S[j].shape, P, o, got.out());
      const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
      EXPECT_GT(lane_rows, P.size() * 95 / 100) << S[i].name << "-" << S[j].name << ": of " << P.size() << " rows";
    }
}

// Warm chains of a smooth polytope beside a superquadric or another polytope
// run in the Newton lanes too (newton_lanes_polytope.hpp), each lane
// repeating the face kernel that the scalar solver runs on this CPU
// (detail::polytope_kernel_isa(): with fused multiply-adds or without),
// and every answer is the loop's to the bit: the paper's polytope (8 faces),
// a box (6 faces: two padding faces; rounding length L = 0.7), a hull of 11 points (18 faces: the
// kernel for any count, two padding faces) and one of 60 points (more faces
// than the kernel's block of 64). Lanes without FMA (SSE2) cannot repeat the fused kernel and
// take no polytope then.
TEST_P(BatchSimd, WarmPolytopeChainsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const bool declined = lanes_take_no_polytope(GetParam());
  auto hull = [](int n, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::vector<Vec3> V;
    for (int i = 0; i < n; ++i) {
      const Vec3 u = test::random_unit(rng);
      V.push_back(Vec3(0.8 * u.x(), 1.1 * u.y(), 0.6 * u.z()));
    }
    return SmoothPolytope::from_vertices(V, 40.0);
  };
  const std::vector<test::Named> S = {{"Poly", test::paper_poly()},
                                      {"Box", SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
                                                             {0.6, 0.6, 0.9, 0.9, 0.4, 0.4}, 10.0, 0.7)},
                                      {"Hull11", hull(11, 7)},
                                      {"Hull60", hull(60, 8)},
                                      {"SE8", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                      {"SEC8", SuperellipticCylinder(1.0, 2.0, 8.0)},
                                      {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)}};
  ASSERT_EQ(std::get<SmoothPolytope>(S[2].shape).num_halfspaces() % 4, 2);
  ASSERT_GT(std::get<SmoothPolytope>(S[3].shape).num_halfspaces(), 64);
  const std::vector<std::pair<int, int>> pairs = {{0, 0}, {0, 4}, {0, 5}, {0, 6}, {1, 4}, {1, 5}, {1, 6},
                                                  {1, 0}, {2, 4}, {2, 1}, {6, 2}, {3, 5}};
  unsigned seed = 190;
  std::size_t rows = 0, lane_rows = 0;
  for (const auto& [i, j] : pairs) {
    const std::string name = S[i].name + "-" + S[j].name;
    BatchOptions o;
    o.warm_start = true;
    o.warm_chain = 160;  // 10 chains: in rotation through 8 lanes, or a group of 4 and 6 in rotation through 4
    std::vector<Pose> P = poses_for(S[i].shape, S[j].shape, 2 * 10 * o.warm_chain, seed++);
    P.erase(P.begin(), P.begin() + static_cast<long>(P.size() / 2));  // the random walk only
    const Tally t = compare(name, S[i].shape, S[j].shape, P, o);
    EXPECT_EQ(t.differ, 0) << name;
    EXPECT_EQ(t.bits_differ, 0) << name;
    // The count is per thread: one thread.
    const std::size_t before = detail::batch_simd_lane_rows();
    Rows got(P.size());
    o.threads = 1;
    solve_batch(S[i].shape, S[j].shape, P, o, got.out());
    const std::size_t n = detail::batch_simd_lane_rows() - before;
    if (declined) EXPECT_EQ(n, 0u) << name;
    else EXPECT_GT(n, P.size() * 97 / 100) << name << ": of " << P.size() << " rows";  // measured: 1583-1590 of 1600 (10 cold)
    std::printf("[%s, face kernel %s] %s: %zu of %zu warm rows in lanes\n", GetParam(), detail::polytope_kernel_isa(),
                name.c_str(), n, P.size());
    rows += P.size(), lane_rows += n;
  }
  std::printf("[%s] polytope pairs: %zu of %zu warm rows in lanes\n", GetParam(), lane_rows, rows);
}

// Cold rows of a smooth polytope beside a polytope, a superellipsoid, a
// superelliptic cylinder (n = 8, the paper's), an ellipsoid or a smooth
// truncated cone (the paper's, and a sharp one), in either order, run in the cold Newton lanes (newton_lanes_cold.hpp: the exact face
// through which the line of centres leaves the polytope, the mean of the
// vertices that reach its support, no stall exit, the Hessians' traces
// checked; the face kernel that the scalar solver runs on this CPU, fused or
// not): every answer and iteration count is the loop's, to the bit. The
// paper's polytope (8 faces), a box (6 faces; rounding length L = 0.7), a
// hull of 11 points (18 faces) and one of 80 (more vertices than
// support_point keeps products for); every fifth pose has its axes aligned.
// Lanes without FMA (SSE2) cannot repeat the fused kernel and take no
// polytope then. It fails when a support point's vertex sum is multiplied by
// the reciprocal of their count instead of divided by it.
TEST_P(BatchSimd, ColdPolytopeRowsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const bool declined = lanes_take_no_polytope(GetParam());
  auto hull = [](int n, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::vector<Vec3> V;
    for (int i = 0; i < n; ++i) {
      const Vec3 u = test::random_unit(rng);
      V.push_back(Vec3(0.8 * u.x(), 1.1 * u.y(), 0.6 * u.z()));
    }
    return SmoothPolytope::from_vertices(V, 40.0);
  };
  const std::vector<test::Named> P8 = test::paper_shapes();
  ASSERT_EQ(P8[0].name, "Poly");
  const std::vector<test::Named> Q = {P8[0],
                                      {"Box", SmoothPolytope({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
                                                             {0.6, 0.6, 0.9, 0.9, 0.4, 0.4}, 10.0, 0.7)},
                                      {"Hull11", hull(11, 7)},
                                      {"Hull80", hull(80, 9)}};
  ASSERT_EQ(std::get<SmoothPolytope>(Q[2].shape).num_halfspaces(), 18);
  ASSERT_GT(std::get<SmoothPolytope>(Q[3].shape).vertices().size(), 64u);
  ASSERT_EQ(P8[1].name, "TC");
  const std::vector<test::Named> S = {P8[2], P8[3], {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)}, P8[1]};
  std::vector<std::pair<test::Named, test::Named>> pairs;
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = i; j < 3; ++j) pairs.push_back({Q[i], Q[j]});
    for (const test::Named& B : S) pairs.push_back({Q[i], B}), pairs.push_back({B, Q[i]});
  }
  pairs.push_back({Q[3], S[0]});
  pairs.push_back({Q[1], Q[3]});
  const test::Named TC2 = {"TC2", SmoothTruncatedCone(0.6, 0.25, 0.8, 1.9, 120.0)};  // sharp
  pairs.push_back({Q[0], TC2});
  pairs.push_back({TC2, Q[1]});
  // The 24 rotations that map the axes onto the axes: poses that put faces
  // of two polytopes parallel (the paper's polytope has opposite faces, the
  // box's and the hulls' may be), where support_point averages a face's
  // vertices (3 or more: a division by the count that no reciprocal repeats).
  std::vector<Mat3> axes;
  for (int perm = 0; perm < 6; ++perm)
    for (int sg = 0; sg < 8; ++sg) {
      static const int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
      Mat3 R = Mat3::Zero();
      for (int r = 0; r < 3; ++r) R(r, kPerm[perm][r]) = (sg >> r & 1) ? -1.0 : 1.0;
      if (R.determinant() > 0.0) axes.push_back(R);
    }
  ASSERT_EQ(axes.size(), 24u);
  unsigned seed = 210;
  std::size_t all_rows = 0, all_lanes = 0;
  for (const auto& [A, B] : pairs) {
    const std::string name = A.name + "-" + B.name;
    BatchOptions o;
    std::vector<Pose> P = poses_for(A.shape, B.shape, 1203, seed++);  // random, then a walk
    for (std::size_t k = 40; k < P.size(); k += 5) P[k].R = axes[(k / 5) % axes.size()];  // every fifth row: axes aligned
    const std::size_t lane_rows = same_rows_and_lane_count(name, A.shape, B.shape, P, o);
    // The rows the lanes could take: those the scalar solver answers in its
    // first run by Newton and chord steps alone (no LM step, no restart).
    // Measured (one thread; SSE2, AVX2 and AVX-512 lanes, the fused face
    // kernel and the unfused one alike): the lanes take all of them but 3 to
    // 7 (the 4 rows of poses_for off the fast path that the scalar solver
    // still answers, a last row alone after the last group, a row or two
    // near a threshold); 93.6-99.3% of each pair's rows, 98.9-99.0% of all.
    // The others take an LM step in their first run (Hull11-SE: 72 of 1203).
    struct FirstRun : TraceSink {
      bool only = true;
      void record(const TraceRecord& r) override { only = only && r.run == 0 && std::string(r.step) != "lm"; }
    };
    std::size_t first_run = 0;
    for (const Pose& X : P) {
      FirstRun f;
      first_run += solve(A.shape, B.shape, X, o.solver, nullptr, &f).converged() && f.only;
    }
    if (declined) EXPECT_EQ(lane_rows, 0u) << name;
    else EXPECT_GE(lane_rows + 10, first_run) << name << ": " << lane_rows << " rows in lanes";
    std::printf("[%s, face kernel %s] %s: %zu of %zu cold rows in lanes (%zu answered by the first run)\n", GetParam(),
                detail::polytope_kernel_isa(), name.c_str(), lane_rows, P.size(), first_run);
    all_rows += P.size(), all_lanes += lane_rows;
  }
  if (!declined) EXPECT_GE(all_lanes * 100, all_rows * 98) << all_lanes << " of " << all_rows;
  std::printf("[%s] cold polytope rows: %zu of %zu in lanes\n", GetParam(), all_lanes, all_rows);
}

// Warm chains of a smooth truncated cone beside a cone, a superellipsoid or
// a superelliptic cylinder (integer n) run in the Newton lanes too
// (newton_lanes_cone.hpp: SmoothTruncatedCone::eval with its inline exp in
// lanes), every answer the loop's to the bit: the paper's cone and a
// sharper, slimmer one whose top is wider than its base.
TEST_P(BatchSimd, WarmConeChainsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> C = {{"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)},
                                      {"TC2", SmoothTruncatedCone(0.6, 0.25, 0.8, 1.9, 120.0)}};
  const std::vector<test::Named> S = {C[0],
                                      C[1],
                                      {"SE8", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                      {"SEC8", SuperellipticCylinder(1.0, 2.0, 8.0)},
                                      {"SE3", Superellipsoid(1.2, 0.4, 0.9, 3.0)},
                                      {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)}};
  unsigned seed = 190;
  for (std::size_t i = 0; i < C.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j)
      for (bool swap : {false, true}) {
        if (swap && j < C.size()) continue;  // two cones: both orders come from (i, j) and (j, i) already
        const test::Named& A = swap ? S[j] : C[i];
        const test::Named& B = swap ? C[i] : S[j];
        const std::string name = A.name + "-" + B.name;
        BatchOptions o;
        o.warm_start = true;
        o.warm_chain = 300;
        std::vector<Pose> P = poses_for(A.shape, B.shape, 2 * 8 * o.warm_chain, seed++);
        P.erase(P.begin(), P.begin() + static_cast<long>(P.size() / 2));  // the random walk only
        const Tally t = compare(name, A.shape, B.shape, P, o);
        EXPECT_EQ(t.differ, 0) << name;
        EXPECT_EQ(t.bits_differ, 0) << name;
        const std::size_t before = detail::batch_simd_lane_rows();
        Rows got(P.size());
        o.threads = 1;
        solve_batch(A.shape, B.shape, P, o, got.out());
        const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
        std::printf("[%s] %s: %zu of %zu warm rows in lanes\n", GetParam(), name.c_str(), lane_rows, P.size());
        // Measured (every instruction set alike): 98.5-99.7% with the paper's
        // cone; 79-99.6% with the sharp one, whose walks meet its rims, where
        // the scalar solver itself leaves the warm Newton path on up to 16%
        // of the rows (LM steps, cold fallbacks), which the lanes hand back.
        const std::size_t pct = i == 0 && j != 1 ? 96 : 75;
        EXPECT_GT(lane_rows, P.size() * pct / 100) << name << ": of " << P.size() << " rows";
      }
}

// Cold rows of two superquadrics run in the cold Newton lanes
// (newton_lanes_cold.hpp: the support guess, then one Newton run): every
// answer is the loop's to the bit, iterations included, on sweep-like
// poses and a random walk. The n = 8 bodies are the paper's
// (test::paper_shapes()); n = 3 takes its roots and support points by
// std::pow; an ellipsoid beside a cylinder is no ellipsoid pair and goes to
// these lanes too. Rows whose first cold run stalls (bodies face to face),
// or that leave the path otherwise, go to the loop: at least 97% of each
// pair's rows are answered in lanes (measured on one thread, 1203 rows a
// pair, SSE2, AVX2 and AVX-512 alike: 98-99.5%).
TEST_P(BatchSimd, ColdSuperquadricRowsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> P8 = test::paper_shapes();
  const std::vector<test::Named> S = {P8[2], P8[3],
                                      {"SE3", Superellipsoid(1.2, 0.4, 0.9, 3.0)},
                                      {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
                                      {"SEC1", SuperellipticCylinder(0.7, 0.3, 1.0)}};
  ASSERT_EQ(S[0].name, "SE");
  ASSERT_EQ(S[1].name, "SEC");
  unsigned seed = 120;
  std::size_t all_rows = 0, all_lanes = 0;
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j) {
      if (S[i].name == "Ellip" && S[j].name == "Ellip") continue;  // the closed-form lanes' pair
      const std::string name = S[i].name + "-" + S[j].name;
      BatchOptions o;
      const std::vector<Pose> P = poses_for(S[i].shape, S[j].shape, 1203, seed++);  // random, then a walk
      const std::size_t lane_rows = same_rows_and_lane_count(name, S[i].shape, S[j].shape, P, o);
      EXPECT_GE(lane_rows * 100, P.size() * 97) << name << ": " << lane_rows << " of " << P.size() << " rows in lanes";
      std::printf("[%s] %s: %zu of %zu cold rows in lanes\n", GetParam(), name.c_str(), lane_rows, P.size());
      all_rows += P.size(), all_lanes += lane_rows;
    }
  std::printf("[%s] cold superquadric rows: %zu of %zu in lanes\n", GetParam(), all_lanes, all_rows);
}


// Cold rows whose first run reaches an LM step (a failed line search, or
// no Newton direction) leave the cold lanes with where they left
// (ColdResume: the point, the run's iteration, the steps made, the stall
// count and the chord flags). W such rows resume together in lanes
// (newton_cold_lanes_*_resume: the LM steps in lanes, then, after a stall,
// the spare starts); a lane that leaves those, and the rows left over when
// fewer than half the lanes' worth remain, go to the scalar solver, which
// resumes the run at the row's last LM step instead of solving it again.
// On the paper's sweep, where such rows cluster (about 1-2% of SE-SE's,
// SE-SEC's and TC-SE's), every row and iteration count is the loop's to the
// bit both ways: with the lanes resuming (rows answered so) and with every
// such row resumed by the scalar solver (the switch for tests).
TEST_P(BatchSimd, ColdRowsLeftAtAnLmStepResumeThere) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> P8 = test::paper_shapes();
  ASSERT_EQ(P8[1].name, "TC");
  ASSERT_EQ(P8[2].name, "SE");
  ASSERT_EQ(P8[3].name, "SEC");
  const std::vector<std::pair<test::Named, test::Named>> pairs = {{P8[2], P8[2]}, {P8[2], P8[3]}, {P8[1], P8[2]}};
  for (bool in_lanes : {true, false}) {
    detail::batch_simd_resume_in_lanes(in_lanes);
    for (const auto& [A, B] : pairs) {
      const std::string name = A.name + "-" + B.name + (in_lanes ? " (lanes resume)" : " (scalar resumes)");
      const std::vector<Pose> P = examples::paper_sweep(A.shape, B.shape, 4000);
      BatchOptions o;
      same_rows_and_lane_count(name, A.shape, B.shape, P, o);  // every row and iteration count the loop's, threads 1 and 3
      // On one thread (the counters are per thread).
      const std::size_t scalar0 = detail::batch_simd_resumed_rows(), lanes0 = detail::batch_simd_lane_resumed_rows();
      Rows got(P.size());
      o.threads = 1;
      solve_batch(A.shape, B.shape, P, o, got.out());
      const std::size_t by_scalar = detail::batch_simd_resumed_rows() - scalar0;
      const std::size_t by_lanes = detail::batch_simd_lane_resumed_rows() - lanes0;
      if (in_lanes)
        EXPECT_GT(by_lanes, 0u) << name << ": no row was resumed in lanes";
      else
        EXPECT_TRUE(by_scalar > 0u && by_lanes == 0u) << name << ": " << by_scalar << " rows resumed by the scalar solver, " << by_lanes << " in lanes";
      std::printf("[%s] %s: of %zu cold rows, %zu resumed in lanes and %zu by the scalar solver at an LM step\n", GetParam(),
                  name.c_str(), P.size(), by_lanes, by_scalar);
    }
  }
  detail::batch_simd_resume_in_lanes(true);
}

// batch_simd_mark_declined, the benchmark's record of the rows that the
// lanes hand to the loop (bench_throughput times the loop on them): on one
// thread every row of a pass whose rows all reach the lanes is either
// answered in lanes or marked, a warm chain's cold first row among the
// marked; with the marks unset, a pass marks nothing.
TEST_P(BatchSimd, DeclinedRowsAreMarked) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> P8 = test::paper_shapes();
  ASSERT_EQ(P8[2].name, "SE");
  const Shape& se = P8[2].shape;
  // 1200 rows: 4 cold blocks of 256 and one of 176, each a multiple of
  // every lane count; warm, chains of 1024 and 176 rows.
  const std::vector<Pose> P = poses_for(se, se, 1200, 91);
  for (bool warm : {false, true}) {
    BatchOptions o;
    o.warm_start = warm;
    o.threads = 1;
    Rows got(P.size());
    std::vector<std::uint8_t> marks(P.size(), 0);
    const std::size_t before = detail::batch_simd_lane_rows();
    detail::batch_simd_mark_declined(&marks);
    solve_batch(se, se, P, o, got.out());
    detail::batch_simd_mark_declined(nullptr);
    const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
    const std::size_t marked = static_cast<std::size_t>(std::count(marks.begin(), marks.end(), 1));
    EXPECT_EQ(lane_rows + marked, P.size()) << (warm ? "warm" : "cold") << ": " << lane_rows << " in lanes, " << marked << " marked";
    if (warm) {
      EXPECT_EQ(marks[0], 1);
      EXPECT_EQ(marks[o.warm_chain], 1);
    }
    std::fill(marks.begin(), marks.end(), 0);
    solve_batch(se, se, P, o, got.out());
    EXPECT_EQ(std::count(marks.begin(), marks.end(), 1), 0) << "marks unset, yet rows marked";
    std::printf("[%s] SE-SE %s: %zu of %zu rows declined\n", GetParam(), warm ? "warm" : "cold", marked, P.size());
  }
}

// Cold rows of a smooth truncated cone beside a cone, a superellipsoid, a
// superelliptic cylinder or an ellipsoid, in either order, in the cold
// Newton lanes (the cone's radial extent by two Newton steps along the ray,
// its support point, no stall exit, the Hessians' traces checked): every
// answer and iteration count is the loop's, to the bit. The paper's cone
// and a sharp beta = 120 one; a bound on each pair's share of rows in lanes
// (measured: see the printout).
TEST_P(BatchSimd, ColdConeRowsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> P8 = test::paper_shapes();
  ASSERT_EQ(P8[1].name, "TC");
  const std::vector<test::Named> C = {P8[1], {"TC2", SmoothTruncatedCone(0.6, 0.25, 0.8, 1.9, 120.0)}};
  const std::vector<test::Named> S = {C[0], C[1], P8[2], P8[3], {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)}};
  unsigned seed = 170;
  std::size_t all_rows = 0, all_lanes = 0;
  for (std::size_t i = 0; i < C.size(); ++i)
    for (std::size_t j = 0; j < S.size(); ++j)
      for (int swap = 0; swap < 2; ++swap) {
        if (swap && j < C.size()) continue;  // two cones: both orders come from (i, j) and (j, i) already
        const test::Named& A = swap ? S[j] : C[i];
        const test::Named& B = swap ? C[i] : S[j];
        const std::string name = A.name + "-" + B.name;
        BatchOptions o;
        const std::vector<Pose> P = poses_for(A.shape, B.shape, 1203, seed++);  // random, then a walk
        const std::size_t lane_rows = same_rows_and_lane_count(name, A.shape, B.shape, P, o);
        // Measured (every instruction set): 99.2-99.5% of the paper's cone's
        // rows, 78-99% of the sharp cone's (TC2-TC2 the fewest, 78%: its
        // first run takes an LM step or fails on 15% of the rows, which the
        // lanes hand to the scalar solver; TC2-SEC 86%, TC2-SE 93%).
        const std::size_t want_pct = A.name == "TC2" || B.name == "TC2" ? (name == "TC2-TC2" ? 76 : 84) : 98;
        EXPECT_GE(lane_rows * 100, P.size() * want_pct) << name << ": " << lane_rows << " of " << P.size() << " rows in lanes";
        std::printf("[%s] %s: %zu of %zu cold rows in lanes\n", GetParam(), name.c_str(), lane_rows, P.size());
        all_rows += P.size(), all_lanes += lane_rows;
      }
  std::printf("[%s] cold cone rows: %zu of %zu in lanes\n", GetParam(), all_lanes, all_rows);
}

// A sphere runs in the Newton lanes beside a superellipsoid, a
// superelliptic cylinder, a cone or a polytope, cold and in warm chains,
// both orders, every answer and iteration count the loop's to the bit
// (the sphere's evaluation is formulas::sphere, shared with Sphere::eval).
// Beside an ellipsoid or a sphere it does not (the scalar solver starts
// those from their closed form or the ray guess), and the rows are still
// the loop's.
TEST_P(BatchSimd, SpherePairsRunInNewtonLanes) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const std::vector<test::Named> P8 = test::paper_shapes();
  ASSERT_EQ(P8[0].name, "Poly");
  const test::Named ball = {"Sphere", Sphere(0.8)};
  std::vector<test::Named> S = {P8[1], P8[2], P8[3], {"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)}, {"Sphere2", Sphere(1.3)}};
  if (!lanes_take_no_polytope(GetParam())) S.push_back(P8[0]);
  unsigned seed = 300;
  for (const test::Named& other : S)
    for (int swap = 0; swap < 2; ++swap)
      for (bool warm : {false, true}) {
        const test::Named& A = swap ? other : ball;
        const test::Named& B = swap ? ball : other;
        const std::string name = A.name + "-" + B.name + (warm ? " warm" : " cold");
        BatchOptions o;
        o.warm_start = warm;
        o.warm_chain = 300;
        const std::vector<Pose> P = poses_for(A.shape, B.shape, warm ? 8 * 300 : 803, seed++);
        const std::size_t lane_rows = same_rows_and_lane_count(name, A.shape, B.shape, P, o);
        const bool newton = other.name != "Ellip" && other.name != "Sphere2";
        if (newton) {
          // Measured: 99.1-100% of the rows on every instruction set.
          EXPECT_GE(lane_rows * 100, P.size() * 97) << name << ": " << lane_rows << " of " << P.size() << " rows in lanes";
        } else {
          EXPECT_EQ(lane_rows, 0u) << name;
        }
        std::printf("[%s] %s: %zu of %zu rows in lanes\n", GetParam(), name.c_str(), lane_rows, P.size());
      }
}

// The warm Newton lanes read the options that their path depends on (the
// tolerance, the surrogate factor and trust region, the fractions to the
// boundary, the step limits, Armijo's constant, the backtracking, the
// iteration limit, the predictor's order): under each, every warm answer
// and iteration count is the loop's, to the bit, and most rows are still
// answered in lanes.
TEST_P(BatchSimd, WarmLanesFollowTheOptions) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const auto pairs = option_test_pairs();
  const bool fused_poly = lanes_take_no_polytope(GetParam());
  std::vector<std::pair<std::string, SolverOptions>> opts = {{"tight", tight_options()}};
  SolverOptions s;
  s.lambda_fraction_to_boundary = 0.6, s.lambda_fraction_to_boundary_restart = 0.8;
  opts.push_back({"fractions", s});
  s = SolverOptions{};
  s.max_step_s = 0.05, s.max_step_x = 0.02;
  opts.push_back({"short steps", s});
  s = SolverOptions{};
  s.armijo_c = 0.3, s.backtrack_factor = 0.8, s.max_backtracks = 3;
  opts.push_back({"strict line search", s});
  s = SolverOptions{};
  s.max_iterations = 7;  // a chain's cold first row may run out of them
  opts.push_back({"7 steps", s});
  for (int order : {0, 1}) {
    s = SolverOptions{};
    s.warm_predictor_order = order;
    opts.push_back({"predictor order " + std::to_string(order), s});
  }
  unsigned seed = 250;
  for (const auto& pr : pairs)
    for (const auto& op : opts) {
      const std::string name = pr.first.name + "-" + pr.second.name + " (" + op.first + ")";
      BatchOptions o;
      o.solver = op.second;
      o.warm_start = true;
      o.warm_chain = 60;
      std::vector<Pose> P = poses_for(pr.first.shape, pr.second.shape, 2 * 10 * o.warm_chain, seed++);
      P.erase(P.begin(), P.begin() + static_cast<long>(P.size() / 2));  // the random walk only
      const std::size_t lane_rows = same_rows_and_lane_count(name, pr.first.shape, pr.second.shape, P, o);
      if (pr.first.name == "Poly" && fused_poly) EXPECT_EQ(lane_rows, 0u) << name;
      else EXPECT_GT(lane_rows, P.size() / 2) << name;
      std::printf("[%s] %s: %zu of %zu warm rows in lanes\n", GetParam(), name.c_str(), lane_rows, P.size());
    }
}

// The cold Newton lanes read the options the scalar solver's first cold
// start reads: the tolerance, the surrogate factor and trust region, the
// fraction to the boundary, the iteration limit, the stall exit (off
// without the rounding continuation; a strict one, lm_min_progress = 0.2 and
// lm_stall_limit = 1, which stalls many runs that the scalar solver then
// restarts), and the support guess (off: the ray guess, which the lanes do
// not take). Every answer and iteration count is still the loop's. A pair
// with a cone or a polytope (not homogeneous) has no stall exit: under the
// strict one its rows stay in lanes (cone: 98% measured, 68% when the lanes
// stall it; Poly-SE: 98.7%, 68.8% when the lanes stall it).
TEST_P(BatchSimd, ColdSuperquadricLanesFollowTheOptions) {
  if (std::string(GetParam()) == "none" || std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  const auto pairs = option_test_pairs();
  const bool fused_poly = lanes_take_no_polytope(GetParam());
  std::vector<std::pair<std::string, SolverOptions>> opts = {{"tight", tight_options()}};
  SolverOptions s;
  s.lambda_fraction_to_boundary = 0.6, s.max_iterations = 6;
  opts.push_back({"bold, 6 steps", s});
  s = SolverOptions{};
  s.rounding_continuation = false;
  opts.push_back({"no rounding", s});
  s = SolverOptions{};
  s.lm_min_progress = 0.2, s.lm_stall_limit = 1;
  opts.push_back({"strict stall", s});
  s = SolverOptions{};
  s.support_guess = false;
  opts.push_back({"no support guess", s});
  unsigned seed = 150;
  for (const auto& pr : pairs)
    for (const auto& op : opts) {
      const std::string name = pr.first.name + "-" + pr.second.name + " (" + op.first + ")";
      BatchOptions o;
      o.solver = op.second;
      const std::vector<Pose> P = poses_for(pr.first.shape, pr.second.shape, 603, seed++);
      const std::size_t lane_rows = same_rows_and_lane_count(name, pr.first.shape, pr.second.shape, P, o);
      const bool declined = pr.first.name == "Poly" && fused_poly;
      if (!op.second.support_guess || declined) EXPECT_EQ(lane_rows, 0u) << name;
      else EXPECT_GT(lane_rows, P.size() / 4) << name;
      if ((pr.first.name == "TC2" || pr.first.name == "Poly") && op.first == "strict stall" && !declined)
        EXPECT_GE(lane_rows * 100, P.size() * 95) << name;
      std::printf("[%s] %s: %zu of %zu cold rows in lanes\n", GetParam(), name.c_str(), lane_rows, P.size());
    }
}

// The contact kinematics the lanes write (gap, normal, witness points) are
// contact_kinematics() of the loop's answers, to the bit: a batch that
// asks for them (the Python module's default) keeps the lanes.
TEST_P(BatchSimd, LanesWriteTheLoopsKinematics) {
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "lanes here: " << batch_simd_isa();
  // Ellipsoids (closed-form lanes), and a superellipsoid and a cone, whose
  // warm rows the Newton lanes answer.
  const std::vector<test::Named> S = {{"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
                                      {"Ellip2", Superellipsoid(1.2, 0.3, 0.7, 1.0)},
                                      {"Plate", Superellipsoid(1000.0, 1.0, 30.0, 1.0)},
                                      {"SE8", Superellipsoid(0.5, 1.0, 1.5, 8.0)},
                                      {"TC", SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0)}};
  auto same = [](double u, double v) { return u == v || (std::isnan(u) && std::isnan(v)); };
  std::size_t lane_rows = 0, rows = 0;
  long differ = 0;
  unsigned seed = 40;
  for (const auto& A : S)
    for (const auto& B : S)
      for (bool warm : {false, true}) {
        const std::vector<Pose> P = poses_for(A.shape, B.shape, 1203, seed++);
        BatchOptions o;
        o.warm_start = warm;
        o.warm_chain = 97;
        const Rows want = loop(A.shape, B.shape, P, o, true);
        Rows got(P.size(), true);
        const std::size_t before = detail::batch_simd_lane_rows();
        solve_batch(A.shape, B.shape, P, o, got.out());
        lane_rows += detail::batch_simd_lane_rows() - before;
        for (std::size_t k = 0; k < P.size(); ++k) {
          ++rows;
          bool eq = same(got.gap[k], want.gap[k]);
          for (int j = 0; j < 3; ++j)
            eq = eq && same(got.normal[3 * k + j], want.normal[3 * k + j]) && same(got.p1[3 * k + j], want.p1[3 * k + j]) &&
                 same(got.p2[3 * k + j], want.p2[3 * k + j]);
          if (!eq && ++differ <= 5)
            ADD_FAILURE() << A.name << "-" << B.name << (warm ? " warm" : " cold") << " row " << k << ": gap "
                          << got.gap[k] << " vs " << want.gap[k] << ", normal " << got.normal[3 * k] << " vs "
                          << want.normal[3 * k];
        }
      }
  EXPECT_EQ(differ, 0) << "of " << rows << " rows";
  if (std::string(GetParam()) == "none") EXPECT_EQ(lane_rows, 0u);
  else EXPECT_GT(lane_rows, rows / 4) << "of " << rows << " rows";
}

// Two ellipsoids, one with a semi-axis below the closed-form lanes' range:
// the scalar solver still starts them from their closed form, so the
// Newton lanes must not take them (they run the loop).
TEST(BatchSimdCover, TwoEllipsoidsOfAnySizeStayOffTheNewtonLanes) {
  const Shape tiny = Superellipsoid(1e-160, 1.0, 0.7, 1.0), ellip = Superellipsoid(0.5, 1.0, 1.5, 1.0);
  EXPECT_FALSE(detail::batch_simd_covers(tiny, ellip, SolverOptions{}));
  EXPECT_FALSE(detail::batch_simd_covers(ellip, tiny, SolverOptions{}));
  if (std::string(batch_simd_isa()) != "none")
    EXPECT_TRUE(detail::batch_simd_covers(ellip, Superellipsoid(0.5, 1.0, 1.5, 2.0), SolverOptions{}));
}

INSTANTIATE_TEST_SUITE_P(Isa, BatchSimd, ::testing::Values("none", "sse2", "avx2", "avx512"));

}  // namespace

namespace {

// The warm start of two ellipsoids is their closed form started from the
// last contact's l: on a random walk it answers what the cold solve
// answers (to the solver's tolerance) and is marked warm-started. (Its
// cost against cold is an instruction count: scripts/callgrind_pairs.sh.)
TEST(WarmEllipsoids, ClosedFormFromTheLastContactAgreesWithCold) {
  std::mt19937_64 rng(21);
  const std::vector<test::Named> S = {{"Ellip", Superellipsoid(0.5, 1.0, 1.5, 1.0)},
                                      {"Ellip2", Superellipsoid(1.2, 0.3, 0.7, 1.0)},
                                      {"Plate", Superellipsoid(1000.0, 1.0, 30.0, 1.0)}};
  for (const auto& A : S)
    for (const auto& B : S) {
      const std::vector<Pose> P = poses_for(A.shape, B.shape, 600, 77);
      WarmStart ws;
      for (std::size_t k = 40; k < P.size(); ++k) {  // past the planted bad rows
        const SolveResult w = solve(A.shape, B.shape, P[k], SolverOptions{}, &ws);
        const SolveResult c = solve(A.shape, B.shape, P[k]);
        ASSERT_TRUE(c.converged()) << A.name << "-" << B.name << " row " << k;
        ASSERT_TRUE(w.converged()) << A.name << "-" << B.name << " row " << k;
        if (k > 40) EXPECT_TRUE(w.warm_started) << A.name << "-" << B.name << " row " << k;
        EXPECT_NEAR(w.alpha, c.alpha, 1e-9 * c.alpha) << A.name << "-" << B.name << " row " << k;
      }
    }
}

}  // namespace
