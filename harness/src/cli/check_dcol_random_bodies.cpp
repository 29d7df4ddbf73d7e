// DCOL (baselines/dcol.hpp) on the random-body generator's bodies that have
// an exact counterpart: spheres, boxes and polytopes (as the exact
// polytopes they smooth), every ordered pair of these families, at the
// generator's random poses (harness/src/gen/random_bodies.hpp, the bodies
// and poses of configs/random_bodies.toml). Each answer is compared with the
// pair's exact oracle (Perram-Wertheim, GLPK's LP, the support-function
// bracket: baselines::exact_oracle), which shares no code with DCOL: its
// alpha must lie within its own bound (twice its duality gap) of the
// oracle's bracket.
//
//   build/harness/idcol_check_dcol_random_bodies [poses per ordered pair = 1000] [wide = 0] [seed = 1] [-o results.json] [--strict]
//
// Prints one row per ordered family pair and the totals, and with -o writes
// them as a results file (with its metadata: machine, compiler, git
// revision). Exit status 0 (it measures DCOL; a record of its misses is the
// result), or with --strict 1 if any answer lies beyond its bound or did not
// converge; 2 for a bad command line.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gen/random_bodies.hpp"
#include "idcol_baselines/baselines.hpp"
#include "idcol_baselines/dcol_adapter.hpp"
#include "io/files.hpp"
#include "io/keys.hpp"
#include "../../../core/examples/cli_args.hpp"

using namespace idcol;
using namespace idcol::baselines;
using nlohmann::json;

namespace {

struct Row {
  long poses = 0, converged = 0, beyond_bound = 0, oracle_failed = 0, iterations = 0, max_iterations = 0;
  double worst_rel = 0.0;  // largest distance from the oracle's bracket, relative to alpha*
  json to_json() const {
    return {{"poses", poses},       {"converged", converged},         {"beyond_bound", beyond_bound},
            {idcol::harness::key::oracle_failed, oracle_failed}, {"mean_iterations", poses ? double(iterations) / poses : 0.0},
            {"max_iterations", max_iterations}, {"worst_rel_outside", worst_rel}};
  }
};

constexpr harness::BodyFamily kExact[] = {harness::BodyFamily::Sphere, harness::BodyFamily::Box, harness::BodyFamily::Polytope};

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args;
  std::string out_path;
  bool strict = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-o" && i + 1 < argc) out_path = argv[++i];
    else if (a == "--strict") strict = true;
    else if (a == "-h" || a == "--help") {
      std::printf("usage: idcol_check_dcol_random_bodies [poses per ordered pair = 1000] [wide = 0] [seed = 1] [-o results.json] [--strict]\n");
      return 0;
    } else args.push_back(a);
  }
  constexpr const char* kTool = "idcol_check_dcol_random_bodies";
  const long per = args.size() > 0 ? examples::count_arg(kTool, "poses per pair", args[0].c_str(), 1, 100000000) : 1000;
  const bool wide = args.size() > 1 && examples::count_arg(kTool, "wide", args[1].c_str(), 0, 1) != 0;
  const long seed = args.size() > 2 ? examples::count_arg(kTool, "seed", args[2].c_str(), 0, 2147483647) : 1;
  if (args.size() > 3) {
    std::fprintf(stderr, "idcol_check_dcol_random_bodies: expected [poses >= 1] [wide 0|1] [seed >= 0] [-o FILE], got %s%s\n",
                 args.empty() ? "" : args[0].c_str(), args.size() > 3 ? " and more" : "");
    return 2;
  }
  std::printf("DCOL on random exact bodies, %s range, %ld poses per ordered pair, seed %ld, against the exact oracles\n",
              wide ? "wide" : "normal", per, seed);
  std::printf("%-20s %8s %10s %12s %10s %10s %8s %12s\n", "pair", "poses", "converged", "beyond bound", "no oracle", "mean iter",
              "max iter", "worst rel");
  Row total;
  json rows = json::array();
  for (const auto f1 : kExact)
    for (const auto f2 : kExact) {
      const harness::RandomBodyCase rc{f1, f2, wide ? harness::BodyRange::Wide : harness::BodyRange::Normal,
                                       static_cast<std::uint64_t>(seed)};
      Row row;
      for (long k = 0; k < per; ++k) {
        const harness::RandomBodyPose P = harness::random_body_pose(rc, static_cast<std::uint64_t>(k));
        const ExactShape e1 = to_exact(P.body1), e2 = to_exact(P.body2);
        const DcolPair dcol(e1, e2);
        const BaselineAnswer a = dcol.answer(P.X_12);
        ++row.poses;
        row.iterations += std::max(0, a.iterations);
        row.max_iterations = std::max<long>(row.max_iterations, a.iterations);
        if (a.failed) {
          std::printf("  NOT CONVERGED %s-%s pose %ld: %s\n", harness::to_string(f1), harness::to_string(f2), k, a.error.c_str());
          continue;
        }
        ++row.converged;
        const OracleAnswer o = exact_oracle(e1, e2, P.X_12);
        if (!o.ok) {
          ++row.oracle_failed;
          continue;
        }
        const double out = std::max({0.0, o.alpha_lo - a.alpha, a.alpha - o.alpha_hi});
        row.worst_rel = std::max(row.worst_rel, out / o.alpha);
        if (out > a.alpha_bound) {
          ++row.beyond_bound;
          std::printf("  BEYOND BOUND %s-%s pose %ld: alpha %.17g, bound %.3g, oracle [%.17g, %.17g]\n", harness::to_string(f1),
                      harness::to_string(f2), k, a.alpha, a.alpha_bound, o.alpha_lo, o.alpha_hi);
        }
      }
      const std::string name = std::string(harness::to_string(f1)) + "-" + harness::to_string(f2);
      std::printf("%-20s %8ld %10ld %12ld %10ld %10.2f %8ld %12.3g\n", name.c_str(), row.poses, row.converged, row.beyond_bound,
                  row.oracle_failed, double(row.iterations) / row.poses, row.max_iterations, row.worst_rel);
      json j = row.to_json();
      j["pair"] = name;
      rows.push_back(j);
      total.poses += row.poses, total.converged += row.converged, total.beyond_bound += row.beyond_bound;
      total.oracle_failed += row.oracle_failed, total.iterations += row.iterations;
      total.max_iterations = std::max(total.max_iterations, row.max_iterations);
      total.worst_rel = std::max(total.worst_rel, row.worst_rel);
    }
  std::printf("total: %ld poses, %ld converged, %ld beyond DCOL's own bound, %ld without an oracle; worst %.3g relative\n",
              total.poses, total.converged, total.beyond_bound, total.oracle_failed, total.worst_rel);
  const bool ok = total.beyond_bound == 0 && total.converged == total.poses;
  if (!out_path.empty()) {
    json r = {{"schema", "idcol-dcol-random-bodies"},
              {"schema_version", 1},
              {"metadata", harness::collect_metadata(argc, argv)},
              {"range", wide ? "wide" : "normal"},
              {"seed", seed},
              {"poses_per_pair", per},
              {"pairs", rows},
              {"total", total.to_json()},
              {"pass", ok}};
    harness::write_file_atomically(out_path, r.dump(2) + "\n");
    std::printf("results: %s\n", out_path.c_str());
  }
  return ok || !strict ? 0 : 1;
}
