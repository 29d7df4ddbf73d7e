// solve_batch's modes for a simulator (batch.hpp): one warm state per row
// in and out, a different pair in every row, the contact wrench and its
// derivatives per row. Every row against the loop of solve() and the
// functions of derivatives.hpp, bit for bit, the warm state out included;
// for every instruction set the CPU has (IDCOL_SIMD), every thread count
// tried; and the argument checks of these modes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "examples/paper_shapes.hpp"
#include "src/batch/batch_simd.hpp"
#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/solver.hpp"
#include "test_util.hpp"

using namespace idcol;

namespace {

/// Rows of a step of a simulation: N rows of pairs drawn from the
/// catalogue (a different pair from row to row), at poses around contact
/// (|r| between 0.6 and 1.3 of the outer radii's sum: penetrating, touching
/// and apart), with warm states from a first call at nearby poses (a few
/// rows left cold).
struct Step {
  std::vector<test::Named> shapes = test::catalogue();
  std::vector<const Shape*> b1, b2;
  std::vector<Pose> poses0, poses;
  /// `only`: draw from these catalogue shapes alone (empty: all of them).
  explicit Step(std::size_t n, unsigned seed, const std::vector<std::string>& only = {}) {
    if (!only.empty()) {
      std::vector<test::Named> kept;
      for (const test::Named& s : shapes)
        for (const std::string& name : only)
          if (s.name == name) kept.push_back(s);
      shapes = kept;
    }
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<std::size_t> pick(0, shapes.size() - 1);
    std::uniform_real_distribution<double> u(0.6, 1.3);
    std::normal_distribution<double> g(0.0, 1.0);
    for (std::size_t k = 0; k < n; ++k) {
      b1.push_back(&shapes[pick(rng)].shape);
      b2.push_back(&shapes[pick(rng)].shape);
      const double reach = radii(*b1.back()).outer + radii(*b2.back()).outer;
      const Pose X{test::random_rotation(rng), u(rng) * reach * test::random_unit(rng)};
      Vec6 xi;
      for (int j = 0; j < 6; ++j) xi[j] = 0.01 * g(rng);
      poses0.push_back(X);
      poses.push_back(X * se3_exp(xi));
    }
  }
};

// n == 0 compares nothing: an empty output's data() may be null, which
// memcmp may not be given even for zero bytes.
bool same(const double* a, const double* b, std::size_t n) { return n == 0 || std::memcmp(a, b, n * sizeof(double)) == 0; }

bool same_warm(const WarmStart& a, const WarmStart& b) {
  return a.valid == b.valid && a.history == b.history && a.extrapolate == b.extrapolate &&
         same(a.z.data(), b.z.data(), 6) && same(&a.length, &b.length, 1) && same(a.z_prev[0].data(), b.z_prev[0].data(), 6) &&
         same(a.z_prev[1].data(), b.z_prev[1].data(), 6);
}

/// Every output of the per-row modes, sized for n rows.
struct Out {
  std::vector<double> alpha, x, dalpha, gap, normal, f_n, F1, F2, df_n, dF1, dF2, dgap, dnormal, dp1, dp2;
  std::vector<std::int32_t> status, iterations;
  std::vector<WarmStart> warm;
  Out(std::size_t n, bool deriv)
      : alpha(n), x(3 * n), dalpha(deriv ? 6 * n : 0), gap(n), normal(3 * n), f_n(n), F1(6 * n), F2(6 * n),
        df_n(deriv ? 6 * n : 0), dF1(deriv ? 36 * n : 0), dF2(deriv ? 36 * n : 0), dgap(deriv ? 6 * n : 0),
        dnormal(deriv ? 18 * n : 0), dp1(deriv ? 18 * n : 0), dp2(deriv ? 18 * n : 0), status(n), iterations(n), warm(n) {}
  BatchOutput view(bool per_row_warm = true) {
    BatchOutput o;
    o.alpha = alpha, o.x_1 = x, o.status = status, o.iterations = iterations, o.dalpha_dxi = dalpha;
    o.gap = gap, o.normal_1 = normal;
    if (per_row_warm) o.warm = warm;
    o.f_n = f_n, o.F1_1 = F1, o.F2_2 = F2, o.df_n_dxi = df_n, o.dF1_dxi = dF1, o.dF2_dxi = dF2;
    o.dgap_dxi = dgap, o.dnormal_dxi = dnormal, o.dp1_dxi = dp1, o.dp2_dxi = dp2;
    return o;
  }
};

/// Row k as the loop computes it: solve() from a copy of the row's warm
/// state, then contact_wrench(), the contact kinematics and their
/// derivatives.
void loop_row(const Shape& a, const Shape& b, const Pose& X, const BatchOptions& o, std::size_t k, Out& out,
              bool per_row_warm = true) {
  SolverOptions so = o.solver;
  so.derivatives = so.derivatives || o.derivatives;
  const SolveResult r = solve(a, b, X, so, per_row_warm ? &out.warm[k] : nullptr);
  out.alpha[k] = r.alpha;
  for (int j = 0; j < 3; ++j) out.x[3 * k + j] = r.x_1[j];
  out.status[k] = static_cast<std::int32_t>(r.status);
  out.iterations[k] = r.iterations;
  const double nan = std::nan("");
  const ContactKinematics c = r.converged() ? contact_kinematics(r) : ContactKinematics{};
  out.gap[k] = c.valid ? c.gap : nan;
  for (int j = 0; j < 3; ++j) out.normal[3 * k + j] = c.valid ? c.nhat_1[j] : nan;
  const ContactWrench w = r.converged() ? contact_wrench(r, o.contact) : ContactWrench{};
  const bool known = r.converged() || (r.status == SolveStatus::Separated && so.alpha_max >= 1.0);
  out.f_n[k] = w.active ? w.f_n : known ? 0.0 : nan;
  for (int j = 0; j < 6; ++j) {
    out.F1[6 * k + j] = w.active ? w.F1_1[j] : known ? 0.0 : nan;
    out.F2[6 * k + j] = w.active ? w.F2_2[j] : known ? 0.0 : nan;
  }
  if (!o.derivatives) return;
  const Row6 g = r.converged() ? alpha_gradient(r) : Row6::Zero();
  for (int j = 0; j < 6; ++j) out.dalpha[6 * k + j] = g[j];
  const ContactWrenchDerivatives d =
      w.active ? contact_wrench_derivatives(r, solution_sensitivity(r), o.contact) : ContactWrenchDerivatives{};
  const ContactKinematicsDerivatives dk =
      r.converged() ? contact_kinematics_derivatives(r, solution_sensitivity(r)) : ContactKinematicsDerivatives{};
  for (int j = 0; j < 6; ++j) {
    out.dgap[6 * k + j] = dk.dgap_dxi[j];
    for (int i = 0; i < 3; ++i) {
      out.dnormal[18 * k + 6 * i + j] = dk.dnhat_1_dxi(i, j);
      out.dp1[18 * k + 6 * i + j] = dk.dp1_1_dxi(i, j);
      out.dp2[18 * k + 6 * i + j] = dk.dp2_1_dxi(i, j);
    }
  }
  for (int i = 0; i < 6; ++i) {
    out.df_n[6 * k + i] = d.df_n_dxi[i];
    for (int j = 0; j < 6; ++j) {
      out.dF1[36 * k + 6 * i + j] = d.dF1_1_dxi(i, j);
      out.dF2[36 * k + 6 * i + j] = d.dF2_2_dxi(i, j);
    }
  }
}

/// Rows that differ, by output; "" when none.
std::string compare(const Out& want, const Out& got, std::size_t n) {
  std::string diff;
  auto check = [&](const char* name, const std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() != b.size() || !same(a.data(), b.data(), a.size())) diff += std::string(" ") + name;
  };
  check("alpha", want.alpha, got.alpha);
  check("x", want.x, got.x);
  check("dalpha_dxi", want.dalpha, got.dalpha);
  check("gap", want.gap, got.gap);
  check("normal", want.normal, got.normal);
  check("f_n", want.f_n, got.f_n);
  check("F1_1", want.F1, got.F1);
  check("F2_2", want.F2, got.F2);
  check("df_n_dxi", want.df_n, got.df_n);
  check("dF1_dxi", want.dF1, got.dF1);
  check("dF2_dxi", want.dF2, got.dF2);
  check("dgap_dxi", want.dgap, got.dgap);
  check("dnormal_dxi", want.dnormal, got.dnormal);
  check("dp1_dxi", want.dp1, got.dp1);
  check("dp2_dxi", want.dp2, got.dp2);
  if (want.status != got.status) diff += " status";
  if (want.iterations != got.iterations) diff += " iterations";
  for (std::size_t k = 0; k < n; ++k)
    if (!same_warm(want.warm[k], got.warm[k])) {
      diff += " warm[" + std::to_string(k) + "]";
      break;
    }
  return diff;
}

