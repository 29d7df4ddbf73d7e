// Paper Table 2 layout: per pair (Poly-Poly, Poly-Ellip, Ellip-Ellip), the
// time per query of iDCOL (cold and warm), FCL collide and distance, libccd
// GJK and MPR booleans, Bullet's two GJK/EPA signed distances (where Bullet
// was found), and the oracles, all on the same pose trajectory. Bullet's
// other ways of taking an ellipsoid (bullet_adapter.hpp) are timed too,
// judged against their documented accuracy rather than the exact alpha*.
//
// Every method is checked against the exact oracle on every pose before it is
// timed; a mismatch ends that benchmark with SkipWithError.
//
// Poses: a seeded smooth trajectory (small SE(3) steps) whose translation is
// rescaled so the exact-geometry alpha* follows 1.05 + 0.35 sin(t), i.e.
// spans [0.7, 1.4]: half the poses penetrate, half are apart. Warm iDCOL
// follows the trajectory in order, as a simulation would.
//
// Run: taskset -c 0 build/baselines/idcol_bench_baselines --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "../../core/bench/bench_note.hpp"

#include "idcol/solver.hpp"
#include "idcol_baselines/baselines.hpp"
#include "idcol_baselines/ccd_adapter.hpp"
#include "idcol_baselines/fcl_adapter.hpp"
#ifdef IDCOL_BENCH_WITH_BULLET
#include "idcol_baselines/bullet_adapter.hpp"
#endif
#include "test_util.hpp"

