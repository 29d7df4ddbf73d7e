// What one query of each kind costs, for the estimate `check` prints and
// `run` prints before a long run (Study::estimate). One place for every
// constant, each with where it was measured; the studies multiply them by
// the counts their scene asks for.
//
// Measured on the development machine (2 cores, shared with other builds,
// load average 2 to 4 while measuring), in seconds of one core:
//  - solves, oracles and baselines: the per-method means of the side-by-side
//    timing section of `run configs/paper_table2.toml --shard 0/100` (10000
//    poses) and `run configs/ci.toml`;
//  - smoothing: `smoothing configs/smoothing_polytope.toml --poses 200 / 2000
//    / 8000`, smoothing_superellipsoid and smoothing_cone at 200 and 2000
//    poses, and the wall times of the 100000-pose results files in results/;
//  - time of impact: the per-entry wall times of `run configs/ci_toi.toml`.
// The estimate against the measured wall time of the whole command (the
// figures are in the comment of each study's estimate) is within a factor
// of 2 on these scenes: a guide to how long to wait, not a measurement.
// Shapes far from these (a sharp polytope at beta = 1000 costs 100 times
// the paper's Poly per cold solve) can take longer than estimated.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "idcol/shapes.hpp"
#include "referee/checks.hpp"

namespace idcol::harness::cost {

/// One iDCOL solve, cold or warm, with the harness's bookkeeping around it
/// (paper_table2 shard: 0.4 to 2.4 us cold, 0.36 to 0.6 us warm; ci.toml's
/// shapes 2 to 5 us cold).
inline constexpr double solve = 3e-6;
/// One derivative check (IFT against central differences in the tangent
/// space: a dozen solves and the sensitivities).
inline constexpr double derivative_check = 60e-6;
/// The checks of one converged answer besides its oracle (surfaces, normal).
inline constexpr double answer_check = 1e-6;

/// The exact oracle's alpha* at one pose, by the oracle the pair gets
/// (AnswerChecker::resolve_oracle; the baselines' oracle_for picks the same):
/// closed form (two spheres), Perram-Wertheim (two ellipsoids, 1.3 to 3.4
/// us), the polytope LP (8 faces: 10.7 to 17.9 us), and the support-function
/// bracket for everything else (paper Poly x Ellip: 374 to 506 us; ci's
/// Tiny x Big: 654 us).
inline constexpr double oracle_closed_form = 0.1e-6;
inline constexpr double oracle_perram_wertheim = 2e-6;
inline constexpr double oracle_polytope_lp = 12e-6;
inline constexpr double oracle_support_function = 450e-6;

inline double oracle_query(const Shape& b1, const Shape& b2) {
  switch (AnswerChecker::resolve_oracle(b1, b2)) {
    case OracleChoice::ClosedForm: return oracle_closed_form;
    case OracleChoice::PerramWertheim: return oracle_perram_wertheim;
    case OracleChoice::PolytopeLP: return oracle_polytope_lp;
    default: return oracle_support_function;
  }
}

/// One query of a boolean or distance baseline, by pair kind (the paper's
/// Poly and Ellip; paper_table2 shard, means of 10000 poses). Bullet's two
/// (btGjkPairDetector, btGjkEpaSolver2) are the CPU times per query of
/// baselines/bench/bench_baselines.cpp (median of 5 repetitions, 512 poses
/// with alpha* in [0.7, 1.4]; its command in baselines/README.md).
struct BaselineQuery {
  double fcl_collide, fcl_distance, ccd_gjk, ccd_mpr, bullet_gjk_pair, bullet_gjk_epa2;
};
inline constexpr BaselineQuery poly_poly{0.7e-6, 5.1e-6, 0.44e-6, 0.28e-6, 1.9e-6, 1.3e-6};
inline constexpr BaselineQuery poly_ellip{1.5e-6, 23e-6, 0.27e-6, 0.19e-6, 4.1e-6, 3.7e-6};
inline constexpr BaselineQuery ellip_ellip{1.8e-6, 79e-6, 0.24e-6, 0.18e-6, 7.9e-6, 8.3e-6};

/// One query of the baseline `method` ("fcl_collide", ...; "oracle" is
/// oracle_query) on the pair.
inline double baseline_query(const std::string& method, const Shape& b1, const Shape& b2) {
  const int polys = std::holds_alternative<SmoothPolytope>(b1) + std::holds_alternative<SmoothPolytope>(b2);
  const BaselineQuery& q = polys == 2 ? poly_poly : polys == 1 ? poly_ellip : ellip_ellip;
  if (method == "fcl_collide") return q.fcl_collide;
  if (method == "fcl_distance") return q.fcl_distance;
  if (method == "ccd_gjk") return q.ccd_gjk;
  if (method == "ccd_mpr") return q.ccd_mpr;
  if (method == "bullet_gjk_pair") return q.bullet_gjk_pair;
  if (method == "bullet_gjk_epa2") return q.bullet_gjk_epa2;
  if (method == "oracle") return oracle_query(b1, b2);
  return 0.0;
}

/// Smoothing grid, per grid point: the directions of the Hausdorff sample
/// (20030 directions: 0.14 to 0.2 s a point), and per pose of the accuracy
/// pass (cold solve, exact alpha*, conditioning, derivatives; core seconds,
/// the pass runs on --threads). The polytope's exact alpha* (its distance
/// to the partner sphere) is the costly one: smoothing_polytope's 100000
/// poses took 182 s on 2 threads for 8 points, the cone, cylinder and
/// superellipsoid 16 to 19 s for 9 to 12 points.
inline constexpr double smoothing_direction = 8e-6;
inline constexpr double smoothing_pose_polytope = 360e-6;
inline constexpr double smoothing_pose_smooth = 30e-6;

/// Time of impact, per motion: the oracle's bracket per sample along the
/// motion (ci_toi, 300 samples: 27 to 30 us a motion closed form, 250 to
/// 370 us Perram-Wertheim, 33 ms the support-function bracket of a box at
/// load 1.8; toi.toml, 500 samples: 88 to 147 ms at load 4.8), and
/// one query of iDCOL's time_of_impact and of FCL's continuousCollide (2 to
/// 25 us; each timed over kToiTimingLoops loops).
inline constexpr double toi_sample_closed_form = 0.1e-6;
inline constexpr double toi_sample_perram_wertheim = 1.1e-6;
inline constexpr double toi_sample_support_function = 150e-6;
inline constexpr double toi_query = 10e-6;
inline constexpr double toi_fcl_query = 10e-6;

inline double toi_sample(const std::string& oracle_method) {
  if (oracle_method == "closed_form") return toi_sample_closed_form;
  if (oracle_method == "perram_wertheim") return toi_sample_perram_wertheim;
  return toi_sample_support_function;
}

}  // namespace idcol::harness::cost