/// The warm states two calls leave at poses0 (the second warm-started by
/// the first, so that its states have a history), every seventh row left
/// cold, for the call at poses.
std::vector<WarmStart> warm_states(const Step& s, const BatchOptions& o) {
  Out first(s.poses0.size(), false);
  BatchOptions cold = o;
  cold.derivatives = false;
  cold.solver.alpha_max = std::numeric_limits<double>::infinity();
  solve_batch(s.b1, s.b2, s.poses0, cold, first.view());
  solve_batch(s.b1, s.b2, s.poses0, cold, first.view());
  for (std::size_t k = 0; k < first.warm.size(); k += 7) first.warm[k].reset();
  return first.warm;
}

class BatchRows : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override { setenv("IDCOL_SIMD", GetParam(), 1); }
  void TearDown() override { unsetenv("IDCOL_SIMD"); }
};

TEST_P(BatchRows, EveryRowIsTheLoopsAnswer) {
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  const Step s(700, 3);
  int active = 0, separated = 0, cases = 0;
  for (const double alpha_max : {std::numeric_limits<double>::infinity(), 1.0, 0.9}) {
    for (const bool deriv : {false, true}) {
      BatchOptions o;
      o.solver.alpha_max = alpha_max;
      o.derivatives = deriv;
      o.contact.stiffness = 1e4;
      const std::vector<WarmStart> warm = warm_states(s, o);
      Out want(s.poses.size(), deriv);
      want.warm = warm;
      for (std::size_t k = 0; k < s.poses.size(); ++k) loop_row(*s.b1[k], *s.b2[k], s.poses[k], o, k, want);
      for (const int threads : {1, 3}) {
        o.threads = threads;
        Out got(s.poses.size(), deriv);
        got.warm = warm;
        solve_batch(s.b1, s.b2, s.poses, o, got.view());
        EXPECT_EQ(compare(want, got, s.poses.size()), "")
            << "alpha_max " << alpha_max << ", derivatives " << deriv << ", threads " << threads;
        ++cases;
      }
      for (std::size_t k = 0; k < s.poses.size(); ++k) {
        active += want.f_n[k] > 0.0;
        separated += want.status[k] == static_cast<std::int32_t>(SolveStatus::Separated);
      }
    }
  }
  EXPECT_EQ(cases, 12);
  // The rows exercise what they claim: forces, and rows stopped by alpha_max.
  EXPECT_GT(active, 600);
  EXPECT_GT(separated, 300);
}

