#include "report/history.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "io/files.hpp"
#include "io/keys.hpp"
#include "studies/results_file.hpp"
#include "studies/study.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

constexpr int kHistoryVersion = 1;

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string hex(std::uint64_t h, int digits) {
  std::string s = format("%016llx", static_cast<unsigned long long>(h));
  return s.substr(0, static_cast<std::size_t>(digits));
}

/// A scene's text as TOML reads it: comments and trailing blanks dropped
/// (a '#' inside a quoted string stays), blank lines dropped; so that a
/// reworded comment does not start a new series.
std::string scene_text_without_comments(const std::string& text) {
  std::string out, line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    char quote = 0;
    std::size_t cut = line.size();
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quote) {
        if (c == '\\' && quote == '"') ++i;
        else if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '#') {
        cut = i;
        break;
      }
    }
    line.resize(cut);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\t' || line.back() == '\r')) line.pop_back();
    if (!line.empty()) out += line + "\n";
  }
  return out;
}

/// The kind of a results file, after the check every reader makes
/// (studies/results_file.hpp), its errors as HistoryError.
const StudyKind& kind_of_results(const json& r, const std::string& file) {
  try {
    return check_results(r, file);
  } catch (const FileError& e) {
    throw HistoryError(e.what());
  }
}

std::string str_or(const json& j, const char* key, const std::string& fallback = "?") {
  if (!j.is_object() || !j.contains(key) || j.at(key).is_null()) return fallback;
  return j.at(key).is_string() ? j.at(key).get<std::string>() : j.at(key).dump();
}

json guard_json(const Guard& g) {
  return json{{"metric", g.pattern}, {"better", g.higher_is_better ? "higher" : "lower"}, {"abs", g.abs}, {"rel", g.rel}, {"fail", g.fail}};
}

Guard guard_from_json(const json& j) {
  Guard g;
  g.pattern = j.value("metric", std::string());
  g.higher_is_better = j.value("better", std::string()) == "higher";
  g.abs = j.value("abs", 0.0);
  g.rel = j.value("rel", 0.0);
  g.fail = j.value("fail", true);
  return g;
}

const Guard* first_match(const std::vector<Guard>& guards, const std::string& metric) {
  for (const Guard& g : guards)
    if (fnmatch(g.pattern.c_str(), metric.c_str(), 0) == 0) return &g;
  return nullptr;
}

constexpr const char* kInstructionModes[] = {"cold", "warm"};
constexpr const char* kInstructionsMetric = ".instructions_per_solve";

}  // namespace

json scene_identity(const json& r) {
  const StudyKind& k = kind_of_results(r, "the results file");
  const json scene = r.value("scene", json::object());
  json id;
  id["kind"] = k.name;
  id["scene"] = str_or(scene, "name", "");
  id["scene_hash"] = hex(fnv1a(scene_text_without_comments(str_or(scene, "content", ""))), 16);
  // The run's settings as recorded, less what describes the build or the
  // machine rather than the scene run: the solver's options (the build's
  // defaults unless the scene sets them, and then its text says so), the
  // timer, wall time, failure bookkeeping.
  static const std::set<std::string> not_scene = {"metadata", "schema", "schema_version", "scene", "solver", "wall_seconds",
                                                 "timing", "failure_records", "failure_count", "failures_file",
                                                 "threads_non_timing", "shard"};
  json settings = json::object();
  for (const auto& [key, v] : r.items()) {
    if (not_scene.count(key) || key == k.entries) continue;
    if (key == "sweep" && v.is_object()) {
      json s = json::object();
      for (const auto& [sk, sv] : v.items())
        if (sk.rfind("solver_", 0) != 0) s[sk] = sv;
      settings[key] = s;
    } else {
      settings[key] = v;
    }
  }
  id["settings"] = settings;
  const json shard = r.value("shard", json::object());
  if (shard.is_object() && shard.value("count", 1) > 1) id["shard"] = {{"index", shard.value("index", 0)}, {"count", shard.value("count", 1)}};
  json entries = json::array(), poses = json::array();
  bool any_poses = false;
  for (const json& e : r.at(k.entries)) {
    entries.push_back(k.entry_key(r, e));
    const bool has = e.is_object() && e.contains("poses") && e.at("poses").is_number();
    poses.push_back(has ? e.at("poses") : json(nullptr));
    any_poses = any_poses || has;
  }
  id["entries"] = entries;
  if (any_poses) id["entry_poses"] = poses;  // a stress cut (--max-poses) changes these
  return id;
}

std::string series_key(const json& id) {
  return str_or(id, "kind", "") + ":" + str_or(id, "scene", "") + ":" + hex(fnv1a(id.dump()), 12);
}

