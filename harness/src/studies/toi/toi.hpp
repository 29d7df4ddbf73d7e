// The time-of-impact study: idcol::time_of_impact (core/include/idcol/toi.hpp)
// on motions drawn from the harness's pose generators, each answer checked
// against an oracle that shares no code with the solver
// (baselines/toi_oracle.hpp: closed forms for spheres, Perram-Wertheim for
// ellipsoids, the support-function bracket otherwise, sampled densely along
// the motion and bisected), with FCL's continuousCollide (naive sampling and
// conservative advancement) on the same motions where this build has FCL
// and FCL has the pair.
//
// A scene (configs/toi.toml) has [shapes] and a [toi] table (ToiSpec,
// toi_spec.hpp); each entry of the results file is one pair under one motion
// model ("translation" or "screw"). Per method it counts impacts, no
// impacts, initial contacts and failures (idcol: NumericalFailure or
// IterationLimit), and against the oracle the missed contacts (the oracle
// sees a clear hit, the method none) and false impacts (the oracle sees a
// clear miss, the method a contact), the worst |t - t_oracle| over the hits
// found (the distance outside the oracle's [t_lo, t_hi]), solves per query
// and CPU time per query (the fastest of 3 loops over the entry's motions).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol_baselines/toi_oracle.hpp"
#include "scene/scene.hpp"
#include "studies/study.hpp"
#include "studies/toi/toi_spec.hpp"

namespace idcol::harness {

/// The schema of a time-of-impact results file (io/record.hpp has the others').
constexpr const char* kToiSchema = "idcol-harness-toi";
/// Each method's loop over an entry's motions runs this many times; the
/// fastest loop gives the time per query, the first the answers.
constexpr int kToiTimingLoops = 3;

/// One motion of body 2 from X0 to X1 (body 1 at rest at the identity).
struct ToiMotion {
  Pose X0, X1;
};

/// Motion k of a pair under a model, from four Halton points (gen/poses.hpp)
/// at 4 (seed 2^20 + k): X0's rotation uniform, its origin at (1.05 + spread u) L
/// along a uniform direction a (the bodies' outer balls apart); X1 on the
/// far side, -(1.05 + spread u') L a plus a sideways shift of up to offset L,
/// or, for a fraction end_inside of the motions, anywhere within L (the
/// bodies may overlap at t = 1); X1's rotation R0 (translation) or R0 turned
/// by turn_min..turn_max rad about a uniform axis (screw).
ToiMotion toi_motion(const ToiSpec& spec, double L, bool screw, std::uint64_t k);

/// A method's answer on one motion, as the tally reads it.
struct ToiAnswer {
  bool decided = true;  // false: idcol's NumericalFailure or IterationLimit
  bool hit = false;     // a contact at some t in [0, 1]
  bool initial = false; // in contact at t = 0
  double t = 1.0;
  double solves = 0.0;
};

/// One method's counts over an entry's motions.
struct ToiTally {
  std::uint64_t motions = 0, impacts = 0, no_impacts = 0, initial = 0, failures = 0;
  std::uint64_t missed = 0, false_impacts = 0;
  double t_error_max = 0.0, solves = 0.0, seconds = 0.0;
  /// Counts the answer against the oracle's verdict; returns "missed_contact",
  /// "false_impact", "failure" or "" (no record needed).
  std::string add(const baselines::ToiOracleAnswer& oracle, const ToiAnswer& a);
  nlohmann::json to_json() const;
};

/// Runs the study over the shard's entries; appends the failure records
/// (missed contacts, false impacts, idcol's failures) to `failures`.
nlohmann::json run_toi(const Scene& scene, const StudyOptions& opt, const nlohmann::json& metadata, nlohmann::json& failures);

/// The Markdown table of a toi results file.
std::string toi_markdown(const nlohmann::json& results, const std::string& path);

}  // namespace idcol::harness
