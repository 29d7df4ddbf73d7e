// The smoothing study (issue 6): error against run time over a sharpness
// grid. A grid file (configs/smoothing_*.toml) names one family's shape
// without its sharpness, the parameter ("beta" or "n") and its values, the
// partner sphere, the sweep, and optionally a [solver] table; see
// smoothing.cpp for what is measured at each grid point. Built only with the
// baselines (the exact oracles).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "idcol_harness/record.hpp"

namespace idcol::harness {

struct SmoothingGrid {
  SceneText scene;
  std::string description;
  std::string parameter;               // "beta" or "n"
  std::vector<double> values;
  std::vector<std::string> shape_texts;  // the grid's shape at each value, as a [shapes] inline table
  double partner_radius = 0.75;
  std::uint64_t poses = 10000;
  double dt = 1e-4;
  std::uint64_t warmup = 500;
  int directions = 20000;
  int oracle_check_poses = 200;
  SolverOptions solver;  // the [solver] table; the accuracy pass adds derivatives
};

/// Parses a grid file through the scene reader's TOML layer (prescan, exact
/// error positions, unknown keys rejected); throws SceneError.
SmoothingGrid parse_smoothing_grid(const std::string& text, const std::string& path);

struct SmoothingOptions {
  int threads = 2;  // the non-timing passes; the timing passes run on one thread
  int pin = -1;     // CPU the timing passes are pinned to (-1: none)
};

/// Runs the study; returns the results file (schema kSmoothingSchema) and
/// appends the failed solves to `failures` (numbered for `failures_path`).
nlohmann::json run_smoothing(const SmoothingGrid& grid, const SmoothingOptions& opt, const nlohmann::json& metadata,
                             nlohmann::json& failures, const std::string& failures_path);

}  // namespace idcol::harness