std::string machine_label(const json& m) {
  std::string flags = str_or(m, "cxx_flags", "");
  std::string label = str_or(m, "host") + " (" + str_or(m, "cpu_model") + "), " + str_or(m, "compiler") + ", " + str_or(m, "build_type");
  if (!flags.empty()) label += " " + flags;
  if (m.is_object() && m.value("native", false)) label += " native";
  return label;
}

Guard instructions_guard() {
  Guard g;
  g.pattern = std::string("*") + kInstructionsMetric;
  g.rel = 0.01;
  g.fail = false;
  g.origin = "history: instructions per solve";
  return g;
}

json history_record(const json& results, const std::vector<Guard>& guards, const json& instructions, const std::string& source) {
  const StudyKind& k = kind_of_results(results, source.empty() ? "the results file" : source);
  const json id = scene_identity(results);
  const json meta = results.value("metadata", json::object());
  if (!meta.is_object() || !meta.contains("git_revision"))
    throw HistoryError("the results file has no metadata.git_revision: a history is over commits");
  std::vector<Guard> all = guards;
  if (!instructions.is_null() &&
      (!first_match(all, std::string("cold") + kInstructionsMetric) || !first_match(all, std::string("warm") + kInstructionsMetric)))
    all.push_back(instructions_guard());
  std::vector<bool> used(all.size(), false);

  json entries = json::object();
  for (const json& e : results.at(k.entries)) {
    json m = json::object();
    for (const auto& [name, value] : entry_metrics(k.metrics(), e)) {
      const Guard* g = first_match(all, name);
      if (!g) continue;
      used[static_cast<std::size_t>(g - all.data())] = true;
      m[name] = std::isfinite(value) ? json(value) : json(nullptr);
    }
    entries[k.entry_key(results, e)] = m;
  }
  json rec;
  if (!instructions.is_null()) {
    if (!instructions.is_object() || instructions.value("schema", std::string()) != kInstructionsSchema ||
        !instructions.contains("pairs") || !instructions.at("pairs").is_object())
      throw HistoryError(std::string("--instructions: not an ") + kInstructionsSchema + " file (scripts/callgrind_instructions.sh writes one)");
    const std::string rev = str_or(instructions, "git_revision", "");
    if (!rev.empty() && rev != str_or(meta, "git_revision", ""))
      throw HistoryError("--instructions: counted at git " + rev + " but the results are of git " + str_or(meta, "git_revision") +
                         ": instructions per solve belong to the revision that ran");
    for (const auto& [pair, modes] : instructions.at("pairs").items())
      for (const char* mode : kInstructionModes) {
        if (!modes.is_object() || !modes.contains(mode)) continue;
        const json& c = modes.at(mode);
        const double n = c.value("solves", 0.0), ir = c.value("instructions", NAN);
        if (!(n > 0) || !std::isfinite(ir) || ir < 0)
          throw HistoryError("--instructions: pairs." + pair + "." + mode + " needs solves > 0 and instructions >= 0, got " + c.dump());
        const std::string name = std::string(mode) + kInstructionsMetric;
        if (const Guard* g = first_match(all, name)) used[static_cast<std::size_t>(g - all.data())] = true;
        entries[pair][name] = ir / n;
      }
    json about = instructions;
    about.erase("pairs");
    rec["instructions"] = about;
  }
  json gl = json::array();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (used[i]) gl.push_back(guard_json(all[i]));

  json run;
  for (const char* key : {"git_revision", "git_dirty", "date_utc", "host", "cpu_model", "logical_cores", "os", "compiler", "cxx_flags",
                          "build_type", "native", "idcol_version", "libraries", "threads", "pinned_cpu"})
    if (meta.contains(key)) run[key] = meta.at(key);
  run["machine"] = machine_label(meta);
  rec["schema"] = kHistorySchema;
  rec["schema_version"] = kHistoryVersion;
  rec["series"] = series_key(id);
  rec["scene"] = id;
  rec["run"] = run;
  rec["source"] = source;
  rec["guards"] = gl;
  rec["entries"] = entries;
  return rec;
}

std::string history_line(const json& record) { return record.dump() + "\n"; }

