// A simulator's narrow phase through solve_batch, against the loop of
// solve() and the derivative functions it replaces (the same call with
// BatchOptions::simd off), on one thread. Rows are the candidate pairs of a
// scene, each with its own pair of bodies:
//
//  - box1000: 1,000 bodies of the paper's ten kinds on a lattice
//    (box_of_bodies), the broad phase's candidate pairs; bodies of one kind
//    share one shape object (as Scene does), so rows of two kinds are rows
//    of one pair, which the batch runs in SIMD lanes;
//  - box100: the same with 100 bodies (about five rows a pair of kinds);
//  - ten: ten bodies of the ten kinds, all 45 pairs: 45 different pairs,
//    each one row;
//  - ten64: 64 independent ten-body scenes (seeds 1..64) stepped as one
//    batch, as a simulator of parallel environments would: the same 45
//    pairs, each now 64 rows of one pair, which fill the lanes;
//  - ten_live, ten_separated, ten64_live, ten64_separated (warm_deriv
//    only): ten's and ten64's rows split into those that solve() under
//    alpha_max = 1 answers Separated at once (a certified bound, no
//    iteration) and the others, which it solves: where the step's time
//    goes.
//
// Modes (warm and warm_wrench are warm_deriv's rows with fewer outputs:
// no derivatives, and warm without the wrench or alpha_max):
//  - cold: alpha*, x*, status and iterations, alpha_max infinite;
//  - warm_deriv: what Scene::update asks for a Jacobian: each row
//    warm-started from its own state of the step before (the poses moved
//    back by dt = 0.01 along the bodies' twists), alpha_max = 1, d alpha/d xi,
//    gap, normal, the wrench and its derivatives;
//  - first_deriv: warm_deriv on the first step, where no row has a warm
//    state yet (each row solved cold, and its state left for the next).
//
// Before timing, the batch's outputs are checked against the loop's, bit
// for bit. ns_per_row is wall time per row; lane_share the rows the lanes
// answered.
//
//   taskset -c 0 build/core/idcol_bench_sim_batch --benchmark_repetitions=5 \
//       --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "bench_note.hpp"

#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "../src/batch/batch_simd.hpp"
#include "idcol/batch.hpp"
#include "idcol/broad_phase.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/multibody_scenes.hpp"
#include "idcol/solver.hpp"

using namespace idcol;

namespace {

/// The rows of one scene: shapes shared per kind, the pose of each row now
/// and one step before.
struct Rows {
  std::deque<Shape> kinds;  // the rows point into it: a deque keeps them valid as kinds are added
  std::vector<const Shape*> b1, b2;
  std::vector<Pose> X, X_before;
};

/// Appends the rows of scene b to r (its kinds into r.kinds where new).
void add_rows(Rows& r, std::map<std::string, std::size_t>& kind_of, const BodyScene& b, bool all_pairs) {
  std::vector<std::size_t> kind(b.shapes.size());
  for (std::size_t i = 0; i < b.shapes.size(); ++i) {
    auto it = kind_of.find(b.names[i]);
    if (it == kind_of.end()) {
      it = kind_of.emplace(b.names[i], r.kinds.size()).first;
      r.kinds.push_back(b.shapes[i]);
    }
    kind[i] = it->second;
  }
  const double dt = 0.01;
  std::vector<Pose> before(b.X_W.size());
  for (std::size_t i = 0; i < b.X_W.size(); ++i) before[i] = b.X_W[i] * se3_exp(-dt * b.eta[i]);
  std::vector<BodyPair> pairs;
  if (all_pairs) {
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(b.X_W.size()); ++i)
      for (std::int32_t j = i + 1; j < static_cast<std::int32_t>(b.X_W.size()); ++j) pairs.push_back({i, j});
  } else {
    std::vector<BoundingSphere> s(b.X_W.size());
    for (std::size_t i = 0; i < s.size(); ++i) s[i] = {b.X_W[i].p, radii(b.shapes[i]).outer};
    BroadPhase broad;
    pairs = broad.find(s);
  }
  for (const BodyPair& p : pairs) {
    r.b1.push_back(&r.kinds[kind[p.i]]);
    r.b2.push_back(&r.kinds[kind[p.j]]);
    r.X.push_back(b.X_W[p.i].inverse() * b.X_W[p.j]);
    r.X_before.push_back(before[p.i].inverse() * before[p.j]);
  }
}

