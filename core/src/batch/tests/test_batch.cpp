// solve_batch against the serial loop it documents (batch.hpp), bit for bit,
// for every thread count, cold and warm, one pair and mixed pairs, with and
// without derivatives; and its argument checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

/// A seeded random walk of relative poses (consecutive poses close, as in a
/// simulation, so warm starts matter), |r| kept in [0.3, 4], with a NaN pose
/// and a reflection planted to check that bad rows stay per-row statuses.
std::vector<Pose> walk(std::size_t n, unsigned seed, double step = 0.05) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Pose> poses(n);
  Pose X{test::random_rotation(rng), 2.0 * test::random_unit(rng)};
  for (std::size_t k = 0; k < n; ++k) {
    Vec6 xi;
    for (int j = 0; j < 6; ++j) xi[j] = step * g(rng);
    X = X * se3_exp(xi);
    const double r = X.p.norm();
    if (r < 0.3 || r > 4.0) X.p *= 2.0 / r;
    poses[k] = X;
  }
  if (n > 40) {
    poses[17].p[1] = std::numeric_limits<double>::quiet_NaN();
    poses[40].R.col(0) *= -1.0;
  }
  return poses;
}

struct Rows {
  std::vector<double> alpha, x, dalpha;
  std::vector<std::int32_t> status, iterations;
  explicit Rows(std::size_t n, bool derivatives)
      : alpha(n), x(3 * n), dalpha(derivatives ? 6 * n : 0), status(n), iterations(n) {}
  BatchOutput out() { return {alpha, x, status, iterations, dalpha}; }
};

/// The serial loop of batch.hpp, written out with solve() and alpha_gradient().
Rows serial(const std::vector<const Shape*>& b1, const std::vector<const Shape*>& b2, const std::vector<Pose>& poses,
            const BatchOptions& o) {
  Rows rows(poses.size(), o.derivatives);
  SolverOptions so = o.solver;
  so.derivatives = so.derivatives || o.derivatives;
  WarmStart ws;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Shape* a = b1.size() == 1 ? b1[0] : b1[k];
    const Shape* b = b2.size() == 1 ? b2[0] : b2[k];
    const bool pair_changed = k > 0 && ((b1.size() > 1 && b1[k] != b1[k - 1]) || (b2.size() > 1 && b2[k] != b2[k - 1]));
    if (k % o.warm_chain == 0 || pair_changed) ws.reset();
    const SolveResult r = solve(*a, *b, poses[k], so, o.warm_start ? &ws : nullptr);
    rows.alpha[k] = r.alpha;
    for (int j = 0; j < 3; ++j) rows.x[3 * k + j] = r.x_1[j];
    rows.status[k] = static_cast<std::int32_t>(r.status);
    rows.iterations[k] = r.iterations;
    if (o.derivatives) {
      const Row6 d = r.converged() ? alpha_gradient(r) : Row6::Zero();
      for (int j = 0; j < 6; ++j) rows.dalpha[6 * k + j] = d[j];
    }
  }
  return rows;
}

/// Bitwise equality of doubles (NaN == NaN when the bits agree).
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

void expect_same(const Rows& want, const Rows& got, const std::string& what) {
  EXPECT_TRUE(same_bits(want.alpha, got.alpha)) << what << ": alpha";
  EXPECT_TRUE(same_bits(want.x, got.x)) << what << ": x";
  EXPECT_TRUE(same_bits(want.dalpha, got.dalpha)) << what << ": dalpha_dxi";
  EXPECT_EQ(want.status, got.status) << what << ": status";
  EXPECT_EQ(want.iterations, got.iterations) << what << ": iterations";
}

int count(const Rows& r, SolveStatus s) {
  int n = 0;
  for (std::int32_t v : r.status) n += v == static_cast<std::int32_t>(s);
  return n;
}

}  // namespace

