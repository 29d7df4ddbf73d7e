// Deterministic companion of idcol_bench for performance work: the same
// shapes and poses, but measured in instructions under callgrind instead of
// wall-clock time (the build machine is shared, so timing is noisy).
//
//   idcol_prof check [out.bin]     every pose of every pair, cold and warm:
//                                  convergence, mean iterations, restarts,
//                                  continuation use; optionally writes
//                                  alpha* of every solve to compare builds.
//   idcol_prof dump out.bin        every pose of every pair, cold and warm:
//                                  status, iterations, alpha* and x of each
//                                  solve as doubles (6 a solve), to compare
//                                  the answers of two builds
//                                  (scripts/compare_dumps.py).
//   idcol_prof steps PAIR MODE N   the N solves of `run` with a trace:
//                                  Newton, chord and LM steps, steps cut by
//                                  the line search, restarts, per solve.
//   idcol_prof run PAIR MODE N     N solves of one pair ("Poly-Poly", ...),
//                                  MODE cold (every 20000/N-th pose) or warm
//                                  (the first N consecutive poses), with
//                                  callgrind collection switched on only
//                                  around the solves; MODE walkcold or
//                                  walkwarm: N consecutive poses of a seeded
//                                  random walk (steps of 0.05 in each twist
//                                  coordinate, |r| kept within the sweep's
//                                  range), solved cold or warm:
//
//   valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file=cg.out \
//       build/core/idcol_prof run Poly-Poly cold 1000
//   callgrind_annotate cg.out | head     (total Ir / N = instructions per solve)
//
//   idcol_prof guard PAIR NCOLD NWARM NMOTIONS
//                                  every path of the speed guard
//                                  (scripts/ci_instructions.sh) in one process,
//                                  one callgrind dump per section
//                                  (CALLGRIND_DUMP_STATS_AT, named by the
//                                  section): cold, warm, batch_cold,
//                                  batch_warm (run's cold, warm, batchcold
//                                  and batchwarm poses), deriv_solve (the cold
//                                  poses solved with SolverOptions::derivatives),
//                                  deriv (alpha_gradient and
//                                  solution_sensitivity of those solves), shape
//                                  (shape_sensitivity of both bodies of those
//                                  solves), toi_translation and toi_screw
//                                  (time_of_impact on NMOTIONS seeded motions of
//                                  each kind); stdout gives the solves per query
//                                  of the last two and the batch's instruction set.
#include <valgrind/callgrind.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "idcol/batch.hpp"
#include "idcol/derivatives.hpp"
#include "idcol/shape_derivatives.hpp"
#include "idcol/solver.hpp"
#include "idcol/toi.hpp"
#include "../examples/cli_args.hpp"
#include "../examples/paper_shapes.hpp"

using namespace idcol;

namespace {

constexpr int kPoses = 20000;

using examples::NamedShape;
// The paper's Table 1 shapes (core/examples/paper_shapes.hpp).
std::vector<NamedShape> shapes() { return examples::paper_catalogue(); }

std::vector<Pose> poses_for(const Shape& a, const Shape& b) { return examples::paper_sweep(a, b, kPoses); }

/// A seeded random walk: consecutive poses close but each step in any
/// direction (warm starts without a steady motion to extrapolate).
std::vector<Pose> walk_for(const Shape& a, const Shape& b, int n) {
  const Radii ra = radii(a), rb = radii(b);
  const double rmin = 0.1 * std::min(ra.inner, rb.inner), rmax = 2.0 * std::max(ra.outer, rb.outer);
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  Pose X{q.toRotationMatrix(), 0.5 * (rmin + rmax) * Vec3(g(rng), g(rng), g(rng)).normalized()};
  std::vector<Pose> poses(n);
  for (int k = 0; k < n; ++k) {
    Vec6 xi;
    for (int j = 0; j < 6; ++j) xi[j] = 0.05 * g(rng);
    X = X * se3_exp(xi);
    const double r = X.p.norm();
    if (r < rmin || r > rmax) X.p *= 0.5 * (rmin + rmax) / r;
    poses[k] = X;
  }
  return poses;
}

int check(const char* out) {
  const auto S = shapes();
  std::vector<double> alphas;
  const SolverOptions opt;
  int bad = 0;
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j)
      for (bool warm : {false, true}) {
        const auto poses = poses_for(S[i].shape, S[j].shape);
        WarmStart ws;
        long conv = 0, its = 0, rest = 0, cont = 0, maxit = 0;
        for (const Pose& X : poses) {
          const SolveResult r = solve(S[i].shape, S[j].shape, X, opt, warm ? &ws : nullptr);
          conv += r.converged();
          its += r.iterations;
          rest += r.restarts;
          cont += r.used_continuation;
          maxit = std::max<long>(maxit, r.iterations);
          alphas.push_back(r.alpha);
        }
        bad += conv != kPoses;
        std::printf("%-5s %-6s-%-6s conv %5ld/%d  its %.3f  max %2ld  restarts %ld  continuation %ld\n", warm ? "warm" : "cold",
                    S[i].name, S[j].name, conv, kPoses, static_cast<double>(its) / kPoses, maxit, rest, cont);
      }
  if (out) {
    FILE* f = std::fopen(out, "wb");
    std::fwrite(alphas.data(), sizeof(double), alphas.size(), f);
    std::fclose(f);
  }
  return bad;
}