namespace {

/// A line as history_record writes it, as show and append read it: the
/// schema and its version, the series, the scene's kind, the run, the guards
/// and every metric's value (a declared one in its declared range).
void check_history_line(const json& j, const JsonAt& top) {
  const json& schema = member(j, "schema", JsonType::String, top);
  if (schema != kHistorySchema) (top / "schema").fail(std::string("\"") + kHistorySchema + "\" (a line of a history)", schema);
  expect_version(j, kHistoryVersion, top);
  member(j, "series", JsonType::String, top);
  const json& kind = member(member(j, "scene", JsonType::Object, top), "kind", JsonType::String, top / "scene");
  const StudyKind* k = study_kind_named(kind.get<std::string>());
  if (!k) (top / "scene.kind").fail("the name of a study kind (sweep, stress, smoothing, toi)", kind);
  const json& run = member(j, "run", JsonType::Object, top);
  for (const char* key : {"git_revision", "date_utc", "machine"}) optional_member(run, key, JsonType::String, top / "run");
  optional_member(run, "git_dirty", JsonType::Bool, top / "run");
  const json& guards = member(j, "guards", JsonType::Array, top);
  for (std::size_t i = 0; i < guards.size(); ++i) {
    const JsonAt at = (top / "guards")[i];
    member(guards[i], "metric", JsonType::String, at);
    const json& better = member(guards[i], "better", JsonType::String, at);
    if (better != "higher" && better != "lower" && better != "same") (at / "better").fail("\"higher\", \"lower\" or \"same\"", better);
    for (const char* key : {"abs", "rel"})
      if (member(guards[i], key, JsonType::Number, at).get<double>() < 0) (at / key).fail("a number >= 0", guards[i][key]);
    member(guards[i], "fail", JsonType::Bool, at);
  }
  for (const auto& [entry, metrics] : member(j, "entries", JsonType::Object, top).items()) {
    const JsonAt at = top / "entries" / entry;
    for (const auto& [name, v] : expect_type(metrics, JsonType::Object, at).items()) {
      const Metric* m = find_metric(k->metrics(), name);
      // history_record writes every figure as a double: a count as 3.0.
      if (m ? !metric_value_ok(*m, v, true) : !is_json_type(v, JsonType::NumberOrNull))
        (at / name).fail(m ? metric_value_expected(*m) : json_type_words(JsonType::NumberOrNull), v);
    }
  }
}

}  // namespace

std::vector<json> read_history(const std::string& path) {
  std::vector<json> out;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw HistoryError(path + ": a folder, not a history file");
  std::ifstream in(path);
  if (!in) return out;
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = path + ":" + std::to_string(n);
    json j;
    try {
      j = json::parse(line);
    } catch (const json::exception& e) {
      throw HistoryError(where + ": not a JSON line (" + e.what() + ")");
    }
    try {
      check_history_line(j, JsonAt(where));
    } catch (const FileError& e) {
      throw HistoryError(e.what());
    }
    out.push_back(std::move(j));
  }
  return out;
}

void append_history(const std::string& path, const json& record) {
  const std::vector<json> old = read_history(path);
  const auto same_run = [&](const json& o) {
    return o.at("series") == record.at("series") && o.at("run").value("git_revision", "") == record.at("run").value("git_revision", "") &&
           o.at("run").value("machine", "") == record.at("run").value("machine", "") &&
           o.at("run").value("date_utc", "") == record.at("run").value("date_utc", "");
  };
  if (std::any_of(old.begin(), old.end(), same_run))
    throw HistoryError(path + " already holds this run (series " + record.at("series").get<std::string>() + ", git " +
                       record.at("run").value("git_revision", "?").substr(0, 12) + ", made " + record.at("run").value("date_utc", "?") + ")");
  std::string text;
  {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    text = s.str();
  }
  if (!text.empty() && text.back() != '\n') text += '\n';
  write_file_atomically(path, text + history_line(record));
}

std::vector<HistoryStep> find_steps(const std::vector<double>& v, const Guard& g) {
  // Which side of the guard around `from` a value lies: +1 above, -1
  // below, 0 within (or within a part in 10^9, rounding).
  const auto side = [&](double from, double to) {
    const double d = to - from;
    const double allowed = std::max({g.abs, g.rel * std::abs(from), 1e-9 * std::max(std::abs(from), std::abs(to))});
    return std::abs(d) > allowed ? (d > 0 ? 1 : -1) : 0;
  };
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::isfinite(v[i])) at.push_back(i);
  std::vector<HistoryStep> steps;
  for (std::size_t t = 1; t < at.size(); ++t) {
    const double before = v[at[t - 1]];
    const int s = side(before, v[at[t]]);
    if (s == 0) continue;
    bool stays = true;
    for (std::size_t u = t + 1; u < at.size() && stays; ++u) stays = side(before, v[at[u]]) == s;
    // The value before is a level, not a one-commit spike that this value
    // merely undoes: it held from the value before it, or this value moved
    // beyond that one too.
    const bool from_level = t < 2 || side(v[at[t - 2]], before) == 0 || side(v[at[t - 2]], v[at[t]]) == s;
    if (stays && from_level) steps.push_back({at[t], before, v[at[t]], (s > 0) == g.higher_is_better});
  }
  return steps;
}