TEST_P(BatchRows, AHundredRowsOfFourPairsRunInLanesAsTheLoop) {
  // A call small enough that the batch counts its rows per pair on the
  // stack before grouping them (some_pair_fills): about 25 rows of each of
  // four pairs, each enough to fill two calls of the lanes, warm per row
  // with every derivative.
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  const Step s(100, 9, {"SE_n8", "SEC_n8"});
  const std::size_t n = s.poses.size();
  BatchOptions o;
  o.derivatives = true;
  o.contact.stiffness = 1e4;
  const std::vector<WarmStart> warm = warm_states(s, o);
  Out want(n, true);
  want.warm = warm;
  for (std::size_t k = 0; k < n; ++k) loop_row(*s.b1[k], *s.b2[k], s.poses[k], o, k, want);
  Out got(n, true);
  got.warm = warm;
  const std::size_t before = detail::batch_simd_lane_rows();
  solve_batch(s.b1, s.b2, s.poses, o, got.view());
  const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
  EXPECT_EQ(compare(want, got, n), "");
  if (std::string(GetParam()) == "none") EXPECT_EQ(lane_rows, 0u);
  else EXPECT_GT(lane_rows, n / 2);
}

TEST_P(BatchRows, RowsOfFewPairsRunInLanesAsTheLoop) {
  // A simulator's bodies of a few kinds: rows of the same two shape objects
  // recur, and the batch runs each such pair's rows in lanes (cold, or each
  // warm from its own state), the derivatives and the wrench formed from
  // the lanes' answers (with derivatives, each row's result formed in
  // lanes, but for the ellipsoid pair's). Pairs whose rows do not fill two
  // calls of the lanes, and on SSE2 the fused polytope's, run the loop
  // beside them.
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  // Under alpha_max = 1 (as Scene) the rows Separated at once are answered
  // before the pairs' rows are counted, and only the others run in lanes.
  const Step s(600, 6, {"ellipsoid", "SE_n8", "SEC_n8", "Poly_b20", "TC_b20"});
  const std::size_t n = s.poses.size();
  for (const double alpha_max : {std::numeric_limits<double>::infinity(), 1.0})
  for (const bool per_row_warm : {true, false}) {
    for (const bool deriv : {false, true}) {
      BatchOptions o;
      o.derivatives = deriv;
      o.contact.stiffness = 1e4;
      o.solver.alpha_max = alpha_max;
      const std::vector<WarmStart> warm = warm_states(s, o);
      Out want(n, deriv);
      want.warm = warm;
      for (std::size_t k = 0; k < n; ++k) loop_row(*s.b1[k], *s.b2[k], s.poses[k], o, k, want, per_row_warm);
      for (const int threads : {1, 2}) {
        o.threads = threads;
        Out got(n, deriv);
        got.warm = warm;
        const std::size_t before = detail::batch_simd_lane_rows();
        solve_batch(s.b1, s.b2, s.poses, o, got.view(per_row_warm));
        const std::size_t lane_rows = detail::batch_simd_lane_rows() - before;
        EXPECT_EQ(compare(want, got, n), "") << "per-row warm " << per_row_warm << ", derivatives " << deriv
                                             << ", threads " << threads << ", alpha_max " << alpha_max;
        // With one thread, every row ran in lanes but the pairs of fewer
        // rows than two calls take, a pair's last rows short of the lanes,
        // the rows left cold (a seventh) and the declined; SSE2's lanes
        // leave the fused polytope's pairs too (batch_simd_covers).
        // Warm rows with derivatives of the ellipsoid pair run the loop
        // (batch.cpp says why).
        if (std::string(GetParam()) != "none" && threads == 1 && std::isinf(alpha_max))
          EXPECT_GT(lane_rows, n / 3) << "per-row warm " << per_row_warm << ", derivatives " << deriv;
        if (std::string(GetParam()) == "none") EXPECT_EQ(lane_rows, 0u);
      }
      // Under alpha_max = 1 rows are answered Separated at once (each pair
      // has 40 rows, so every pair's rows are screened).
      if (!std::isinf(alpha_max))
        EXPECT_GT(std::count(want.status.begin(), want.status.end(), static_cast<std::int32_t>(SolveStatus::Separated)),
                  static_cast<std::ptrdiff_t>(n / 4));
    }
  }
}

