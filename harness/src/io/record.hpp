// The one record of the harness. Every results file (sweep, stress,
// smoothing) opens with the same header (schema, metadata: machine,
// compiler, flags, git revision; the scene as given; every solver option),
// and every failure record, whichever pass wrote it, has the same fields
// (the site: bodies, shapes, pass, pose index and pose; the solve: status,
// iterations, residual, alpha, x; the warm start it began from), so that
// `replay` rebuilds any of them.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "idcol/result.hpp"
#include "idcol/shapes.hpp"
#include "idcol/solver.hpp"
#include "io/json_fields.hpp"

namespace idcol::harness {

constexpr int kResultsSchemaVersion = 1;
/// Failure records of a sweep that carry the iteration trace of a re-solve:
/// the first 20 of the run (--max-traced-failures; a trace can be ~100 kB,
/// and replay regenerates any).
constexpr std::size_t kDefaultTracedFailures = 20;
constexpr const char* kResultsSchema = "idcol-harness-results";
constexpr const char* kFailuresSchema = "idcol-harness-failures";
constexpr const char* kStressSchema = "idcol-harness-stress";
constexpr const char* kSmoothingSchema = "idcol-smoothing-study";

/// The scene a results file was made from, as given.
struct SceneText {
  std::string path, name, text;
};

/// Header common to every results file: schema, schema_version, metadata,
/// scene {path, name, content} and solver (every option, solver_json).
nlohmann::json results_header(const char* schema, const nlohmann::json& metadata, const SceneText& scene,
                              const SolverOptions& solver);
/// A failures file for `results_path`: the same header (schema
/// kFailuresSchema) and the records.
nlohmann::json failures_file(const nlohmann::json& metadata, const SceneText& scene, const SolverOptions& solver,
                             const std::string& results_path, nlohmann::json failures);

/// The header of a file written through results_header, as its readers
/// read it: schema_version exactly kResultsSchemaVersion (a reader reads
/// one version); scene and solver objects; metadata, where present, an
/// object whose git_revision and date_utc are strings and git_dirty true or
/// false. The schema is the caller's (a results file's is its kind's).
/// Throws FileError naming the file, the field and the value.
void check_header(const nlohmann::json& f, const JsonAt& top);

/// A failures file (failures_file) as `replay` and `info` read it: schema
/// kFailuresSchema, the header, and every record with the fields
/// failure_record writes, each of its type (the pose 3 x 3 and 3 numbers,
/// the warm start's z 6 numbers, counts integers in [0, 2^64), ...).
/// Throws FileError naming the file, the field and the value.
void check_failures_file(const nlohmann::json& f, const std::string& file);

/// Pose and warm start as stored in a failure record, and back.
nlohmann::json pose_to_json(const Pose& X);
Pose pose_from_json(const nlohmann::json& j);
std::string pose_text(const Pose& X);  // 17 significant digits
/// {valid, z, length}; an invalid warm start's z is stale and unused, so it is left out.
nlohmann::json warm_start_json(const WarmStart& w);
WarmStart warm_start_from_json(const nlohmann::json& j);

/// Where a failure happened: enough, with the solver options of the file,
/// to rebuild the solve.
struct FailureSite {
  std::string body1, body2;
  const Shape* shape1 = nullptr;
  const Shape* shape2 = nullptr;
  std::string pass;  // "cold" or "warm"
  std::uint64_t k = 0;
  std::string generator;  // "paper", "uniform", "stress:shell", ...
};

/// The record of one failed or disputed solve: the site, the pose, the
/// solve's status, iterations, restarts, continuation, residual, alpha and
/// x (the contact point x*, body-1 frame) (when r is given; non-finite
/// numbers as null), and the warm start the
/// solve began from (when warm_before is given, i.e. on the warm pass).
/// Callers add what only they know (the problem found, a trace, an oracle's
/// answer) as further keys.
nlohmann::json failure_record(const FailureSite& site, const Pose& X, const SolveResult* r = nullptr,
                              const WarmStart* warm_before = nullptr);

/// The harness command that replay commands name: "idcol_harness" unless the
/// command line sets the path it runs from (main: the executable's path,
/// relative to the working directory when beneath it).
void set_harness_command(const std::string& command);
const std::string& harness_command();

/// Moves `records` to the end of `into`, giving each its index there and the
/// command that replays it from `failures_path`.
void append_failures(nlohmann::json& into, nlohmann::json records, const std::string& failures_path);

}  // namespace idcol::harness