namespace {

/// One series of a history, gathered for show: the commits in order of
/// first appearance, the machines, and per (entry, metric) the values of
/// each machine at each commit (NaN where none; the last run wins).
struct Trend {
  std::string key;
  json identity;
  std::vector<std::string> commits, commit_labels, dates;
  std::vector<std::string> machines;
  std::vector<Guard> guards;  // of the latest line
  std::size_t runs = 0;
  struct Line {
    std::string entry, metric;
    std::vector<std::vector<double>> by_machine;  // [machine][commit]
  };
  std::vector<Line> lines;  // by metric_rank, then metric name, then entry
};

std::size_t index_of(std::vector<std::string>& v, const std::string& s) {
  auto it = std::find(v.begin(), v.end(), s);
  if (it != v.end()) return static_cast<std::size_t>(it - v.begin());
  v.push_back(s);
  return v.size() - 1;
}

void check_glob(const std::string& what, const std::string& glob) {
  if (glob.empty()) return;
  if (glob.find_first_of(" \t\n") != std::string::npos)
    throw HistoryError(what + " expects a glob without blanks such as \"*.convergence_rate\", got \"" + glob + "\"");
}

/// Where a metric comes in the table and the page: rates (convergence,
/// genuine answers) and instructions per solve first, then iterations, then
/// counts of failures, timing last; then by name. Read off the metric's
/// declaration (its unit), not its spelling.
const Metric* declared_metric(const std::string& m) {
  for (const StudyKind& k : study_kinds())
    if (const Metric* d = find_metric(k.metrics(), m)) return d;
  return nullptr;
}

int metric_rank(const std::string& m) {
  const auto has = [&](const char* part) { return m.find(part) != std::string::npos; };
  const Metric* d = declared_metric(m);
  const std::string unit = d && d->unit ? d->unit : "";
  if (d && !d->timing && unit == "fraction" && d->better == Better::Higher) return 0;
  if (has(kInstructionsMetric)) return 1;
  if (unit == key::iterations) return 2;
  if (d && unit == "count" && d->guard.level == DefaultGuard::Fail && d->better == Better::Lower) return 3;
  if (m.rfind("derivatives.", 0) == 0) return 4;
  if (m.rfind("baselines.", 0) == 0) return 5;
  if (m.rfind("timing.", 0) == 0) return 7;
  if (has(".time.")) return 6;
  return 5;
}

std::vector<Trend> gather(const std::vector<json>& records, const HistoryFilter& f) {
  check_glob("--metric", f.metric);
  check_glob("--pair", f.pair);
  std::vector<Trend> out;
  std::map<std::string, std::size_t> at;
  // (series, entry, metric) -> machine -> commit -> value
  std::vector<std::map<std::pair<std::string, std::string>, std::map<std::size_t, std::map<std::size_t, double>>>> vals;
  for (const json& r : records) {
    const std::string key = r.at("series").get<std::string>();
    auto it = at.find(key);
    if (it == at.end()) {
      it = at.emplace(key, out.size()).first;
      out.push_back({});
      out.back().key = key;
      vals.emplace_back();
    }
    Trend& t = out[it->second];
    t.identity = r.at("scene");
    ++t.runs;
    const json& run = r.at("run");
    const std::string rev = str_or(run, "git_revision", "unknown") + (run.value("git_dirty", false) ? "+dirty" : "");
    const std::size_t c = index_of(t.commits, rev);
    if (t.commit_labels.size() < t.commits.size()) {
      t.commit_labels.push_back(rev.substr(0, 7) + (run.value("git_dirty", false) ? "+" : ""));
      t.dates.push_back(str_or(run, "date_utc"));
    }
    const std::size_t m = index_of(t.machines, str_or(run, "machine"));
    t.guards.clear();
    for (const json& g : r.at("guards")) t.guards.push_back(guard_from_json(g));
    for (const auto& [entry, metrics] : r.at("entries").items()) {
      if (!f.pair.empty() && fnmatch(f.pair.c_str(), entry.c_str(), 0) != 0) continue;
      for (const auto& [metric, v] : metrics.items()) {
        if (!f.metric.empty() && fnmatch(f.metric.c_str(), metric.c_str(), 0) != 0) continue;
        vals[it->second][{metric, entry}][m][c] = v.is_number() ? v.get<double>() : NAN;
      }
    }
  }
  for (std::size_t s = 0; s < out.size(); ++s) {
    Trend& t = out[s];
    for (const auto& [me, by] : vals[s]) {
      Trend::Line l{me.second, me.first, std::vector<std::vector<double>>(t.machines.size(), std::vector<double>(t.commits.size(), NAN))};
      bool any = false;
      for (const auto& [m, byc] : by)
        for (const auto& [c, v] : byc) {
          l.by_machine[m][c] = v;
          any = any || std::isfinite(v);
        }
      if (any) t.lines.push_back(std::move(l));
    }
    std::stable_sort(t.lines.begin(), t.lines.end(), [](const Trend::Line& a, const Trend::Line& b) {
      return metric_rank(a.metric) < metric_rank(b.metric);
    });
  }
  return out;
}

std::string unit_of(const Trend& t, const std::string& metric) {
  if (metric.size() > std::string(kInstructionsMetric).size() &&
      metric.compare(metric.size() - std::string(kInstructionsMetric).size(), std::string::npos, kInstructionsMetric) == 0)
    return "instructions";
  if (const StudyKind* k = study_kind_named(str_or(t.identity, "kind", "")))
    if (const Metric* m = find_metric(k->metrics(), metric)) return m->unit;
  return "";
}

/// A wall-clock figure (the metric's declaration says so): its steps on a
/// shared machine are as likely load as code.
bool is_timing(const Trend& t, const std::string& metric) {
  if (const StudyKind* k = study_kind_named(str_or(t.identity, "kind", "")))
    if (const Metric* m = find_metric(k->metrics(), metric)) return m->timing;
  return false;
}

Guard guard_of(const Trend& t, const std::string& metric) {
  if (const Guard* g = first_match(t.guards, metric)) return *g;
  Guard none;
  none.pattern = "*";
  none.fail = false;
  none.origin = "none";
  return none;
}

std::string number(double v) {
  if (!std::isfinite(v)) return "-";
  return format("%.6g", v);
}

std::string series_heading(const Trend& t) {
  const std::size_t n = t.identity.contains("entries") ? t.identity.at("entries").size() : 0;
  const StudyKind* k = study_kind_named(str_or(t.identity, "kind", ""));
  // The key and the scene's name as a results file gave them (edited by hand, they may hold a newline).
  return format("series %s: scene \"%s\" (%s, %zu %s%s), %zu run%s over %zu commit%s on %zu machine%s", escaped(t.key).c_str(),
                escaped(str_or(t.identity, "scene", "")).c_str(), escaped(str_or(t.identity, "kind", "")).c_str(), n, k ? k->entry_word : "entries",
                n == 1 || !k ? "" : "s", t.runs, t.runs == 1 ? "" : "s", t.commits.size(), t.commits.size() == 1 ? "" : "s",
                t.machines.size(), t.machines.size() == 1 ? "" : "s");
}

std::string step_text(const HistoryStep& s, const std::string& commit) {
  return commit + " " + (s.better ? "better" : "worse") + " (" + number(s.before) + " -> " + number(s.after) + ")";
}

}  // namespace

