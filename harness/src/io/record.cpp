#include "io/record.hpp"

#include <climits>
#include <cmath>

#include "io/keys.hpp"

#include "io/solver_options.hpp"
#include "io/text.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {
json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json vec6(const Vec6& z) { return {z[0], z[1], z[2], z[3], z[4], z[5]}; }
Vec6 vec6_from(const json& j) {
  Vec6 z;
  for (int i = 0; i < 6; ++i) z[i] = j.at(i).get<double>();
  return z;
}
}  // namespace

json results_header(const char* schema, const json& metadata, const SceneText& scene, const SolverOptions& solver) {
  return {{"schema", schema},
          {"schema_version", kResultsSchemaVersion},
          {"metadata", metadata},
          {"scene", {{"path", scene.path}, {"name", scene.name}, {"content", scene.text}}},
          {"solver", solver_json(solver)}};
}

json failures_file(const json& metadata, const SceneText& scene, const SolverOptions& solver, const std::string& results_path,
                   json failures) {
  json f = results_header(kFailuresSchema, metadata, scene, solver);
  f["results"] = results_path;
  f[key::failures] = std::move(failures);
  return f;
}

void check_header(const json& f, const JsonAt& top) {
  expect_version(f, kResultsSchemaVersion, top);
  member(f, "scene", JsonType::Object, top);
  member(f, "solver", JsonType::Object, top);
  if (const json* m = optional_member(f, "metadata", JsonType::Object, top)) {
    for (const char* key : {"git_revision", "date_utc"}) optional_member(*m, key, JsonType::String, top / "metadata");
    optional_member(*m, "git_dirty", JsonType::Bool, top / "metadata");
  }
}

namespace {

void check_pose(const json& pose, const JsonAt& at) {
  const json& R = member(pose, "R", JsonType::Array, at);
  if (R.size() != 3) (at / "R").fail("3 rows of 3 numbers", R);
  for (std::size_t i = 0; i < 3; ++i) expect_array_of(R[i], 3, JsonType::Number, (at / "R")[i]);
  expect_array_of(member(pose, "p", JsonType::Array, at), 3, JsonType::Number, at / "p");
}

void check_warm_start(const json& w, const JsonAt& at) {
  if (!member(w, "valid", JsonType::Bool, at).get<bool>()) return;
  expect_array_of(member(w, "z", JsonType::Array, at), 6, JsonType::Number, at / "z");
  member(w, "length", JsonType::Number, at);
  optional_member(w, "extrapolate", JsonType::Bool, at);
  const json* history = optional_member(w, "history", JsonType::Count, at);
  const std::uint64_t n = history ? history->get<std::uint64_t>() : 0;
  if (n > 2) (at / "history").fail("0, 1 or 2 (the predictor keeps the last two starts)", *history);
  if (n == 0) return;
  const json& prev = member(w, "z_prev", JsonType::Array, at);
  if (prev.size() < n) (at / "z_prev").fail(std::to_string(n) + " starts (history = " + std::to_string(n) + ")", prev);
  for (std::size_t i = 0; i < n; ++i) expect_array_of(prev[i], 6, JsonType::Number, (at / "z_prev")[i]);
}

/// A record as failure_record writes it, and the keys its callers add that
/// replay reads (an agreement record's kind, a derivative record's h and
/// tolerance).
void check_failure_record(const json& r, const JsonAt& at) {
  for (const char* k : {"body1", "body2", "pass", "shape1", "shape2", "pose_text"}) member(r, k, JsonType::String, at);
  for (const char* k : {"generator", "problem", "replay"}) optional_member(r, k, JsonType::String, at);
  member(r, "k", JsonType::Count, at);
  optional_member(r, "index", JsonType::Count, at);
  check_pose(member(r, "pose", JsonType::Object, at), at / "pose");
  if (optional_member(r, "status", JsonType::String, at)) {
    const json& it = member(r, key::iterations, JsonType::Count, at);
    if (it.get<std::uint64_t>() > static_cast<std::uint64_t>(INT_MAX)) (at / key::iterations).fail("at most 2^31 - 1 iterations", it);
    member(r, "restarts", JsonType::Count, at);
    member(r, "used_continuation", JsonType::Bool, at);
    member(r, "residual_norm", JsonType::NumberOrNull, at);
    member(r, "alpha", JsonType::NumberOrNull, at);
    expect_array_of(member(r, "x", JsonType::Array, at), 3, JsonType::NumberOrNull, at / "x");
  }
  if (const json* w = optional_member(r, "warm_start", JsonType::Object, at)) check_warm_start(*w, at / "warm_start");
  const json* kind = optional_member(r, "kind", JsonType::String, at);
  if (kind && *kind == "derivative_disagreement") {
    member(r, "h", JsonType::Number, at);
    member(r, "tolerance", JsonType::Number, at);
  }
}

}  // namespace