/// Whether row k of n holds the same values in every output of a and b
/// (the warm state too).
bool same_row(const Out& a, const Out& b, std::size_t k, std::size_t n) {
  auto row = [k, n](const std::vector<double>& x, const std::vector<double>& y) {
    const std::size_t per = x.size() / n;
    return same(x.data() + per * k, y.data() + per * k, per);
  };
  return row(a.alpha, b.alpha) && row(a.x, b.x) && row(a.dalpha, b.dalpha) && row(a.gap, b.gap) &&
         row(a.normal, b.normal) && row(a.f_n, b.f_n) && row(a.F1, b.F1) && row(a.F2, b.F2) && row(a.df_n, b.df_n) &&
         row(a.dF1, b.dF1) && row(a.dF2, b.dF2) && row(a.dgap, b.dgap) && row(a.dnormal, b.dnormal) &&
         row(a.dp1, b.dp1) && row(a.dp2, b.dp2) && a.status[k] == b.status[k] && a.iterations[k] == b.iterations[k] &&
         same_warm(a.warm[k], b.warm[k]);
}

TEST_P(BatchRows, OnePairsRowsUnderAlphaMaxAreTheLoops) {
  // Rows of one pair given once (a span of one shape each), under
  // alpha_max = 1 with every derivative, warm per row and cold: the lanes'
  // path screens the rows Separated at once itself, a block at a time,
  // and writes each after its block's first as a copy of that row's
  // outputs with its own bound.
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  const Step s(600, 8, {"SEC_n8"});
  const std::size_t n = s.poses.size();
  const Shape* a = s.b1[0];
  const Shape* b = s.b2[0];
  std::size_t separated = 0;
  for (const bool per_row_warm : {true, false})
    for (const int threads : {1, 3}) {
      BatchOptions o;
      o.derivatives = true;
      o.contact.stiffness = 1e4;
      o.solver.alpha_max = 1.0;
      o.threads = threads;
      const std::vector<WarmStart> warm = warm_states(s, o);
      Out want(n, true);
      want.warm = warm;
      for (std::size_t k = 0; k < n; ++k) loop_row(*a, *b, s.poses[k], o, k, want, per_row_warm);
      Out got(n, true);
      got.warm = warm;
      solve_batch(Span<const Shape* const>(&a, 1), Span<const Shape* const>(&b, 1), s.poses, o, got.view(per_row_warm));
      EXPECT_EQ(compare(want, got, n), "") << "per-row warm " << per_row_warm << ", threads " << threads;
      separated = static_cast<std::size_t>(
          std::count(want.status.begin(), want.status.end(), static_cast<std::int32_t>(SolveStatus::Separated)));
    }
  EXPECT_GT(separated, n / 4);  // the rows exercise the screen
}

