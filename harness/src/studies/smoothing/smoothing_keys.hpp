// The keys only a smoothing study's results file has (io/keys.hpp explains
// why keys are constants).
#pragma once

#include "io/keys.hpp"

namespace idcol::harness::key {

inline constexpr char converged_fraction[] = "converged_fraction";  // converged solves / poses, per pass
inline constexpr char oracle_failures[] = "oracle_failures";        // accuracy pass: poses the exact oracle did not answer
inline constexpr char alpha_rel_error[] = "alpha_rel_error";        // accuracy pass: |alpha* - exact| / exact
inline constexpr char geometry[] = "geometry";                      // the smooth body against its exact body ...
inline constexpr char hausdorff_lower_rel[] = "hausdorff_lower_rel";
inline constexpr char radial_gap_max_rel[] = "radial_gap_max_rel";
inline constexpr char smooth_outside_exact_count[] = "smooth_outside_exact_count";
inline constexpr char smoothness[] = "smoothness";  // the answer's change along the trajectory ...
inline constexpr char alpha_jump_rel_per_step[] = "alpha_jump_rel_per_step";
inline constexpr char normal_jump_per_step[] = "normal_jump_per_step";
/// The scene's [study] recommend_error_below: the recommendation's bound on
/// the alpha* p99 relative error (scripts/plot_smoothing.py reads it).
inline constexpr char recommend_error_below[] = "recommend_error_below";

}  // namespace idcol::harness::key
