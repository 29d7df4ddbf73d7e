// The stress suite (configs/stress.toml): cases that push one pair of shapes
// into a hard regime (sharp shapes, extreme aspect and size ratios,
// separation extremes, touching contact, many facets, off-centre frames,
// warm starts under large jumps), each checked beyond the solver's own
// status: surface and normal checks of every converged answer, an
// independent oracle wherever one exists, derivatives against finite
// differences on a subsample, and the KKT conditioning.
//
// Stress scene schema (see configs/stress.toml for a commented example; read
// by read_stress_scene, stress_spec.hpp, into a StressSpec: parse_scene takes
// a file with [[case]] tables as a stress scene):
//   name, description
//   [shapes]   as in sweep scenes, including the generated polytopes:
//     { family = "box", half = [hx, hy, hz], origin = [ox, oy, oz], beta, L }
//         the box |y_i - o_i| <= h_i written in a frame whose origin is
//         displaced by -origin from the box centre (origin = [0, 0, 0]:
//         centred), as half-spaces;
//     { family = "facet_sphere", facets = m, radius, beta, L }
//         m half-spaces tangent to the sphere at Fibonacci points;
//     { family = "vertex_sphere", vertices = m, radius, beta, L }
//         the hull of m Fibonacci points on the sphere (vertex form).
//     A scene's facet and vertex spheres ask for at most 20,000 half-spaces
//     in all, a vertex counting as four (read_shapes, scene/scene.cpp).
//   [solver]   optional SolverOptions overrides (as in sweep scenes)
//   [[case]]   name, body1, body2, kind, poses, passes, and per kind:
//     kind = "shell":    distance |r| = L 10^u, u uniform in [log10 rmin, log10 rmax]
//                        (rmin, rmax relative to L = outer1 + outer2), uniform
//                        direction and rotation; zero_every = N puts r = 0 exactly
//                        at every pose k with k % N == 0;
//     kind = "touching": orientation = "uniform" | "face" | "edge" | "vertex";
//                        a reference cold solve at |r| = L, then r scaled by
//                        (1 + eps_k) / alpha_ref so that alpha* = 1 + eps_k,
//                        eps_k = touch_eps[k % len] (default [0, 1e-12, -1e-12]);
//     kind = "explicit": poses = [{ R = [[..],[..],[..]], p = [..] }, ...]; each
//                        must be finite with R orthonormal and det R = +1;
//     kind = "random_bodies": no body1, body2; instead family1, family2 (sphere,
//                        superellipsoid, cylinder, box, polytope, cone), range =
//                        "normal" | "wide", seed (default 1): pose k draws a new
//                        pair of bodies and a pose (random_bodies.hpp). Each pose
//                        is solved in both body orders (passes "cold", "warm",
//                        "cold_swapped", "warm_swapped"; swapped: body 2 first, at
//                        the inverse pose); a warm solve answers the nearby pose
//                        from the answer at the pose. The oracle is the
//                        support-function bracket; no derivative subsample.
//                        [shapes] may be absent when every case is random_bodies.
//   optional per case: warm_chain (default 1000), oracle ("auto", "none",
//   "closed_form", "pw", "lp"; default "auto"), oracle_every (default 1),
//   derivative_samples (default 64).
// Pose k of every kind depends on k alone (Halton point k + 1), so any pose
// can be replayed from its index; consecutive poses are far apart, so the
// warm pass warm-starts under large jumps.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "referee/checks.hpp"
#include "studies/study.hpp"
#include "studies/stress/stress_spec.hpp"
#include "scene/scene.hpp"

namespace idcol::harness {

/// Cuts every case to its first min(poses, max_poses) poses (pose k depends
/// on k alone, so the shorter run is a prefix of the full one).
void limit_stress_poses(Scene& s, std::uint64_t max_poses);

/// Pose k of a case (kind Touching: scaled so that the independent oracle's
/// alpha* (its bracket's midpoint) is 1 + eps_k). `ref` receives that
/// oracle's bracket at the returned pose (Touching only) and
/// `expected_alpha` 1 + eps_k (Touching; else NaN).
Pose stress_pose(const Scene& s, const StressCase& c, std::uint64_t k, TouchReference* ref, double* expected_alpha);

struct StressOutput {
  nlohmann::json cases = nlohmann::json::array();
  nlohmann::json failures = nlohmann::json::array();
  double wall_seconds = 0.0;
  /// With --shard i/N (N > 1): the shard's "shard" member (studies/entry_shards.hpp).
  nlohmann::json shard;
};

/// Runs every case of the shard (opt.shard_index of opt.shard_count: cases
/// i, i + N, ...; every case when unsharded), keeping opt.max_failures records per case and pass (all
/// are counted); opt.progress: one line per case to stderr (which case,
/// elapsed time, estimated time left). Throws Interrupted (exec/chains.hpp) when
/// interrupt_flag() is raised.
StressOutput run_stress(const Scene& s, const StudyOptions& opt);

/// The results file, and the Markdown report generated from it alone.
nlohmann::json make_stress_results(const Scene& s, const StressOutput& out, const nlohmann::json& metadata);
std::string stress_markdown(const nlohmann::json& results, const std::string& results_path);

}  // namespace idcol::harness