std::string history_table(const std::vector<json>& records, const HistoryFilter& f) {
  std::string out;
  // Every name in the table is text from results files, shown escaped (io/text.hpp).
  for (const Trend& t : gather(records, f)) {
    out += series_heading(t) + "\n";
    for (std::size_t m = 0; m < t.machines.size(); ++m)
      out += format("  machine %c: %s\n", static_cast<char>('A' + m % 26), escaped(t.machines[m]).c_str());
    if (t.lines.empty()) {
      out += "  (no metric matches the filter)\n\n";
      continue;
    }
    std::size_t we = 4, wm = 6;
    for (const Trend::Line& l : t.lines) {
      we = std::max(we, escaped(l.entry).size());
      wm = std::max(wm, escaped(l.metric).size());
    }
    // Only the commits where a row shown has a value (a filter to one
    // machine's metrics leaves out the other machines' commits).
    std::vector<bool> col(t.commits.size(), false);
    for (const Trend::Line& l : t.lines)
      for (const auto& v : l.by_machine)
        for (std::size_t c = 0; c < v.size(); ++c) col[c] = col[c] || std::isfinite(v[c]);
    out += format("  %-*s  %-*s  %-12s  m", static_cast<int>(we), "pair", static_cast<int>(wm), "metric", "unit");
    for (std::size_t c = 0; c < t.commits.size(); ++c)
      if (col[c]) out += format("  %11s", escaped(t.commit_labels[c]).c_str());
    out += "  steps\n";
    for (const Trend::Line& l : t.lines) {
      const Guard g = guard_of(t, l.metric);
      for (std::size_t m = 0; m < l.by_machine.size(); ++m) {
        const auto& v = l.by_machine[m];
        if (std::none_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); })) continue;
        out += format("  %-*s  %-*s  %-12s  %c", static_cast<int>(we), escaped(l.entry).c_str(), static_cast<int>(wm),
                      escaped(l.metric).c_str(), unit_of(t, l.metric).c_str(), static_cast<char>('A' + m % 26));
        for (std::size_t c = 0; c < v.size(); ++c)
          if (col[c]) out += format("  %11s", number(v[c]).c_str());
        std::string steps;
        for (const HistoryStep& s : find_steps(v, g))
          steps += (steps.empty() ? "" : "; ") + step_text(s, escaped(t.commit_labels[s.index]));
        if (!steps.empty() && is_timing(t, l.metric)) steps += " [timing]";
        out += "  " + (steps.empty() ? std::string("-") : steps) + "\n";
      }
    }
    out += "\n";
  }
  if (out.empty()) out = "the history holds no run\n";
  return out;
}

namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

const char* const kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#17becf"};
constexpr const char* kWorse = "#d62728";
constexpr const char* kBetter = "#2ca02c";

/// Tick positions 1, 2 or 5 times a power of ten covering [lo, hi], and the
/// decimals that tell them apart.
struct Ticks {
  double lo, hi, step;
  int decimals;
  bool sci;
};

Ticks ticks_for(double lo, double hi) {
  // A spread below a part in 10^9 is rounding: drawn as a flat line (and
  // ticks finer than the values' spacing in binary could not be stepped).
  if (hi - lo <= 1e-9 * std::max(std::abs(lo), std::abs(hi))) {
    lo = hi = 0.5 * (lo + hi);
    const double pad = lo != 0.0 ? std::abs(lo) * 0.01 : 1.0;
    lo -= pad;
    hi += pad;
  }
  const double raw = (hi - lo) / 4.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double step = (norm <= 1.0 ? 1.0 : norm <= 2.0 ? 2.0 : norm <= 5.0 ? 5.0 : 10.0) * mag;
  Ticks t{std::floor(lo / step) * step, std::ceil(hi / step) * step, step, 0, false};
  t.decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  t.sci = t.decimals > 6 || std::max(std::abs(t.lo), std::abs(t.hi)) >= 1e7;
  return t;
}

std::string tick_label(const Ticks& t, double v) {
  if (std::abs(v) < t.step * 1e-9) v = 0.0;
  return t.sci ? format("%.3g", v) : format("%.*f", t.decimals, v);
}

std::string y_title(const std::string& metric, const std::string& unit) {
  if (unit == "fraction") return metric + " (fraction of solves)";
  if (unit == "1") return metric + " (dimensionless)";
  if (unit == "instructions") return metric + " (instructions)";
  if (unit == "us") return metric + " (µs)";
  return metric + (unit.empty() ? "" : " (" + unit + ")");
}