TEST_P(BatchRows, TheLanesScreenOfRowsSeparatedAtOnceIsTheLoops) {
  // Under a finite alpha_max the lanes screen the rows of the pairs they
  // take, W rows of one pair at a time (separated_rows_lanes), and leave
  // to the scalar screen the rows they cannot decide. Rows of six pairs of
  // every family, interleaved, from deep penetration to far apart; rows
  // the lanes must leave (a pose just inside check_pose's tolerance, one
  // just outside it, a reflection, a NaN, r = 0, a scale far from the
  // pair's); alpha_max equal to one row's bound (the test is strict).
  // Every row against the loop, by the rows of many pairs and by one
  // pair's rows given once.
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  const std::vector<test::Named> cat = test::catalogue();
  auto shape = [&](const std::string& name) {
    for (const test::Named& x : cat)
      if (x.name == name) return &x.shape;
    throw std::logic_error("no catalogue shape " + name);
  };
  const std::vector<std::pair<std::string, std::string>> kinds = {{"sphere", "Poly_b20"}, {"SE_n8", "SEC_n1"},
                                                                  {"Cone_b15", "Box_b10"}, {"TC_b20", "ellipsoid"},
                                                                  {"SEC_n8", "sphere"},    {"Poly_b20", "SE_n8"}};
  const std::size_t n = 40 * kinds.size();
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> far(0.2, 3.0);
  std::vector<const Shape*> b1, b2;
  std::vector<Pose> poses;
  for (std::size_t k = 0; k < n; ++k) {
    b1.push_back(shape(kinds[k % kinds.size()].first));
    b2.push_back(shape(kinds[k % kinds.size()].second));
    const double reach = radii(*b1.back()).outer + radii(*b2.back()).outer;
    poses.push_back(Pose{test::random_rotation(rng), far(rng) * reach * test::random_unit(rng)});
  }
  // R scaled by 1 + e: |R^T R - I|_F = sqrt(3) (2 e + e^2).
  auto scaled = [](Pose X, double frobenius) {
    X.R *= 1.0 + frobenius / (2.0 * std::sqrt(3.0));
    return X;
  };
  for (const std::size_t k : {6, 20, 27})  // apart, bound >= 4: the lanes would answer them at once
    poses[k].p = 4.0 * (radii(*b1[k]).outer + radii(*b2[k]).outer) * poses[k].p.normalized();
  poses[6] = scaled(poses[6], 0.9995 * kPoseTolerance);  // valid, inside the lanes' margin
  poses[20] = scaled(poses[20], 1.01 * kPoseTolerance);  // not valid
  poses[27].R = -poses[27].R;
  poses[34].p[1] = std::nan("");
  poses[41].p.setZero();
  poses[48].p *= 1e7;
  SolverOptions so;
  so.alpha_max = 1.0;
  double alpha_max = 0.0;  // a row's bound above 1
  for (std::size_t k = 60; k < n && alpha_max == 0.0; ++k) {
    double lower = 0.0;
    if (detail::separated_bound(*b1[k], *b2[k], poses[k], so, lower) && lower < 2.0) alpha_max = lower;
  }
  ASSERT_GT(alpha_max, 1.0);
  for (const bool per_row_warm : {true, false}) {
    BatchOptions o;
    o.derivatives = true;
    o.contact.stiffness = 1e4;
    o.solver.alpha_max = alpha_max;
    o.threads = 1;
    Step s(0, 1);
    s.b1 = b1, s.b2 = b2, s.poses0 = poses, s.poses = poses;
    const std::vector<WarmStart> warm = warm_states(s, o);
    Out want(n, true);
    want.warm = warm;
    for (std::size_t k = 0; k < n; ++k) loop_row(*b1[k], *b2[k], poses[k], o, k, want, per_row_warm);
    Out got(n, true);
    got.warm = warm;
    const std::size_t before = detail::batch_simd_screened_rows();
    solve_batch(b1, b2, poses, o, got.view(per_row_warm));
    const std::size_t screened = detail::batch_simd_screened_rows() - before;
    EXPECT_EQ(compare(want, got, n), "") << "rows of many pairs, per-row warm " << per_row_warm;
    if (std::string(GetParam()) != "none") EXPECT_GT(screened, n / 3) << "per-row warm " << per_row_warm;  // SSE2: no polytope pairs
    else EXPECT_EQ(screened, 0u);
    // One pair's rows, given once: the lanes' path screens them itself.
    std::vector<Pose> one;
    for (std::size_t k = 2; k < n; k += kinds.size()) one.push_back(poses[k]);
    const Shape* a = b1[2];
    const Shape* b = b2[2];
    const std::size_t m = one.size();
    Step t(0, 1);
    t.b1.assign(m, a), t.b2.assign(m, b), t.poses0 = one, t.poses = one;
    const std::vector<WarmStart> warm1 = warm_states(t, o);
    Out want1(m, true), got1(m, true);
    want1.warm = warm1, got1.warm = warm1;
    for (std::size_t k = 0; k < m; ++k) loop_row(*a, *b, one[k], o, k, want1, per_row_warm);
    solve_batch(Span<const Shape* const>(&a, 1), Span<const Shape* const>(&b, 1), one, o, got1.view(per_row_warm));
    EXPECT_EQ(compare(want1, got1, m), "") << "one pair's rows, per-row warm " << per_row_warm;
    // The rows exercise the screen: both answers, and the rows left.
    const auto count = [&](SolveStatus st) { return std::count(want.status.begin(), want.status.end(), static_cast<std::int32_t>(st)); };
    EXPECT_GT(count(SolveStatus::Separated), static_cast<std::ptrdiff_t>(n / 4));
    EXPECT_GT(count(SolveStatus::Converged), static_cast<std::ptrdiff_t>(n / 8));
    EXPECT_EQ(want.status[20], static_cast<std::int32_t>(SolveStatus::InvalidInput));
    EXPECT_EQ(want.status[27], static_cast<std::int32_t>(SolveStatus::InvalidInput));
    EXPECT_EQ(want.status[6], static_cast<std::int32_t>(SolveStatus::Separated));
  }
}

