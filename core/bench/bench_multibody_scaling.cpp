// How the cost of a simulation step's contact detection grows with the
// number of bodies: the box scene (multibody_scenes.hpp: bodies of the
// paper's ten kinds on a jittered lattice, a bounded number of neighbours
// each) at 10, 100, 1,000 and 10,000 bodies, each body moving along its
// own constant twist; one step is Scene::update at the step's poses (broad
// phase, narrow phase as one batch, warm-started from the step before),
// with the wrench Jacobians (as an implicit integrator's Jacobian needs) and
// without them (as its right-hand side does).
//
//   build/core/idcol_bench_multibody_scaling [-o OUT.json] [--sizes 10,100,1000,10000]
//                                            [--steps S] [--reps R]
//
// Prints a table and writes OUT.json (default build/out/multibody_scaling.json)
// with every figure, the machine, compiler, flags and git revision; each
// time is the median over R repetitions of S steps. Also times the three
// broad-phase methods alone on the same poses (all pairs up to 1,000
// bodies), and the narrow phase again in the batch's SIMD lanes
// (SceneOptions::simd), side by side. scripts/plot_multibody.py --scaling draws it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "idcol/batch.hpp"
#include "idcol/broad_phase.hpp"
#include "idcol/multibody_scenes.hpp"
#include "idcol/scene.hpp"
#include "../examples/run_info.hpp"

using namespace idcol;

namespace {

struct Args {
  std::string out = "build/out/multibody_scaling.json";
  std::vector<int> sizes = {10, 100, 1000, 10000};
  int steps = 20, reps = 3;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr, "%s\nusage: idcol_bench_multibody_scaling [-o OUT.json] [--sizes N,N,...] [--steps S] [--reps R]\n",
               why.c_str());
  std::exit(2);
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage("missing value after " + k);
      return argv[++i];
    };
    auto positive = [&](const std::string& v) {
      char* end = nullptr;
      const long x = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || x < 1 || x > 1000000) usage(k + " needs integers in 1..1000000, got '" + v + "'");
      return static_cast<int>(x);
    };
    if (k == "-o") a.out = value();
    else if (k == "--steps") a.steps = positive(value());
    else if (k == "--reps") a.reps = positive(value());
    else if (k == "--sizes") {
      a.sizes.clear();
      std::stringstream ss(value());
      for (std::string item; std::getline(ss, item, ',');) a.sizes.push_back(positive(item));
    } else usage("unknown argument " + k);
  }
  return a;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The poses of step k: each body moved along its own body twist.
std::vector<Pose> poses_at(const BodyScene& sc, int k, double dt) {
  std::vector<Pose> X(sc.X_W.size());
  for (std::size_t i = 0; i < X.size(); ++i) X[i] = sc.X_W[i] * se3_exp(k * dt * sc.eta[i]);
  return X;
}

struct Size {
  int n = 0;
  double broad = 0, narrow = 0, broad_d = 0, narrow_d = 0;  // seconds per step (median), without / with derivatives
  double narrow_lanes = 0, narrow_d_lanes = 0;  // the narrow phase in the batch's SIMD lanes (SceneOptions::simd)
  double candidates = 0, active = 0, iterations = 0;       // per step
  long failed = 0;
  double sap = 0, tree = 0, all_pairs = -1;  // the broad phase alone, seconds per call
};