/// One plot: the values of each machine over the commits, steps marked.
std::string svg_plot(const Trend& t, const Trend::Line& l, std::vector<std::pair<std::size_t, std::vector<HistoryStep>>>& steps_out) {
  const Guard g = guard_of(t, l.metric);
  const std::string unit = unit_of(t, l.metric);
  std::vector<std::size_t> shown;  // machines with a value
  for (std::size_t m = 0; m < l.by_machine.size(); ++m)
    if (std::any_of(l.by_machine[m].begin(), l.by_machine[m].end(), [](double x) { return std::isfinite(x); })) shown.push_back(m);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t m : shown)
    for (double x : l.by_machine[m])
      if (std::isfinite(x)) {
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
  const Ticks tk = ticks_for(lo, hi);
  const std::size_t n = t.commits.size();
  const double W = 600, left = 84, right = 14, top = 26, ph = 170;
  const double pw = W - left - right;
  std::size_t label_chars = 4;
  for (const std::string& c : t.commit_labels) label_chars = std::max(label_chars, c.size());
  const double label_h = 7.0 * static_cast<double>(label_chars) + 10;
  const double legend_top = top + ph + 8 + label_h + 30;
  const double H = legend_top + 16.0 * static_cast<double>(shown.size()) + 6;
  const auto X = [&](std::size_t c) { return left + (static_cast<double>(c) + 0.5) * pw / static_cast<double>(n); };
  const auto Y = [&](double v) { return top + ph - (v - tk.lo) / (tk.hi - tk.lo) * ph; };

  std::string s = format("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" role=\"img\">", W, H, W, H);
  s += "<title>" + esc(l.metric + " of " + l.entry) + "</title>";
  s += format("<text x=\"%.1f\" y=\"16\" class=\"t\">%s — %s</text>", left, esc(l.entry).c_str(), esc(l.metric).c_str());
  // Grid and y ticks.
  const int nticks = static_cast<int>(std::lround((tk.hi - tk.lo) / tk.step));
  for (int i = 0; i <= nticks && i <= 20; ++i) {
    const double v = tk.lo + i * tk.step;
    const double y = Y(v);
    s += format("<path d=\"M%.1f %.1fH%.1f\" class=\"g\"/>", left, y, left + pw);
    s += format("<text x=\"%.1f\" y=\"%.1f\" class=\"yt\">%s</text>", left - 5, y + 4, esc(tick_label(tk, v)).c_str());
  }
  // Axes.
  s += format("<path d=\"M%.1f %.1fV%.1fH%.1f\" class=\"ax\"/>", left, top, top + ph, left + pw);
  s += format("<text transform=\"translate(14 %.1f) rotate(-90)\" class=\"at\">%s</text>", top + ph / 2, esc(y_title(l.metric, unit)).c_str());
  // Commit labels: every k-th, so that rotated labels (about 13 px across)
  // never overlap; the newest is always labelled.
  const double spacing = pw / static_cast<double>(n);
  const std::size_t every = static_cast<std::size_t>(std::ceil(13.0 / spacing));
  for (std::size_t c = 0; c < n; ++c) {
    if ((n - 1 - c) % every != 0) continue;
    s += format("<path d=\"M%.1f %.1fv4\" class=\"ax\"/>", X(c), top + ph);
    s += format("<text transform=\"translate(%.1f %.1f) rotate(-90)\" class=\"xt\">%s</text>", X(c) + 4, top + ph + 8,
                esc(t.commit_labels[c]).c_str());
  }
  s += format("<text x=\"%.1f\" y=\"%.1f\" class=\"at\" text-anchor=\"middle\">commit (oldest left)</text>", left + pw / 2, top + ph + 8 + label_h + 16);
  // Steps: a dashed line at the commit from which the metric stays beyond its guard.
  for (std::size_t i = 0; i < shown.size(); ++i) {
    const std::size_t m = shown[i];
    std::vector<HistoryStep> st = find_steps(l.by_machine[m], g);
    for (const HistoryStep& h : st)
      s += format("<path d=\"M%.1f %.1fV%.1f\" class=\"st\" stroke=\"%s\"><title>%s</title></path>", X(h.index), top, top + ph,
                  h.better ? kBetter : kWorse, esc(step_text(h, t.commit_labels[h.index])).c_str());
    steps_out.emplace_back(m, std::move(st));
  }
  // The machines' lines and points.
  for (std::size_t i = 0; i < shown.size(); ++i) {
    const std::size_t m = shown[i];
    const char* colour = kColours[m % (sizeof kColours / sizeof *kColours)];
    const auto& v = l.by_machine[m];
    std::string d;
    bool pen = false;
    // A machine's line runs through the commits it did not run.
    for (std::size_t c = 0; c < n; ++c) {
      if (!std::isfinite(v[c])) continue;
      d += format("%s%.1f %.1f", pen ? "L" : "M", X(c), Y(v[c]));
      pen = true;
    }
    s += format("<path d=\"%s\" class=\"ln\" stroke=\"%s\"/>", d.c_str(), colour);
    for (std::size_t c = 0; c < n; ++c)
      if (std::isfinite(v[c]))
        s += format("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"><title>%s: %s</title></circle>", X(c), Y(v[c]), colour,
                    esc(t.commit_labels[c]).c_str(), esc(number(v[c])).c_str());
    // Legend below the axes.
    const double y = legend_top + 16.0 * static_cast<double>(i);
    s += format("<path d=\"M%.1f %.1fh18\" class=\"ln\" stroke=\"%s\"/><circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>", left, y - 4,
                colour, left + 9, y - 4, colour);
    std::string label = t.machines[m];
    if (label.size() > 84) label = label.substr(0, 81) + "...";
    s += format("<text x=\"%.1f\" y=\"%.1f\" class=\"lg\">%s</text>", left + 24, y, esc(label).c_str());
  }
  s += "</svg>";
  return s;
}

constexpr const char* kStyle =
    "body{font-family:sans-serif;margin:1.5em;color:#222}h1{font-size:1.4em}h2{font-size:1.2em;margin-top:2em}"
    "h3{font-size:1.05em;margin:1.5em 0 .3em}table{border-collapse:collapse;font-size:.85em}"
    "td,th{border:1px solid #ccc;padding:2px 6px;text-align:left}td.n{text-align:right;font-family:monospace}"
    ".plots{display:flex;flex-wrap:wrap;gap:8px}figure{margin:0;border:1px solid #ddd;padding:4px}"
    "figcaption{font-size:.8em;max-width:600px}.worse{color:#d62728}.better{color:#2ca02c}"
    "svg text{font-family:sans-serif;font-size:11px;fill:#222}svg .t{font-size:12px;font-weight:bold}"
    "svg .yt{text-anchor:end}svg .xt{text-anchor:end;font-family:monospace}svg .at{text-anchor:middle}"
    "svg .g{stroke:#e4e4e4;fill:none}svg .ax{stroke:#444;fill:none}svg .ln{fill:none;stroke-width:1.5}"
    "svg .st{stroke-dasharray:4 3;stroke-width:1.5;fill:none}";

}  // namespace