/// Every pose of every pair, cold and warm: (status, iterations, alpha, x)
/// as six doubles a solve, in check()'s order.
int dump(const char* out) {
  const auto S = shapes();
  const SolverOptions opt;
  std::vector<double> rows;
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j)
      for (bool warm : {false, true}) {
        const auto poses = poses_for(S[i].shape, S[j].shape);
        WarmStart ws;
        for (const Pose& X : poses) {
          const SolveResult r = solve(S[i].shape, S[j].shape, X, opt, warm ? &ws : nullptr);
          rows.insert(rows.end(), {static_cast<double>(r.status), static_cast<double>(r.iterations), r.alpha, r.x_1[0], r.x_1[1], r.x_1[2]});
        }
      }
  FILE* f = std::fopen(out, "wb");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", out);
    return 2;
  }
  std::fwrite(rows.data(), sizeof(double), rows.size(), f);
  std::fclose(f);
  return 0;
}

/// Tallies the steps of a trace.
class StepTally : public TraceSink {
 public:
  long newton = 0, cut = 0, chord = 0, lm = 0, runs = 0;
  void record(const TraceRecord& r) override {
    const std::string k = r.step;
    if (k == "newton") newton += 1, cut += r.step_length < 1.0;
    else if (k == "chord") ++chord;
    else if (k == "lm" || k == "lm-stalled") ++lm;
    if (r.iteration == 0) ++runs;
  }
};

/// run()'s cold, warm, walkcold and walkwarm solves with a trace: steps of
/// each kind per solve.
int steps(const std::string& pair, const std::string& mode, int n) {
  const auto S = shapes();
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j) {
      if (pair != std::string(S[i].name) + "-" + S[j].name) continue;
      const bool walk = mode == "walkcold" || mode == "walkwarm";
      const auto poses = walk ? walk_for(S[i].shape, S[j].shape, n + 1) : poses_for(S[i].shape, S[j].shape);
      const bool warm = mode == "warm" || mode == "walkwarm";
      const int stride = warm || walk ? 1 : kPoses / n;
      const SolverOptions opt;
      WarmStart ws;
      if (warm) solve(S[i].shape, S[j].shape, poses[0], opt, &ws);
      StepTally t;
      long restarts = 0;
      for (int k = 0; k < n; ++k) {
        const SolveResult r = solve(S[i].shape, S[j].shape, poses[warm || walk ? k + 1 : k * stride], opt, warm ? &ws : nullptr, &t);
        restarts += r.restarts;
      }
      const double d = n;
      std::printf("%s %s n=%d per solve: runs %.3f newton %.3f (cut by the line search %.3f) chord %.3f lm %.3f restarts %.3f\n",
                  pair.c_str(), mode.c_str(), n, t.runs / d, t.newton / d, t.cut / d, t.chord / d, t.lm / d, restarts / d);
      return 0;
    }
  std::fprintf(stderr, "unknown pair %s\n", pair.c_str());
  return 2;
}

/// run()'s batchcold / batchwarm rows: every (20000 / n)-th pose of the
/// sweep, or its poses 1..n, through solve_batch on one thread (its SIMD path
/// where the pair has one), with the outputs allocated beforehand.
struct BatchRun {
  std::vector<Pose> P;
  std::vector<double> alpha, x;
  std::vector<std::int32_t> status, iterations;
  BatchOptions o;

  BatchRun(const std::vector<Pose>& poses, bool warm, int n)
      : P(n), alpha(n), x(3 * n), status(n), iterations(n) {
    const int stride = warm ? 1 : kPoses / n;
    for (int k = 0; k < n; ++k) P[k] = poses[warm ? k + 1 : k * stride];
    o.warm_start = warm;
    o.warm_chain = static_cast<std::size_t>(n / 10 + 1);  // 10 chains, as 10^5 poses in paper_table1's chains of 10^4
  }
  void operator()(const Shape& a, const Shape& b) { solve_batch(a, b, P, o, {alpha, x, status, iterations, {}}); }
  double sum() const {
    double s = 0.0;
    for (double v : alpha) s += v;
    return s;
  }
};