/// S steps after one warm-up step (which starts every pair cold), R times.
Size measure(int n, const Args& a) {
  const BodyScene sc = box_of_bodies(n, 1);
  const double dt = 0.005;
  std::vector<std::vector<Pose>> steps;
  for (int k = 0; k <= a.steps; ++k) steps.push_back(poses_at(sc, k, dt));
  Size s;
  s.n = n;
  for (const bool deriv : {false, true}) {
    std::vector<double> broad, narrow, narrow_lanes;
    // Each repetition runs the steps with the narrow phase on the loop (the
    // scene's default) and then in the batch's SIMD lanes
    // (SceneOptions::simd; the same answers, bit for bit), side by side.
    for (int r = 0; r < a.reps; ++r)
      for (const bool lanes : {false, true}) {
        SceneOptions o;
        o.simd = lanes;
        o.contact.stiffness = 1e4;
        Scene scene(o);
        for (const Shape& sh : sc.shapes) scene.add_body(sh);
        scene.update(steps[0], deriv);
        double b = 0, w = 0, cand = 0, act = 0, it = 0;
        long failed = 0;
        for (int k = 1; k <= a.steps; ++k) {
          scene.update(steps[k], deriv);
          const SceneUpdateStats& st = scene.last_stats();
          b += st.broad_seconds, w += st.narrow_seconds;
          cand += st.candidates, act += st.active, it += st.newton_iterations;
          failed += static_cast<long>(st.failed);
        }
        if (lanes) {
          narrow_lanes.push_back(w / a.steps);
          continue;
        }
        s.failed += failed;
        broad.push_back(b / a.steps);
        narrow.push_back(w / a.steps);
        s.candidates = cand / a.steps, s.active = act / a.steps, s.iterations = it / a.steps;
      }
    (deriv ? s.broad_d : s.broad) = median(broad);
    (deriv ? s.narrow_d : s.narrow) = median(narrow);
    (deriv ? s.narrow_d_lanes : s.narrow_lanes) = median(narrow_lanes);
  }
  std::vector<BoundingSphere> spheres;
  for (std::size_t i = 0; i < sc.shapes.size(); ++i) spheres.push_back({steps[0][i].p, radii(sc.shapes[i]).outer});
  auto time_method = [&](BroadPhaseMethod m) {
    BroadPhase bp(m);
    std::vector<double> t;
    for (int r = 0; r < a.reps; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < a.steps; ++k) bp.find(spheres);
      t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / a.steps);
    }
    return median(t);
  };
  s.sap = time_method(BroadPhaseMethod::SweepAndPrune);
  s.tree = time_method(BroadPhaseMethod::Tree);
  if (n <= 1000) s.all_pairs = time_method(BroadPhaseMethod::AllPairs);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  try {
    std::printf("box scene, one body per unit cell (ten kinds at half size), %d warm steps of 5 ms, median of %d\n",
                a.steps, a.reps);
    std::printf("narrow: the scene's narrow phase (the loop); lanes: the same in the batch's SIMD lanes (%s)\n",
                batch_simd_isa());
    std::printf("%7s %11s %9s %11s %11s %9s %11s %9s %11s %9s %9s %9s\n", "bodies", "candidates", "contacts", "broad us",
                "narrow us", "lanes us", "+Jacobians", "lanes us", "us/body", "SAP us", "tree us", "all us");
    std::ostringstream js;
    js << "{\"benchmark\": \"multibody_scaling\", " << examples::provenance_json(examples::command_line(argc, argv)) << ",\n\"steps\": " << a.steps
       << ", \"reps\": " << a.reps << ", \"lanes\": \"" << batch_simd_isa() << "\", \"dt\": 0.005, \"broad_phase\": \"auto\", \"all_pairs_up_to\": "
       << BroadPhase::kAllPairsUpTo << ",\n\"sizes\": [";
    for (std::size_t k = 0; k < a.sizes.size(); ++k) {
      const Size s = measure(a.sizes[k], a);
      const double per_body = (s.broad_d + s.narrow_d) / s.n;
      std::printf("%7d %11.1f %9.1f %11.1f %11.1f %9.1f %11.1f %9.1f %11.3f %9.1f %9.1f %9s\n", s.n, s.candidates, s.active,
                  1e6 * s.broad, 1e6 * s.narrow, 1e6 * s.narrow_lanes, 1e6 * s.narrow_d, 1e6 * s.narrow_d_lanes,
                  1e6 * per_body, 1e6 * s.sap, 1e6 * s.tree,
                  s.all_pairs < 0 ? "-" : std::to_string(static_cast<long>(1e6 * s.all_pairs)).c_str());
      js << (k ? ",\n  " : "\n  ") << "{\"bodies\": " << s.n << ", \"candidates_per_step\": " << s.candidates
         << ", \"contacts_per_step\": " << s.active << ", \"newton_iterations_per_step\": " << s.iterations
         << ", \"failed_rows\": " << s.failed << ", \"broad_seconds\": " << s.broad << ", \"narrow_seconds\": " << s.narrow
         << ", \"broad_seconds_with_jacobians\": " << s.broad_d << ", \"narrow_seconds_with_jacobians\": " << s.narrow_d
         << ", \"narrow_seconds_lanes\": " << s.narrow_lanes << ", \"narrow_seconds_with_jacobians_lanes\": " << s.narrow_d_lanes
         << ", \"narrow_lanes_speedup\": " << s.narrow / s.narrow_lanes
         << ", \"narrow_lanes_speedup_with_jacobians\": " << s.narrow_d / s.narrow_d_lanes
         << ", \"seconds_per_body\": " << (s.broad + s.narrow) / s.n
         << ", \"seconds_per_body_with_jacobians\": " << per_body << ", \"broad_phase_alone\": {\"sweep_and_prune\": "
         << s.sap << ", \"tree\": " << s.tree << ", \"all_pairs\": ";
      if (s.all_pairs < 0) js << "null";
      else js << s.all_pairs;
      js << "}}";
    }
    js << "]}\n";
    examples::write_whole(a.out, js.str());
    std::printf("wrote %s\n", a.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "idcol_bench_multibody_scaling: %s\n", e.what());
    return 2;
  }
}