TEST_P(BatchRows, ColdRowsResumedInLanesKeepTheirOwnDerivatives) {
  // Cold rows that the lanes leave at an LM step wait until a call of W of
  // them resumes together, which may come in the middle of the rows of
  // another call: each row's derivatives and wrench must be its own
  // (solve_rows_newton_cold; the resumed call once overwrote the lanes'
  // derivatives of the call it interrupted). The paper's sweep of pairs
  // whose cold rows reach LM steps, with every derivative, cold and per
  // row with no warm state yet (a simulation's first step).
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  const std::vector<test::Named> P8 = test::paper_shapes();
  ASSERT_EQ(P8[1].name, "TC");
  ASSERT_EQ(P8[2].name, "SE");
  ASSERT_EQ(P8[3].name, "SEC");
  std::size_t resumed = 0;
  for (const auto& [A, B] : std::vector<std::pair<test::Named, test::Named>>{{P8[2], P8[2]}, {P8[2], P8[3]}, {P8[1], P8[2]}}) {
    const std::vector<Pose> P = examples::paper_sweep(A.shape, B.shape, 2000);
    const std::size_t n = P.size();
    const Shape* a = &A.shape;
    const Shape* b = &B.shape;
    for (const bool per_row_warm : {false, true}) {
      BatchOptions o;
      o.derivatives = true;
      o.contact.stiffness = 1e4;
      o.threads = 1;
      Out want(n, true), got(n, true);
      for (std::size_t k = 0; k < n; ++k) loop_row(*a, *b, P[k], o, k, want, per_row_warm);
      const std::size_t before = detail::batch_simd_lane_resumed_rows();
      solve_batch(Span<const Shape* const>(&a, 1), Span<const Shape* const>(&b, 1), P, o, got.view(per_row_warm));
      resumed += detail::batch_simd_lane_resumed_rows() - before;
      EXPECT_EQ(compare(want, got, n), "") << A.name << "-" << B.name << ", per-row warm " << per_row_warm;
    }
  }
  if (std::string(GetParam()) != "none") EXPECT_GT(resumed, 0u);  // the rows exercise the resumed calls
}