void check_failures_file(const json& f, const std::string& file) {
  const JsonAt top(file);
  const json& schema = member(f, "schema", JsonType::String, top);
  if (schema != kFailuresSchema) (top / "schema").fail(std::string("\"") + kFailuresSchema + "\" (a failures file)", schema);
  check_header(f, top);
  const json& records = member(f, key::failures, JsonType::Array, top);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const JsonAt at = (top / key::failures)[i];
    check_failure_record(expect_type(records[i], JsonType::Object, at), at);
  }
}

json pose_to_json(const Pose& X) {
  json R = json::array();
  for (int i = 0; i < 3; ++i) R.push_back({X.R(i, 0), X.R(i, 1), X.R(i, 2)});
  return {{"R", R}, {"p", {X.p.x(), X.p.y(), X.p.z()}}};
}

Pose pose_from_json(const json& j) {
  Pose X;
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 3; ++c) X.R(i, c) = j.at("R").at(i).at(c).get<double>();
  for (int i = 0; i < 3; ++i) X.p[i] = j.at("p").at(i).get<double>();
  return X;
}

std::string pose_text(const Pose& X) {
  return format("R = [[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g]], p = [%.17g, %.17g, %.17g]",
                X.R(0, 0), X.R(0, 1), X.R(0, 2), X.R(1, 0), X.R(1, 1), X.R(1, 2), X.R(2, 0), X.R(2, 1), X.R(2, 2), X.p.x(),
                X.p.y(), X.p.z());
}

json warm_start_json(const WarmStart& w) {
  if (!w.valid) return {{"valid", false}};
  json j = {{"valid", true}, {"z", vec6(w.z)}, {"length", w.length}, {"history", w.history}, {"extrapolate", w.extrapolate}};
  for (int i = 0; i < w.history && i < 2; ++i) j["z_prev"].push_back(vec6(w.z_prev[i]));
  return j;
}

WarmStart warm_start_from_json(const json& j) {
  WarmStart w;
  w.valid = j.at("valid").get<bool>();
  if (!w.valid) return w;
  w.z = vec6_from(j.at("z"));
  w.length = j.at("length").get<double>();
  // Records written before the predictor's history was kept replay without it.
  w.history = j.value("history", 0);
  for (int i = 0; i < w.history && i < 2; ++i) w.z_prev[i] = vec6_from(j.at("z_prev").at(i));
  w.extrapolate = j.value("extrapolate", true);
  return w;
}

json failure_record(const FailureSite& s, const Pose& X, const SolveResult* r, const WarmStart* warm_before) {
  json f = {{"body1", s.body1},
            {"body2", s.body2},
            {"pass", s.pass},
            {"k", s.k},
            {"generator", s.generator},
            {"shape1", describe(*s.shape1)},
            {"shape2", describe(*s.shape2)},
            {"pose", pose_to_json(X)},
            {"pose_text", pose_text(X)}};
  if (r) {
    f["status"] = to_string(r->status);
    f[key::iterations] = r->iterations;
    f["restarts"] = r->restarts;
    f["used_continuation"] = r->used_continuation;
    f["residual_norm"] = finite_or_null(r->residual_norm);
    f["alpha"] = finite_or_null(r->alpha);
    f["x"] = {finite_or_null(r->x_1[0]), finite_or_null(r->x_1[1]), finite_or_null(r->x_1[2])};
  }
  if (warm_before) f["warm_start"] = warm_start_json(*warm_before);
  return f;
}

namespace {
std::string& harness_command_storage() {
  static std::string c = "idcol_harness";
  return c;
}
}  // namespace

void set_harness_command(const std::string& command) { harness_command_storage() = command; }
const std::string& harness_command() { return harness_command_storage(); }

void append_failures(json& into, json records, const std::string& failures_path) {
  const std::string file = failures_path.empty() ? std::string("FAILURES.json") : failures_path;
  for (auto& f : records) {
    const std::size_t index = into.size();
    f["index"] = index;
    f["replay"] = harness_command() + " replay " + file + " --index " + std::to_string(index);
    into.push_back(std::move(f));
  }
}

}  // namespace idcol::harness