/// The rows of the scenes in `bs`, one after another; shapes are shared
/// per kind across the scenes (box_of_bodies' kinds are the same in each).
Rows make_rows(const std::vector<BodyScene>& bs, bool all_pairs) {
  Rows r;
  std::map<std::string, std::size_t> kind_of;
  for (const BodyScene& b : bs) add_rows(r, kind_of, b, all_pairs);
  return r;
}

enum SceneId { kBox1000, kBox100, kTen, kTen64, kTenLive, kTenSeparated, kTen64Live, kTen64Separated };
const char* const kSceneNames[] = {"box1000",  "box100",         "ten",        "ten64",
                                   "ten_live", "ten_separated", "ten64_live", "ten64_separated"};

/// The rows of r that solve() under alpha_max = 1 (as Scene asks) answers
/// Separated at once (no iteration: its certified bound exceeds 1), or the
/// others: where a warm step's time goes, the screened rows or the solved.
Rows split_rows(const Rows& r, bool separated) {
  Rows s;  // its rows point into r's kinds
  SolverOptions so;
  so.alpha_max = 1.0;
  for (std::size_t k = 0; k < r.X.size(); ++k) {
    const SolveResult res = solve(*r.b1[k], *r.b2[k], r.X[k], so);
    if ((res.status == SolveStatus::Separated && res.iterations == 0) != separated) continue;
    s.b1.push_back(r.b1[k]);
    s.b2.push_back(r.b2[k]);
    s.X.push_back(r.X[k]);
    s.X_before.push_back(r.X_before[k]);
  }
  return s;
}

const Rows& scene_rows(SceneId id) {
  static const Rows box = make_rows({box_of_bodies(1000, 1)}, false);
  static const Rows box100 = make_rows({box_of_bodies(100, 1)}, false);
  static const Rows tenb = make_rows({box_of_bodies(10, 1)}, true);
  static const Rows ten64 = [] {
    std::vector<BodyScene> envs;
    for (unsigned seed = 1; seed <= 64; ++seed) envs.push_back(box_of_bodies(10, seed));
    return make_rows(envs, true);
  }();
  if (id == kTenLive || id == kTenSeparated) {
    static const Rows live = split_rows(tenb, false), separated = split_rows(tenb, true);
    return id == kTenLive ? live : separated;
  }
  if (id == kTen64Live || id == kTen64Separated) {
    static const Rows live = split_rows(ten64, false), separated = split_rows(ten64, true);
    return id == kTen64Live ? live : separated;
  }
  return id == kBox1000 ? box : id == kBox100 ? box100 : id == kTen ? tenb : ten64;
}

/// Every output a mode fills.
enum Mode { kCold, kWarm, kWarmWrench, kWarmDeriv, kFirstDeriv };
const char* const kModeNames[] = {"cold", "warm", "warm_wrench", "warm_deriv", "first_deriv"};
/// The modes that ask for every derivative.
bool derivs(Mode m) { return m == kWarmDeriv || m == kFirstDeriv; }