TEST(Batch, OnePairEqualsSerialLoopForEveryThreadCount) {
  const Shape a = test::paper_poly();
  const Shape b = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  const std::vector<Pose> poses = walk(3000, 1);
  const std::vector<const Shape*> b1{&a}, b2{&b};
  int cases = 0;
  for (const bool warm : {false, true}) {
    for (const bool deriv : {false, true}) {
      BatchOptions o;
      o.warm_start = warm;
      o.derivatives = deriv;
      o.warm_chain = 256;  // 12 chains: chunk boundaries fall on several of them
      const Rows want = serial(b1, b2, poses, o);
      // The walk must exercise what it claims: every row converged but the
      // two planted bad poses, which are refused as invalid.
      EXPECT_EQ(count(want, SolveStatus::Converged), 2998);
      EXPECT_EQ(count(want, SolveStatus::InvalidInput), 2);
      for (const int threads : {1, 2, 3, 7, 0}) {
        o.threads = threads;
        Rows got(poses.size(), deriv);
        solve_batch(a, b, poses, o, got.out());
        expect_same(want, got, "warm=" + std::to_string(warm) + " deriv=" + std::to_string(deriv) +
                                   " threads=" + std::to_string(threads));
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 20);
}

TEST(Batch, WarmChainsCutIterations) {
  const Shape a = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  const Shape b = SuperellipticCylinder(1.0, 2.0, 8.0);
  // Steps of 0.01 (rad, and body lengths) per twist component. At 0.05 the
  // n = 8 faces' contact jumps across them from pose to pose, and the last
  // answer is no better a start than the support guess (SE-SEC, 2000 poses
  // solved serially: 9699 warm steps against 9650 cold).
  const std::vector<Pose> poses = walk(2000, 2, 0.01);
  BatchOptions o;  // the default warm predictor, which stands aside on a random walk
  Rows cold(poses.size(), false), warm(poses.size(), false);
  solve_batch(a, b, poses, o, cold.out());
  o.warm_start = true;
  o.threads = 2;
  solve_batch(a, b, poses, o, warm.out());
  long ic = 0, iw = 0;
  for (std::size_t k = 0; k < poses.size(); ++k) ic += cold.iterations[k], iw += warm.iterations[k];
  EXPECT_LT(iw, ic);
}

TEST(Batch, MixedPairsEqualSerialLoopAndRowMajorSpans) {
  const std::vector<test::Named> cat = test::catalogue();
  const std::size_t n = 2500;
  const std::vector<Pose> poses = walk(n, 3);
  // Pairs change in runs of varying length, so the warm start is reset
  // inside chains as well as at their starts.
  std::vector<const Shape*> b1(n), b2(n);
  std::mt19937_64 rng(4);
  for (std::size_t k = 0; k < n;) {
    const std::size_t len = 1 + rng() % 90;
    const Shape* a = &cat[rng() % cat.size()].shape;
    const Shape* b = &cat[rng() % cat.size()].shape;
    for (std::size_t j = 0; j < len && k < n; ++j, ++k) b1[k] = a, b2[k] = b;
  }
  // The same poses as row-major (N, 3, 3) and (N, 3) arrays.
  std::vector<double> R(9 * n), p(3 * n);
  for (std::size_t k = 0; k < n; ++k)
    for (int i = 0; i < 3; ++i) {
      p[3 * k + i] = poses[k].p[i];
      for (int j = 0; j < 3; ++j) R[9 * k + 3 * i + j] = poses[k].R(i, j);
    }
  int cases = 0;
  for (const bool warm : {false, true}) {
    BatchOptions o;
    o.warm_start = warm;
    o.derivatives = true;
    o.warm_chain = 300;
    const Rows want = serial(b1, b2, poses, o);
    EXPECT_EQ(count(want, SolveStatus::Converged), 2498);  // all but the walk's two planted bad poses
    EXPECT_EQ(count(want, SolveStatus::InvalidInput), 2);
    for (const int threads : {1, 2, 5}) {
      o.threads = threads;
      Rows got(n, true), got_rm(n, true);
      solve_batch(b1, b2, Span<const Pose>(poses), o, got.out());
      solve_batch(b1, b2, Span<const double>(R), Span<const double>(p), o, got_rm.out());
      expect_same(want, got, "poses, threads=" + std::to_string(threads));
      expect_same(want, got_rm, "row-major, threads=" + std::to_string(threads));
      cases += 2;
    }
  }
  EXPECT_EQ(cases, 12);
}

TEST(Batch, EmptyBatchIsFine) {
  const Shape a = Sphere(1.0);
  std::vector<Pose> none;
  Rows r(0, true);
  BatchOptions o;
  o.derivatives = true;
  o.threads = 0;
  EXPECT_NO_THROW(solve_batch(a, a, none, o, r.out()));
}

TEST(Batch, BadArgumentsNameTheField) {
  const Shape a = Sphere(1.0);
  const std::vector<Pose> poses(4);
  auto message = [&](auto&& call) {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no exception)");
  };
  const std::vector<const Shape*> one{&a}, three{&a, &a, &a}, with_null{nullptr};
  {
    Rows r(4, false);
    EXPECT_NE(message([&] { solve_batch(three, one, Span<const Pose>(poses), BatchOptions{}, r.out()); }).find("body1 must hold 1 shape or one per row (4), got 3"), std::string::npos);
    EXPECT_NE(message([&] { solve_batch(one, with_null, Span<const Pose>(poses), BatchOptions{}, r.out()); }).find("body2[0] is a null shape"), std::string::npos);
  }
  {
    Rows r(3, false);
    EXPECT_NE(message([&] { solve_batch(a, a, poses, BatchOptions{}, r.out()); }).find("output alpha must hold 4 values, got 3"), std::string::npos);
  }
  {
    Rows r(4, false);  // no room for derivatives
    BatchOptions o;
    o.derivatives = true;
    EXPECT_NE(message([&] { solve_batch(a, a, poses, o, r.out()); }).find("output dalpha_dxi must hold 24 values, got 0"), std::string::npos);
  }
  {
    Rows r(4, false);
    BatchOptions o;
    o.threads = -2;
    EXPECT_NE(message([&] { solve_batch(a, a, poses, o, r.out()); }).find("'threads' must be >= 0 (0 = all CPUs), got -2"), std::string::npos);
    o = BatchOptions{};
    o.warm_chain = 0;
    EXPECT_NE(message([&] { solve_batch(a, a, poses, o, r.out()); }).find("'warm_chain' must be >= 1, got 0"), std::string::npos);
    o = BatchOptions{};
    o.solver.tolerance = -1.0;
    EXPECT_NE(message([&] { solve_batch(a, a, poses, o, r.out()); }).find("'tolerance'"), std::string::npos);
  }
  {
    Rows r(4, false);
    std::vector<double> R(35), p(12);
    EXPECT_NE(message([&] { solve_batch(one, one, Span<const double>(R), Span<const double>(p), BatchOptions{}, r.out()); }).find("R must hold 9 values per row (36 for 4 rows), got 35"), std::string::npos);
    std::vector<double> p_bad(13);
    EXPECT_NE(message([&] { solve_batch(one, one, Span<const double>(R), Span<const double>(p_bad), BatchOptions{}, r.out()); }).find("p must hold 3 values per row, got 13"), std::string::npos);
  }
}

TEST(Batch, ThreadCountResolves) {
  EXPECT_EQ(resolve_thread_count(3), 3);
  EXPECT_GE(resolve_thread_count(0), 1);
}

// The optional kinematics outputs equal contact_kinematics and
// contact_kinematics_derivatives of each row's solve, for any thread count;
// rows without a contact (NaN pose, reflection, Separated under alpha_max)
// hold NaN and zeros, and no worker throws.
TEST(Batch, KinematicsEqualContactKinematicsPerRow) {
  const Shape a = Superellipsoid(0.5, 1.0, 1.5, 8.0);
  const Shape b = SmoothTruncatedCone(1.0, 1.5, 1.5, 1.5, 20.0);
  const std::vector<Pose> poses = walk(300, 5);
  for (const double alpha_max : {std::numeric_limits<double>::infinity(), 1.5}) {
    for (const int threads : {1, 3}) {
      BatchOptions o;
      o.derivatives = true;
      o.threads = threads;
      o.solver.alpha_max = alpha_max;
      const std::size_t n = poses.size();
      Rows r(n, true);
      std::vector<double> gap(n), nrm(3 * n), p1(3 * n), p2(3 * n), dgap(6 * n), dn(18 * n), dp1(18 * n),
          dp2(18 * n);
      BatchOutput out = r.out();
      out.gap = gap, out.normal_1 = nrm, out.p1_1 = p1, out.p2_1 = p2;
      out.dgap_dxi = dgap, out.dnormal_dxi = dn, out.dp1_dxi = dp1, out.dp2_dxi = dp2;
      solve_batch(a, b, poses, o, out);
      SolverOptions so = o.solver;
      so.derivatives = true;
      int contacts = 0, none = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const SolveResult res = solve(a, b, poses[k], so);
        ASSERT_EQ(static_cast<int>(res.status), r.status[k]) << k;
        if (!res.converged()) {
          ++none;
          EXPECT_TRUE(std::isnan(gap[k]) && std::isnan(p1[3 * k]) && std::isnan(nrm[3 * k + 2])) << k;
          for (int j = 0; j < 18; ++j) EXPECT_EQ(dp2[18 * k + j], 0.0) << k;
          continue;
        }
        ++contacts;
        const ContactKinematics c = contact_kinematics(res);
        const ContactKinematicsDerivatives d = contact_kinematics_derivatives(res, solution_sensitivity(res));
        EXPECT_EQ(gap[k], c.gap) << k;
        for (int i = 0; i < 3; ++i) {
          EXPECT_EQ(nrm[3 * k + i], c.nhat_1[i]) << k;
          EXPECT_EQ(p1[3 * k + i], c.p1_1[i]) << k;
          EXPECT_EQ(p2[3 * k + i], c.p2_1[i]) << k;
          for (int j = 0; j < 6; ++j) {
            EXPECT_EQ(dn[18 * k + 6 * i + j], d.dnhat_1_dxi(i, j)) << k;
            EXPECT_EQ(dp1[18 * k + 6 * i + j], d.dp1_1_dxi(i, j)) << k;
            EXPECT_EQ(dp2[18 * k + 6 * i + j], d.dp2_1_dxi(i, j)) << k;
          }
        }
        for (int j = 0; j < 6; ++j) EXPECT_EQ(dgap[6 * k + j], d.dgap_dxi[j]) << k;
      }
      EXPECT_GT(contacts, 50);
      EXPECT_GE(none, 2);  // the NaN pose and the reflection at least
    }
  }
}