/// solve_batch of s under o, on one thread, cancelled by its poll at the
/// at-th call for each of `ats`: every row must hold either the loop's
/// whole answer or what it held before the call. Returns how many of the
/// calls left some rows as they were.
std::size_t cancelled_calls(const Step& s, BatchOptions o, const std::vector<int>& ats) {
  const std::size_t n = s.poses.size();
  o.threads = 1;
  const bool deriv = o.derivatives;
  const std::vector<WarmStart> warm = warm_states(s, o);
  Out want(n, deriv);
  want.warm = warm;
  for (std::size_t k = 0; k < n; ++k) loop_row(*s.b1[k], *s.b2[k], s.poses[k], o, k, want);
  Out before(n, deriv);  // what the outputs hold before the call
  for (std::vector<double>* v : {&before.alpha, &before.x, &before.dalpha, &before.gap, &before.normal, &before.f_n, &before.F1,
                                 &before.F2, &before.df_n, &before.dF1, &before.dF2, &before.dgap, &before.dnormal,
                                 &before.dp1, &before.dp2})
    std::fill(v->begin(), v->end(), -12345.0);
  std::fill(before.status.begin(), before.status.end(), -7);
  std::fill(before.iterations.begin(), before.iterations.end(), -7);
  before.warm = warm;
  struct Cancel {
    std::atomic<bool> flag{false};
    int polls = 0, at = 0;
  };
  std::size_t cut = 0;
  for (const int at : ats) {
    Cancel cancel;
    cancel.at = at;
    o.cancel = &cancel.flag;
    o.poll = [](void* d) {
      auto* c = static_cast<Cancel*>(d);
      if (++c->polls >= c->at) c->flag = true;
    };
    o.poll_data = &cancel;
    Out got = before;
    solve_batch(s.b1, s.b2, s.poses, o, got.view());
    std::size_t whole = 0, untouched = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (same_row(got, want, k, n)) ++whole;
      else if (same_row(got, before, k, n)) ++untouched;
      else ADD_FAILURE() << "cancelled at poll " << at << ": row " << k << " is neither the loop's answer nor as it was";
    }
    EXPECT_GT(whole, 0u) << "cancelled at poll " << at;
    cut += untouched > 0;
  }
  return cut;
}