std::string history_html(const std::vector<json>& records, const HistoryFilter& f, std::size_t* plots) {
  const std::vector<Trend> trends = gather(records, f);
  std::string body;
  std::size_t count = 0;
  for (std::size_t si = 0; si < trends.size(); ++si) {
    const Trend& t = trends[si];
    body += "<section class=\"series\"><h2>" + esc(series_heading(t)) + "</h2>";
    body += "<details><summary>scene identity (what every run of this series shares)</summary><pre>" + esc(t.identity.dump(1)) +
            "</pre></details>";
    body += "<table><tr><th>#</th><th>commit</th><th>first run made (UTC)</th></tr>";
    for (std::size_t c = 0; c < t.commits.size(); ++c)
      body += format("<tr><td class=\"n\">%zu</td><td><code>%s</code></td><td>%s</td></tr>", c + 1, esc(t.commits[c]).c_str(), esc(t.dates[c]).c_str());
    body += "</table>";
    std::string figs, step_rows, timing_rows, current;
    for (const Trend::Line& l : t.lines) {
      if (l.metric != current) {
        figs += (current.empty() ? "" : "</div>") + std::string("<h3>") + esc(y_title(l.metric, unit_of(t, l.metric))) + "</h3><div class=\"plots\">";
        current = l.metric;
      }
      const std::string id = format("s%zu-p%zu", si, count);
      std::vector<std::pair<std::size_t, std::vector<HistoryStep>>> steps;
      const std::string svg = svg_plot(t, l, steps);
      std::string caption;
      for (const auto& [m, st] : steps)
        for (const HistoryStep& h : st) {
          const std::string what = step_text(h, t.commit_labels[h.index]);
          caption += format("<span class=\"%s\">step at %s</span>%s. ", h.better ? "better" : "worse", esc(what).c_str(),
                            t.machines.size() > 1 ? (" on " + esc(t.machines[m])).c_str() : "");
          (is_timing(t, l.metric) ? timing_rows : step_rows) += format("<tr><td><a href=\"#%s\">%s</a></td><td>%s</td><td><code>%s</code></td><td class=\"n\">%s</td><td class=\"n\">%s</td>"
                              "<td class=\"%s\">%s</td><td>%s</td></tr>",
                              id.c_str(), esc(l.metric).c_str(), esc(l.entry).c_str(), esc(t.commit_labels[h.index]).c_str(),
                              esc(number(h.before)).c_str(), esc(number(h.after)).c_str(), h.better ? "better" : "worse",
                              h.better ? "better" : "worse", esc(t.machines[m]).c_str());
        }
      const Guard g = guard_of(t, l.metric);
      caption += esc("guard " + g.pattern + format(": abs %g, rel %g, %s is better", g.abs, g.rel, g.higher_is_better ? "higher" : "lower"));
      figs += "<figure id=\"" + id + "\">" + svg + "<figcaption>" + caption + "</figcaption></figure>";
      ++count;
    }
    if (!current.empty()) figs += "</div>";
    body += "<h3>Steps beyond the guards</h3>";
    const std::string head = "<table><tr><th>metric</th><th>pair</th><th>from commit</th><th>before</th><th>after</th><th></th><th>machine</th></tr>";
    body += step_rows.empty() ? "<p>None: every metric stayed within its guard of its previous value.</p>" : head + step_rows + "</table>";
    if (!timing_rows.empty())
      body += "<p>Steps of wall-clock figures (load on a shared machine moves them as much as code does):</p>" + head + timing_rows + "</table>";
    body += figs + "</section>";
  }
  if (plots) *plots = count;
  std::string filter;
  if (!f.metric.empty()) filter += " metric " + f.metric;
  if (!f.pair.empty()) filter += " pair " + f.pair;
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>idcol history</title><style>" + std::string(kStyle) +
         "</style></head><body><h1>How each guarded metric moved over commits</h1><p>" +
         esc(format("%zu runs in %zu series, %zu plots%s. ", records.size(), trends.size(), count,
                    filter.empty() ? "" : (", filtered:" + filter).c_str())) +
         "A step (dashed line) marks the first commit after which a metric stays beyond its guard around the value before it; "
         "green: better, red: worse. Runs of scenes that cannot be compared are separate series.</p>" +
         body + "</body></html>\n";
}

}  // namespace idcol::harness
