#include "report/compare.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "study/study.hpp"
#include "io/files.hpp"
#include "scene/scene_toml.hpp"

namespace idcol::harness {

using nlohmann::json;

std::vector<Guard> load_guards(const std::string& path) {
  toml::table t;
  // Through the scene reader's parser, which bounds the nesting before
  // toml++ recurses into it.
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CompareError(path + ": cannot read: " + std::strerror(errno));
  std::stringstream text;
  text << in.rdbuf();
  try {
    t = parse_toml(text.str(), path);
  } catch (const SceneError& e) {
    throw CompareError(std::string("not a valid TOML file: ") + e.what());
  }
  const toml::array* arr = t["guard"].as_array();
  if (!arr) throw CompareError(path + ": expected [[guard]] entries");
  std::vector<Guard> out;
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const std::string where = path + ": guard[" + std::to_string(i) + "]";
    const toml::table* g = arr->get(i)->as_table();
    if (!g) throw CompareError(where + ": expected a table");
    for (const auto& [k, v] : *g) {
      const std::string key(k.str());
      if (key != "metric" && key != "better" && key != "abs" && key != "rel" && key != "fail" && key != "why")
        throw CompareError(where + "." + key + ": unknown key (expected metric, better, abs, rel, fail, why)");
    }
    Guard gd;
    auto metric = (*g)["metric"].value<std::string>();
    auto better = (*g)["better"].value<std::string>();
    if (!metric) throw CompareError(where + ".metric: missing; expected a glob such as \"*.convergence_rate\"");
    if (!better || (*better != "higher" && *better != "lower"))
      throw CompareError(where + ".better: expected \"higher\" or \"lower\"");
    gd.pattern = *metric;
    gd.origin = where;
    gd.higher_is_better = *better == "higher";
    gd.abs = (*g)["abs"].value<double>().value_or(0.0);
    gd.rel = (*g)["rel"].value<double>().value_or(0.0);
    gd.fail = (*g)["fail"].value<bool>().value_or(true);
    if (!(gd.abs >= 0.0) || !(gd.rel >= 0.0)) throw CompareError(where + ": abs and rel must be >= 0");
    out.push_back(gd);
  }
  return out;
}

std::vector<Guard> default_guards() {
  // Read off the declared metrics: one guard "*.<name>" for each metric
  // whose default guard is not informational, once however many kinds
  // declare a metric of that name.
  std::vector<Guard> g;
  for (const StudyKind& k : study_kinds())
    for (const MetricGroup& grp : k.metrics().groups)
      for (const Metric& m : grp.metrics) {
        if (m.guard.level == DefaultGuard::Info) continue;
        const std::string pattern = std::string("*.") + m.name;
        if (std::any_of(g.begin(), g.end(), [&](const Guard& x) { return x.pattern == pattern; })) continue;
        g.push_back({pattern, m.better == Better::Higher, m.guard.abs, m.guard.rel, m.guard.level == DefaultGuard::Fail,
                     "default guard"});
      }
  return g;
}

namespace {

/// A name of every metric compare produces, for representative pass and
/// method names (cold, warm, fcl_collide...): a guard must match one of them
/// or a metric of the files compared.
const std::vector<std::string>& known_metric_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const StudyKind& k : study_kinds())
      for (const auto& [name, value] : entry_metrics(k.metrics(), json::parse(k.full_entry))) {
        v.push_back(name);
        if (name.compare(0, 5, "cold.") == 0) v.push_back("warm" + name.substr(4));
      }
    return v;
  }();
  return names;
}

/// The kind of a results file, by its schema and its array of entries.
const StudyKind& kind_of(const json& r, const char* which) {
  const std::string schema = r.is_object() && r.contains("schema") && r.at("schema").is_string() ? r.at("schema").get<std::string>() : "";
  const StudyKind* k = study_kind_of_schema(schema);
  if (k && r.contains(k->entries) && r.at(k->entries).is_array()) return *k;
  std::string expected;
  for (std::size_t i = 0; i < study_kinds().size(); ++i) {
    const StudyKind& e = study_kinds()[i];
    expected += std::string(i == 0 ? "" : i + 1 == study_kinds().size() ? " or " : ", ") + "\"" + e.schema + "\" with " + e.entries;
  }
  throw CompareError(std::string(which) + ": not a results file of the harness (schema " + expected + "; got schema \"" + schema + "\")");
}

/// Every compared entry of a results file, keyed as the report names it.
std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> entries(const json& r, const StudyKind& k) {
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> out;
  for (const json& e : r.at(k.entries)) out.emplace_back(k.entry_key(r, e), entry_metrics(k.metrics(), e));
  return out;
}
}  // namespace