int run(const std::string& pair, const std::string& mode, int n) {
  const auto S = shapes();
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j) {
      if (pair != std::string(S[i].name) + "-" + S[j].name) continue;
      if (mode == "batchcold" || mode == "batchwarm") {
        // The same poses as cold / warm, through solve_batch on one thread
        // (its SIMD path where the pair has one).
        BatchRun batch(poses_for(S[i].shape, S[j].shape), mode == "batchwarm", n);
        CALLGRIND_TOGGLE_COLLECT;
        batch(S[i].shape, S[j].shape);
        CALLGRIND_TOGGLE_COLLECT;
        const double sum = batch.sum();
        std::printf("%s %s n=%d simd %s (checksum %.17g)\n", pair.c_str(), mode.c_str(), n, batch_simd_isa(), sum);
        return 0;
      }
      const bool walk = mode == "walkcold" || mode == "walkwarm";
      const auto poses = walk ? walk_for(S[i].shape, S[j].shape, n + 1) : poses_for(S[i].shape, S[j].shape);
      const bool warm = mode == "warm" || mode == "walkwarm";
      const int stride = warm ? 1 : walk ? 1 : kPoses / n;
      const SolverOptions opt;
      WarmStart ws;
      if (warm) solve(S[i].shape, S[j].shape, poses[0], opt, &ws);  // the first warm solve is cold
      double sum = 0.0;
      long its = 0;
      CALLGRIND_TOGGLE_COLLECT;
      for (int k = 0; k < n; ++k) {
        const SolveResult r = solve(S[i].shape, S[j].shape, poses[warm || walk ? k + 1 : k * stride], opt, warm ? &ws : nullptr);
        sum += r.alpha;
        its += r.iterations;
      }
      CALLGRIND_TOGGLE_COLLECT;
      std::printf("%s %s n=%d its/solve %.3f (checksum %.17g)\n", pair.c_str(), mode.c_str(), n, static_cast<double>(its) / n, sum);
      return 0;
    }
  std::fprintf(stderr, "unknown pair %s\n", pair.c_str());
  return 2;
}


/// Seeded time-of-impact motions scaled to the pair (L = the sum of the
/// outer radii): body 2 from 1.2-2.2 L on one side of body 1 to as far on
/// the other, shifted sideways by up to 0.8 L (most motions hit, some pass
/// by); a screw turns by 0.3-2.5 rad about a random axis on the way.
std::vector<std::pair<Pose, Pose>> toi_motions(const Shape& a, const Shape& b, int n, bool screw) {
  const double L = radii(a).outer + radii(b).outer;
  std::mt19937_64 rng(screw ? 1002 : 1001);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto unit = [&] { return Vec3(g(rng), g(rng), g(rng)).normalized(); };
  std::vector<std::pair<Pose, Pose>> out(n);
  for (auto& [X0, X1] : out) {
    const Vec3 d = unit();
    X0.R = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    X0.p = (1.2 + u(rng)) * L * d;
    X1.R = X0.R;
    if (screw) X1.R = X0.R * Eigen::AngleAxisd(0.3 + 2.2 * u(rng), unit()).toRotationMatrix();
    X1.p = -(1.2 + u(rng)) * L * d + 0.8 * u(rng) * L * unit();
  }
  return out;
}

/// Runs f with callgrind collecting, then dumps the section's count under
/// its name (one file per section: the counters restart at zero).
template <class F>
void section(const char* name, F&& f) {
  CALLGRIND_TOGGLE_COLLECT;
  f();
  CALLGRIND_TOGGLE_COLLECT;
  CALLGRIND_DUMP_STATS_AT(name);
}