TEST(Batch, KinematicsDerivativesNeedDerivativesAndRightSizes) {
  const Shape a = Sphere(1.0);
  const std::vector<Pose> poses = walk(10, 6);
  BatchOptions o;
  Rows r(10, false);
  std::vector<double> dgap(60), gap(9);
  BatchOutput out = r.out();
  out.dgap_dxi = dgap;
  EXPECT_THROW(solve_batch(a, a, poses, o, out), std::invalid_argument);
  out = r.out();
  out.gap = gap;
  EXPECT_THROW(solve_batch(a, a, poses, o, out), std::invalid_argument);
}

// BatchOptions::poll runs on the calling thread only, every 64 of its rows
// (before each of its blocks on the SIMD path: cold, blocks of 256 rows), and a cancel it sets stops the
// batch before the next row: what the Python module's Ctrl-C relies on.
struct PollLog {
  std::thread::id caller = std::this_thread::get_id();
  int calls = 0, cancel_at = 0;
  bool foreign = false;  // called from a thread other than the caller
  std::atomic<bool> cancel{false};
  static void poll(void* d) {
    PollLog& l = *static_cast<PollLog*>(d);
    if (std::this_thread::get_id() != l.caller) l.foreign = true;
    if (++l.calls == l.cancel_at) l.cancel = true;
  }
};