TEST_P(BatchRows, ACancelLeavesEachRowWholeOrAsItWas) {
  // A cancel stops the batch between rows: every row holds either the
  // loop's whole answer or what it held before the call, never a part of
  // either, wherever the cancel lands.
  if (std::string(GetParam()) != "none" && std::string(batch_simd_isa()) != GetParam())
    GTEST_SKIP() << "this CPU has no " << GetParam() << " (lanes here: " << batch_simd_isa() << ")";
  // Rows of a few pairs under alpha_max = 1, warm with every derivative:
  // the batch screens the rows of the pairs that fill its lanes first
  // (polling every 64 rows: nine polls), then runs each such pair's other
  // rows in lanes, then the rest on the loop (polling every 64).
  BatchOptions o;
  o.derivatives = true;
  o.contact.stiffness = 1e4;
  o.solver.alpha_max = 1.0;
  EXPECT_GE(cancelled_calls(Step(600, 6, {"ellipsoid", "SE_n8", "SEC_n8", "Poly_b20", "TC_b20"}), o, {1, 5, 10, 12, 20}), 2u);
  // Cold rows of four pairs, about 350 each: a pair's rows run in lanes as
  // a batch of their own, blocks of 256 rows, polling before the second
  // block; cancelled there, its rows' outputs go back as they were.
  BatchOptions cold;
  cold.solver.alpha_max = std::numeric_limits<double>::infinity();
  EXPECT_GE(cancelled_calls(Step(1400, 7, {"SE_n8", "SEC_n8"}), cold, {1, 2, 3}), 1u);
}

INSTANTIATE_TEST_SUITE_P(Isa, BatchRows, ::testing::Values("none", "sse2", "avx2", "avx512"));

TEST(BatchRows, WarmStatesCarryFromCallToCall) {
  // The same rows twice at the same poses: the second call starts every row
  // from its own answer, so it takes no more than a step or two a row.
  const Step s(200, 4);
  BatchOptions o;
  Out out(s.poses.size(), false);
  solve_batch(s.b1, s.b2, s.poses, o, out.view());
  long cold = 0, warm = 0;
  for (std::int32_t it : out.iterations) cold += it;
  solve_batch(s.b1, s.b2, s.poses, o, out.view());
  for (std::int32_t it : out.iterations) warm += it;
  EXPECT_LT(warm * 5, cold) << "cold " << cold << ", warm " << warm;
}

TEST(BatchRows, BadArgumentsNameTheField) {
  const Step s(10, 5);
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  BatchOptions o;
  {
    Out out(10, false);
    out.warm.resize(9);
    EXPECT_NE(message([&] { solve_batch(s.b1, s.b2, s.poses, o, out.view()); }).find("output warm must hold 10"),
              std::string::npos);
  }
  {
    Out out(10, false);
    BatchOptions chained = o;
    chained.warm_start = true;
    EXPECT_NE(message([&] { solve_batch(s.b1, s.b2, s.poses, chained, out.view()); }).find("warm_start"),
              std::string::npos);
  }
  {
    Out out(10, true);  // wrench derivatives without BatchOptions::derivatives
    out.dalpha.clear();
    EXPECT_NE(message([&] { solve_batch(s.b1, s.b2, s.poses, o, out.view()); }).find("need BatchOptions::derivatives"),
              std::string::npos);
  }
  {
    Out out(10, false);
    BatchOptions bad = o;
    bad.contact.exponent = 0.5;
    EXPECT_NE(message([&] { solve_batch(s.b1, s.b2, s.poses, bad, out.view()); }).find("exponent"), std::string::npos);
    out.F1.resize(59);
    EXPECT_NE(message([&] { solve_batch(s.b1, s.b2, s.poses, o, out.view()); }).find("output F1_1 must hold 60"),
              std::string::npos);
  }
}

}  // namespace