/// The speed guard's paths of one pair, one callgrind dump each (see the top
/// of this file). Every input is made before the first section.
int guard(const std::string& pair, int ncold, int nwarm, int nmotions) {
  const auto S = shapes();
  for (std::size_t i = 0; i < S.size(); ++i)
    for (std::size_t j = i; j < S.size(); ++j) {
      if (pair != std::string(S[i].name) + "-" + S[j].name) continue;
      const Shape &a = S[i].shape, &b = S[j].shape;
      const auto poses = poses_for(a, b);
      BatchRun batch_cold(poses, false, ncold), batch_warm(poses, true, nwarm);
      const std::vector<Pose> &cold = batch_cold.P, &warm = batch_warm.P;
      const auto translations = toi_motions(a, b, nmotions, false), screws = toi_motions(a, b, nmotions, true);
      const SolverOptions opt;
      SolverOptions dopt;
      dopt.derivatives = true;
      std::vector<SolveResult> dres(ncold);
      WarmStart ws;
      solve(a, b, poses[0], opt, &ws);  // the first warm solve is cold
      double sum = 0.0;
      section("cold", [&] {
        for (const Pose& X : cold) sum += solve(a, b, X, opt).alpha;
      });
      section("warm", [&] {
        for (const Pose& X : warm) sum += solve(a, b, X, opt, &ws).alpha;
      });
      section("batch_cold", [&] { batch_cold(a, b); });
      section("batch_warm", [&] { batch_warm(a, b); });
      sum += batch_cold.sum() + batch_warm.sum();
      section("deriv_solve", [&] {
        for (int k = 0; k < ncold; ++k) dres[k] = solve(a, b, cold[k], dopt);
      });
      section("deriv", [&] {
        for (const SolveResult& r : dres) sum += alpha_gradient(r)[5] + solution_sensitivity(r).dz_dxi(0, 0);
      });
      section("shape", [&] {
        for (const SolveResult& r : dres)
          if (r.converged()) sum += shape_sensitivity(r, a, b, 1).dz_dtheta(3, 0) + shape_sensitivity(r, a, b, 2).dz_dtheta(3, 0);
      });
      long solves[2] = {0, 0};
      for (int screw = 0; screw < 2; ++screw)
        section(screw ? "toi_screw" : "toi_translation", [&] {
          for (const auto& [X0, X1] : screw ? screws : translations) {
            const ToiResult r = time_of_impact(a, b, X0, X1);
            solves[screw] += r.solves;
            sum += r.t;
          }
        });
      std::printf("%s guard simd %s (checksum %.17g)\n", pair.c_str(), batch_simd_isa(), sum);
      std::printf("solves toi_translation %.4f\nsolves toi_screw %.4f\n", static_cast<double>(solves[0]) / nmotions,
                  static_cast<double>(solves[1]) / nmotions);
      return 0;
    }
  std::fprintf(stderr, "unknown pair %s\n", pair.c_str());
  return 2;
}

/// run's and steps' MODE and N: the sweep modes read poses 0..N of the
/// kPoses-pose sweep (warm: N + 1 of them), the walk makes N + 1 poses.
bool run_args(const char* cmd, const char* mode_text, const char* n_text, int& n) {
  const std::string mode = mode_text;
  static const char* const run_modes[] = {"cold", "warm", "walkcold", "walkwarm", "batchcold", "batchwarm"};
  const bool batch = mode == "batchcold" || mode == "batchwarm";
  bool known = false;
  for (const char* m : run_modes) known |= mode == m && (!batch || !std::strcmp(cmd, "run"));
  if (!known) {
    std::fprintf(stderr, "idcol_prof %s: MODE must be one of cold, warm, walkcold, walkwarm%s, got '%s'\n", cmd,
                 std::strcmp(cmd, "run") ? "" : ", batchcold, batchwarm", mode_text);
    return false;
  }
  const bool walk = mode == "walkcold" || mode == "walkwarm";
  n = static_cast<int>(examples::count_arg("idcol_prof", "N", n_text, 1, walk ? 10000000 : kPoses - 1));
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && !std::strcmp(argv[1], "check")) return check(argc >= 3 ? argv[2] : nullptr);
  if (argc == 3 && !std::strcmp(argv[1], "dump")) return dump(argv[2]);
  if (argc == 5 && (!std::strcmp(argv[1], "run") || !std::strcmp(argv[1], "steps"))) {
    int n = 0;
    if (!run_args(argv[1], argv[3], argv[4], n)) return 2;
    return !std::strcmp(argv[1], "run") ? run(argv[2], argv[3], n) : steps(argv[2], argv[3], n);
  }
  if (argc == 6 && !std::strcmp(argv[1], "guard")) {
    auto count = [&](const char* name, const char* text, long hi) {
      return static_cast<int>(examples::count_arg("idcol_prof", name, text, 1, hi));
    };
    return guard(argv[2], count("NCOLD", argv[3], kPoses - 1), count("NWARM", argv[4], kPoses - 1), count("NMOTIONS", argv[5], 10000000));
  }
  std::fprintf(stderr, "usage: idcol_prof check [out.bin] | dump out.bin | run|steps PAIR MODE N | guard PAIR NCOLD NWARM NMOTIONS\n");
  return 2;
}