namespace {

using namespace idcol;
using namespace idcol::baselines;

constexpr int kPoses = 512;
constexpr double kBand = 1e-6;  // booleans are not judged within |alpha* - 1| <= kBand

struct Scene {
  std::string name;
  Shape s1, s2;
  std::unique_ptr<BaselinePair> pair;  // the oracle
  std::unique_ptr<FclPair> fcl;         // the adapters, called directly
  std::unique_ptr<CcdPair> ccd;
#ifdef IDCOL_BENCH_WITH_BULLET
  std::unique_ptr<BulletPair> bullet;
  std::unique_ptr<BulletPair> bullet_scaled_sphere, bullet_hull1000;  // the other ellipsoid models
#endif
  std::vector<Pose> poses;
  std::vector<double> alpha_exact;
};

Scene make_scene(const std::string& name, Shape s1, Shape s2, uint64_t seed) {
  Scene sc{name, s1, s2};
  sc.pair = std::make_unique<BaselinePair>(s1, s2);
  sc.fcl = std::make_unique<FclPair>(sc.pair->exact1(), sc.pair->exact2());
  sc.ccd = std::make_unique<CcdPair>(sc.pair->exact1(), sc.pair->exact2());
#ifdef IDCOL_BENCH_WITH_BULLET
  sc.bullet = std::make_unique<BulletPair>(sc.pair->exact1(), sc.pair->exact2());
  sc.bullet_scaled_sphere =
      std::make_unique<BulletPair>(sc.pair->exact1(), sc.pair->exact2(), BulletOptions{BulletEllipsoid::ScaledSphere});
  sc.bullet_hull1000 = std::make_unique<BulletPair>(sc.pair->exact1(), sc.pair->exact2(),
                                                    BulletOptions{BulletEllipsoid::SurfaceHull, 1000});
#endif
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Pose X = test::random_pose(rng, 1.0, 2.0);
  for (int k = 0; k < kPoses; ++k) {
    X = X * test::se3_exp(0.03 * Vec3(n(rng), n(rng), n(rng)), 0.03 * Vec3(n(rng), n(rng), n(rng)));
    const double target = 1.05 + 0.35 * std::sin(2.0 * M_PI * 3.0 * k / kPoses);
    const OracleAnswer o = sc.pair->oracle(X);
    X.p *= target / o.alpha;
    const OracleAnswer o2 = sc.pair->oracle(X);
    sc.poses.push_back(X);
    sc.alpha_exact.push_back(o2.alpha);
  }
  return sc;
}

std::vector<Scene>& scenes() {
  static std::vector<Scene> s = [] {
    std::vector<Scene> v;
    const Shape poly = test::paper_poly(20.0), ellip = Superellipsoid(0.5, 1.0, 1.5, 1.0);
    v.push_back(make_scene("Poly-Poly", poly, poly, 1));
    v.push_back(make_scene("Poly-Ellip", poly, ellip, 2));
    v.push_back(make_scene("Ellip-Ellip", ellip, ellip, 3));
    return v;
  }();
  return s;
}

/// A method: a check over every pose (empty string = pass) and a timed call.
struct Method {
  std::string name;
  std::function<std::string(const Scene&)> check;
  std::function<void(const Scene&, int k, benchmark::State&)> call;
  bool needs_ellipsoid = false;  // not run on Poly-Poly (a way of modelling the ellipsoid)
};

/// The boolean `f` against alpha* < 1 on every pose farther than `band`
/// (relative) from contact.
std::string judge_boolean(const Scene& sc, const std::function<bool(const Pose&)>& f, double band = kBand) {
  for (int k = 0; k < kPoses; ++k) {
    const double a = sc.alpha_exact[k];
    if (std::abs(a - 1.0) <= band) continue;
    if (f(sc.poses[k]) != (a < 1.0)) return "boolean wrong at pose " + std::to_string(k) + " (alpha* = " + std::to_string(a) + ")";
  }
  return "";
}

std::string judge_idcol(const Scene& sc, bool warm) {
  ContactPair cp(sc.s1, sc.s2);
  for (int k = 0; k < kPoses; ++k) {
    const SolveResult s = warm ? cp.solve(sc.poses[k]) : cp.solve_cold(sc.poses[k]);
    if (!s.converged()) return std::string("iDCOL ") + to_string(s.status) + " at pose " + std::to_string(k);
    const auto br = sc.pair->smoothing_bracket(sc.alpha_exact[k]);
    const double slack = 1e-9 * br[0];
    if (s.alpha < br[0] - slack || s.alpha > br[1] + slack)
      return "iDCOL alpha outside the smoothing bracket at pose " + std::to_string(k);
  }
  return "";
}

std::vector<Method> methods() {
  std::vector<Method> m;
  m.push_back({"idcol_cold", [](const Scene& sc) { return judge_idcol(sc, false); },
               [](const Scene& sc, int k, benchmark::State&) {
                 benchmark::DoNotOptimize(solve(sc.s1, sc.s2, sc.poses[k]));
               }});
  m.push_back({"idcol_warm", [](const Scene& sc) { return judge_idcol(sc, true); }, nullptr});  // timed specially
  m.push_back({"fcl_collide",
               [](const Scene& sc) { return judge_boolean(sc, [&](const Pose& X) { return sc.fcl->intersects(X); }); },
               [](const Scene& sc, int k, benchmark::State&) {
                 benchmark::DoNotOptimize(sc.fcl->intersects(sc.poses[k]));
               }});
  // The query "is alpha* <= 1?" with the certified early exit
  // (SolverOptions::alpha_max = 1) against FCL's collide with its contact,
  // which answers the same question. A Separated answer must have alpha* > 1
  // and a bound at most alpha*; every other pose must solve as without it.
  m.push_back({"idcol_alpha_max1",
               [](const Scene& sc) {
                 SolverOptions o;
                 o.alpha_max = 1.0;
                 for (int k = 0; k < kPoses; ++k) {
                   const SolveResult s = solve(sc.s1, sc.s2, sc.poses[k], o);
                   if (s.status == SolveStatus::Separated) {
                     if (!(sc.alpha_exact[k] > 1.0 && s.alpha <= sc.alpha_exact[k] * (1.0 + 1e-12)))
                       return "Separated with alpha* = " + std::to_string(sc.alpha_exact[k]) + " at pose " + std::to_string(k);
                   } else if (!s.converged()) {
                     return std::string("iDCOL ") + to_string(s.status) + " at pose " + std::to_string(k);
                   }
                 }
                 return std::string();
               },
               nullptr});  // timed specially (counts its early exits)
  m.push_back({"fcl_collide_contact",
               [](const Scene& sc) { return judge_boolean(sc, [&](const Pose& X) { return sc.fcl->collide(X, true).intersect; }); },
               [](const Scene& sc, int k, benchmark::State&) {
                 benchmark::DoNotOptimize(sc.fcl->collide(sc.poses[k], true));
               }});
  m.push_back({"fcl_distance",
               [](const Scene& sc) {
                 return judge_boolean(sc, [&](const Pose& X) {
                   const BaselineAnswer a = sc.fcl->distance(X);
                   return a.threw ? !(a.intersect) : a.intersect;  // a throw counts as wrong
                 });
               },
               [](const Scene& sc, int k, benchmark::State&) {
                 benchmark::DoNotOptimize(sc.fcl->distance(sc.poses[k]));
               }});
  m.push_back({"ccd_gjk",
               [](const Scene& sc) { return judge_boolean(sc, [&](const Pose& X) { return sc.ccd->gjk_intersect(X); }); },
               [](const Scene& sc, int k, benchmark::State&) {
                 benchmark::DoNotOptimize(sc.ccd->gjk_intersect(sc.poses[k]));
               }});
  m.push_back({"ccd_mpr",
               [](const Scene& sc) { return judge_boolean(sc, [&](const Pose& X) { return sc.ccd->mpr_intersect(X); }); },
               [](const Scene& sc, int k, benchmark::State&) {
                 benchmark::DoNotOptimize(sc.ccd->mpr_intersect(sc.poses[k]));
               }});
#ifdef IDCOL_BENCH_WITH_BULLET
  // A failed Bullet answer counts as wrong (it has no boolean).
  const auto bullet_method = [](const char* name, std::unique_ptr<BulletPair> Scene::*which,
                                BaselineAnswer (BulletPair::*query)(const Pose&) const, double band) {
    return Method{name,
                  [=](const Scene& sc) {
                    return judge_boolean(
                        sc, [&](const Pose& X) {
                          const BaselineAnswer a = ((*(sc.*which)).*query)(X);
                          return a.failed ? !(a.intersect) : a.intersect;
                        },
                        band);
                  },
                  [=](const Scene& sc, int k, benchmark::State&) {
                    benchmark::DoNotOptimize(((*(sc.*which)).*query)(sc.poses[k]));
                  },
                  which != &Scene::bullet};
  };
  m.push_back(bullet_method("bullet_gjk_pair", &Scene::bullet, &BulletPair::pair_detector, kBand));
  m.push_back(bullet_method("bullet_gjk_epa2", &Scene::bullet, &BulletPair::gjk_epa2, kBand));
  // Judged outside their accuracy bands (baselines/README.md: worst alpha*
  // error 0.15 for the scaled sphere, 2.5e-3 for the hull of 1000 points).
  m.push_back(bullet_method("bullet_gjk_epa2_scaled_sphere", &Scene::bullet_scaled_sphere, &BulletPair::gjk_epa2, 0.3));
  m.push_back(bullet_method("bullet_gjk_epa2_hull1000", &Scene::bullet_hull1000, &BulletPair::gjk_epa2, 5e-3));
#endif
  m.push_back({"oracle",
               [](const Scene& sc) {
                 for (int k = 0; k < kPoses; ++k) {
                   const OracleAnswer o = sc.pair->oracle(sc.poses[k]);
                   if (!o.ok || std::abs(o.alpha - sc.alpha_exact[k]) > 1e-12 * o.alpha)
                     return "oracle not reproducible at pose " + std::to_string(k) + ": " + o.error;
                 }
                 return std::string();
               },
               [](const Scene& sc, int k, benchmark::State&) { benchmark::DoNotOptimize(sc.pair->oracle(sc.poses[k])); }});
  return m;
}

void run(benchmark::State& state, const Scene& sc, const Method& m) {
  const std::string err = m.check(sc);
  if (!err.empty()) {
    state.SkipWithError(err.c_str());
    return;
  }
  if (m.name == "idcol_warm") {
    ContactPair cp(sc.s1, sc.s2);
    int k = 0;
    for (auto _ : state) {
      benchmark::DoNotOptimize(cp.solve(sc.poses[k]));
      if (++k == kPoses) k = 0;
    }
  } else if (m.name == "idcol_alpha_max1") {
    SolverOptions o;
    o.alpha_max = 1.0;
    int separated = 0;
    for (int k = 0; k < kPoses; ++k) separated += solve(sc.s1, sc.s2, sc.poses[k], o).status == SolveStatus::Separated;
    state.counters["separated_fraction"] = static_cast<double>(separated) / kPoses;
    int k = 0;
    for (auto _ : state) {
      benchmark::DoNotOptimize(solve(sc.s1, sc.s2, sc.poses[k], o));
      if (++k == kPoses) k = 0;
    }
  } else {
    int k = 0;
    for (auto _ : state) {
      m.call(sc, k, state);
      if (++k == kPoses) k = 0;
    }
  }
  state.counters["poses"] = kPoses;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  static const std::vector<Method> ms = methods();
  for (const Scene& sc : scenes())
    for (const Method& m : ms) {
      if (m.needs_ellipsoid && sc.pair->kind() == PairKind::PolyPoly) continue;
      benchmark::RegisterBenchmark((sc.name + "/" + m.name).c_str(),
                                   [&sc, &m](benchmark::State& st) { run(st, sc, m); })
          ->Unit(benchmark::kMicrosecond);
    }
  benchmark::AddCustomContext("libccd_precision", ccd_precision());
#ifdef IDCOL_BENCH_WITH_BULLET
  benchmark::AddCustomContext("bullet_precision", bullet_precision());
#endif
  benchmark::AddCustomContext("poses_per_pair", std::to_string(kPoses));
  idcol::bench::add_library_note();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