/// One thread, with `log`'s poll, which cancels at its cancel_at-th call:
/// the number of rows solved (the others keep -7 in alpha).
long rows_before_cancel(const Shape& a, const Shape& b, const std::vector<Pose>& poses, PollLog& log, Rows& r) {
  BatchOptions o;
  o.poll = &PollLog::poll;
  o.poll_data = &log;
  o.cancel = &log.cancel;
  std::fill(r.alpha.begin(), r.alpha.end(), -7.0);
  solve_batch(a, b, poses, o, r.out());
  return std::count_if(r.alpha.begin(), r.alpha.end(), [](double v) { return v != -7.0; });
}

TEST(Batch, PollRunsOnTheCallingThreadAndItsCancelStopsTheBatch) {
  // A pair the SIMD lanes do not take (a sphere beside an ellipsoid): the
  // loop's polls, every 64 rows.
  const Shape a = Sphere(1.0), b = Superellipsoid(0.5, 1.0, 1.5, 1.0);
  const std::vector<Pose> poses = walk(2000, 11);
  for (const int threads : {1, 2}) {
    PollLog log;
    BatchOptions o;
    o.threads = threads;
    o.poll = &PollLog::poll;
    o.poll_data = &log;
    Rows r(poses.size(), false);
    solve_batch(a, b, poses, o, r.out());
    EXPECT_FALSE(log.foreign) << threads;
    // Rows 64, 128, ... of the caller's rows: all 2000 on one thread (on
    // two, those of the blocks it took, which the other thread's speed
    // decides).
    if (threads == 1) EXPECT_GE(log.calls, 31);
  }
  // Cancelled at the second poll: rows 0..127 solved, none after.
  PollLog log;
  log.cancel_at = 2;
  Rows r(poses.size(), false);
  EXPECT_EQ(rows_before_cancel(a, b, poses, log, r), 128);
  EXPECT_NE(r.alpha[127], -7.0);
  EXPECT_EQ(r.alpha[128], -7.0);
}