struct Out {
  std::vector<double> alpha, x, dalpha, gap, normal, f_n, F1, F2, df_n, dF1, dF2;
  std::vector<std::int32_t> status, iterations;
  std::vector<WarmStart> warm;
  Out(std::size_t n, Mode m)
      : alpha(n), x(3 * n), dalpha(derivs(m) ? 6 * n : 0), gap(m >= kWarmWrench ? n : 0),
        normal(m >= kWarmWrench ? 3 * n : 0), f_n(m >= kWarmWrench ? n : 0), F1(m >= kWarmWrench ? 6 * n : 0),
        F2(m >= kWarmWrench ? 6 * n : 0), df_n(derivs(m) ? 6 * n : 0), dF1(derivs(m) ? 36 * n : 0),
        dF2(derivs(m) ? 36 * n : 0), status(n), iterations(n), warm(m != kCold ? n : 0) {}
  BatchOutput view() {
    BatchOutput o;
    o.alpha = alpha, o.x_1 = x, o.status = status, o.iterations = iterations, o.dalpha_dxi = dalpha;
    o.gap = gap, o.normal_1 = normal, o.warm = warm;
    o.f_n = f_n, o.F1_1 = F1, o.F2_2 = F2, o.df_n_dxi = df_n, o.dF1_dxi = dF1, o.dF2_dxi = dF2;
    return o;
  }
  bool operator==(const Out& o) const {
    auto same = [](const std::vector<double>& a, const std::vector<double>& b) {
      return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
    };
    return same(alpha, o.alpha) && same(x, o.x) && same(dalpha, o.dalpha) && same(gap, o.gap) &&
           same(normal, o.normal) && same(f_n, o.f_n) && same(F1, o.F1) && same(F2, o.F2) && same(df_n, o.df_n) &&
           same(dF1, o.dF1) && same(dF2, o.dF2) && status == o.status && iterations == o.iterations;
  }
};

BatchOptions options(Mode m, bool simd) {
  BatchOptions o;
  o.simd = simd;
  o.threads = 1;
  o.derivatives = derivs(m);
  o.contact.stiffness = 1e4;
  if (m >= kWarmWrench) o.solver.alpha_max = 1.0;  // as Scene
  return o;
}

/// The warm states that the step before leaves.
std::vector<WarmStart> states_before(const Rows& r) {
  Out o(r.X.size(), kWarm);
  solve_batch(r.b1, r.b2, r.X_before, options(kWarm, true), o.view());
  return o.warm;
}

void run(benchmark::State& state, SceneId ten, Mode m, bool simd) {
  const Rows& r = scene_rows(ten);
  const std::size_t n = r.X.size();
  const bool deriv = m != kCold;  // warm states
  const std::vector<WarmStart> warm0 =
      m == kFirstDeriv ? std::vector<WarmStart>(n) : deriv ? states_before(r) : std::vector<WarmStart>{};
  auto once = [&](bool lanes, Out& o) {
    if (deriv) o.warm = warm0;
    solve_batch(r.b1, r.b2, r.X, options(m, lanes), o.view());
  };
  Out want(n, m), got(n, m);
  once(false, want);
  once(true, got);
  if (!(want == got)) {
    state.SkipWithError("the batch differs from the loop");
    return;
  }
  double ns = 0.0;
  std::size_t lane_rows = 0;
  for (auto _ : state) {
    if (deriv) got.warm = warm0;
    const std::size_t before = detail::batch_simd_lane_rows();
    const auto t0 = std::chrono::steady_clock::now();
    solve_batch(r.b1, r.b2, r.X, options(m, simd), got.view());
    ns += std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    lane_rows += detail::batch_simd_lane_rows() - before;
    benchmark::DoNotOptimize(got.alpha.data());
    benchmark::ClobberMemory();
  }
  const double rows = static_cast<double>(state.iterations()) * static_cast<double>(n);
  state.counters["rows"] = static_cast<double>(n);
  state.counters["ns_per_row"] = ns / rows;
  state.counters["lane_share"] = static_cast<double>(lane_rows) / rows;
  state.SetLabel(batch_simd_isa());
}

const int registered = [] {
  for (const SceneId ten : {kBox1000, kBox100, kTen, kTen64, kTenLive, kTenSeparated, kTen64Live, kTen64Separated})
    for (const Mode m : {kCold, kWarm, kWarmWrench, kWarmDeriv, kFirstDeriv})
      for (const bool simd : {false, true}) {
        if (ten >= kTenLive && m != kWarmDeriv) continue;  // the split of the simulator's step only
        const std::string name = std::string(kSceneNames[ten]) + "/" + kModeNames[m] + (simd ? "/batch" : "/loop");
        benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) { run(st, ten, m, simd); })
            ->Unit(benchmark::kMicrosecond)
            ->UseRealTime()
            ->MinTime(0.3);
      }
  return 0;
}();

}  // namespace

IDCOL_BENCHMARK_MAIN()