CompareReport compare_results(const json& o, const json& n, const std::vector<Guard>& guards, bool common_only) {
  const StudyKind& k = kind_of(o, "OLD");
  if (&kind_of(n, "NEW") != &k)
    throw CompareError("OLD is an " + o.at("schema").get<std::string>() + " file but NEW is an " + n.at("schema").get<std::string>() +
                       " file: compare two files of the same kind");
  CompareReport rep;
  for (const char* section : {"sweep", "solver", "thresholds"})
    if (o.contains(section) && n.contains(section) && o[section] != n[section])
      rep.notes.push_back(std::string("the ") + section + " settings differ: OLD " + o[section].dump() + ", NEW " + n[section].dump());
  const std::string word = k.entry_word;
  std::map<std::string, std::vector<std::pair<std::string, double>>> newp;
  for (auto& [key, m] : entries(n, k)) newp[key] = std::move(m);
  std::map<std::string, bool> seen;
  for (const auto& [key, om] : entries(o, k)) {
    seen[key] = true;
    auto it = newp.find(key);
    if (it == newp.end()) {
      if (!common_only) throw CompareError(word + " " + key + " is in OLD but missing from NEW (--common-pairs compares the shared ones)");
      rep.notes.push_back(word + " " + key + " is only in OLD: not compared");
      continue;
    }
    std::map<std::string, double> nmap(it->second.begin(), it->second.end());
    for (const auto& [metric, ov] : om) {
      const Metric* declared = find_metric(k.metrics(), metric);
      CompareRow row{key, metric, declared ? declared->unit : "", ov, NAN, ""};
      const Guard* g = nullptr;
      for (const Guard& gd : guards)
        if (fnmatch(gd.pattern.c_str(), metric.c_str(), 0) == 0) {
          g = &gd;
          break;
        }
      row.guarded = g != nullptr;
      auto nv = nmap.find(metric);
      if (nv == nmap.end()) {
        row.verdict = g && g->fail ? "FAIL" : "missing";
        if (g && g->fail) ++rep.failed;
        rep.rows.push_back(row);
        continue;
      }
      row.new_value = nv->second;
      if (std::isnan(ov) && std::isnan(row.new_value)) row.verdict = "same";
      else if (std::isnan(row.new_value) || std::isnan(ov)) row.verdict = g ? (g->fail ? "FAIL" : "WARN") : "info";
      else if (!g) row.verdict = row.new_value == ov ? "same" : "info";
      else {
        const double worse = g->higher_is_better ? ov - row.new_value : row.new_value - ov;
        const double allowed = std::max(g->abs, g->rel * std::abs(ov));
        // Below a part in 10^9 of the value, a change is rounding, not a trend.
        const double noise = 1e-9 * std::max(std::abs(ov), std::abs(row.new_value));
        if (worse > allowed) row.verdict = g->fail ? "FAIL" : "WARN";
        else if (worse > noise) row.verdict = "worse";
        else if (worse < -noise) row.verdict = "better";
        else row.verdict = "same";
      }
      if (row.verdict == "FAIL") ++rep.failed;
      if (row.verdict == "WARN") ++rep.warned;
      rep.rows.push_back(row);
    }
  }
  for (const auto& [key, m] : newp)
    if (!seen.count(key)) {
      if (!common_only) throw CompareError(word + " " + key + " is in NEW but missing from OLD (--common-pairs compares the shared ones)");
      rep.notes.push_back(word + " " + key + " is only in NEW: not compared");
    }
  if (rep.rows.empty()) throw CompareError("OLD and NEW share no " + word + ": nothing to compare");
  // One thresholds file serves every kind of results file, so a guard may
  // match nothing here; but it must match some metric compare can produce.
  for (const Guard& g : guards) {
    const auto matches = [&](const std::string& m) { return fnmatch(g.pattern.c_str(), m.c_str(), 0) == 0; };
    const std::vector<std::string>& known = known_metric_names();
    if (std::any_of(rep.rows.begin(), rep.rows.end(), [&](const CompareRow& r) { return matches(r.metric); }) ||
        std::any_of(known.begin(), known.end(), matches))
      continue;
    throw CompareError((g.origin.empty() ? std::string("guard") : g.origin) + ": metric = \"" + g.pattern +
                       "\" matches no metric of these files nor any metric name compare produces (such as \"cold.convergence_rate\"); "
                       "a guard that matches nothing guards nothing (names: harness/src/report/compare.hpp)");
  }
  return rep;
}

namespace {
/// The change as a reader wants it: rates in percentage points, counts as a
/// difference, other figures relative, with as many digits as it takes to
/// show a change that is there (never "+0.00%" for a change).
std::string change_text(const CompareRow& r) {
  if (std::isnan(r.old_value) || std::isnan(r.new_value)) return kMissing;
  const double d = r.new_value - r.old_value;
  if (d == 0.0) return "0";
  if (r.unit == "fraction") return format("%+.3g pp", 100.0 * d);
  if (r.old_value == 0.0 || (std::floor(r.old_value) == r.old_value && std::floor(r.new_value) == r.new_value && std::abs(d) < 1e6))
    return format("%+.6g", d);
  const double rel = 100.0 * d / std::abs(r.old_value);
  return std::abs(rel) >= 0.01 ? format("%+.2f%%", rel) : format("%+.2g%%", rel);
}
}  // namespace

std::string CompareReport::text(bool all_rows) const {
  std::ostringstream o;
  for (const auto& note : notes) o << "note: " << note << "\n";
  std::string cur;
  std::size_t shown = 0;
  for (const auto& r : rows) {
    if (!all_rows && r.verdict == "same") continue;
    ++shown;
    if (r.pair != cur) {
      cur = r.pair;
      o << format("\n%s\n  %-40s %14s %14s %12s  %s\n", cur.c_str(), "metric", "old", "new", "change", "verdict");
    }
    o << format("  %-40s %14.6g %14.6g %12s  %s%s\n", r.metric.c_str(), r.old_value, r.new_value, change_text(r).c_str(),
                r.verdict.c_str(), r.verdict == "FAIL" ? "  <<<" : "");
  }
  if (!all_rows && shown == 0) o << "\nno metric changed\n";
  std::size_t guarded = 0;
  for (const auto& r : rows) guarded += r.guarded;
  o << format("\n%zu metrics compared (%zu guarded)%s: %d FAIL, %d WARN -> %s\n", rows.size(), guarded,
              all_rows ? "" : ", only changes shown (--all shows every one)", failed, warned, failed ? "REGRESSION" : "PASS");
  return o.str();
}

}  // namespace idcol::harness