TEST(Batch, PollRunsBetweenTheBlocksOfTheSimdPath) {
  if (std::string(batch_simd_isa()) == "none") GTEST_SKIP() << "no SIMD path on this CPU";
  const Shape e1 = Superellipsoid(0.5, 1.0, 1.5, 1.0), e2 = Superellipsoid(1.0, 0.7, 0.4, 1.0);
  const std::vector<Pose> poses = walk(3000, 12);
  PollLog log;
  log.cancel_at = 1;
  Rows r(poses.size(), false);
  EXPECT_EQ(rows_before_cancel(e1, e2, poses, log, r), 256);
  EXPECT_EQ(log.calls, 1);  // before the second block, which it cancels
}

// A cancel flag already set stops every worker before its first row.
TEST(Batch, CancelFlagStopsBeforeTheNextRow) {
  const Shape a = Sphere(1.0);
  const std::vector<Pose> poses = walk(100, 7);
  BatchOptions o;
  o.threads = 2;
  std::atomic<bool> cancel{true};
  o.cancel = &cancel;
  Rows r(100, false);
  std::fill(r.alpha.begin(), r.alpha.end(), -7.0);
  solve_batch(a, a, poses, o, r.out());
  for (const double v : r.alpha) EXPECT_EQ(v, -7.0);
  cancel = false;
  solve_batch(a, a, poses, o, r.out());
  EXPECT_NE(r.alpha[0], -7.0);
}
