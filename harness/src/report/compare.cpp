#include "report/compare.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "studies/results_file.hpp"
#include "studies/study.hpp"
#include "io/files.hpp"
#include "scene/scene_toml.hpp"

namespace idcol::harness {

using nlohmann::json;

std::vector<Guard> guards_in_force(const std::vector<Guard>& file_guards) {
  std::vector<Guard> all = file_guards;
  for (Guard& g : default_guards()) all.push_back(std::move(g));
  return all;
}

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
      if (key != "metric" && key != "better" && key != "abs" && key != "rel" && key != "fail" && key != "why" && key != "replace")
        throw CompareError(where + "." + key + ": unknown key (expected metric, better, abs, rel, fail, replace, why)");
    }
    Guard gd;
    auto metric = (*g)["metric"].value<std::string>();
    auto better = (*g)["better"].value<std::string>();
    if (!metric) throw CompareError(where + ".metric: missing; expected a glob such as \"*.convergence_rate\"");
    if (!better || (*better != "higher" && *better != "lower" && *better != "same"))
      throw CompareError(where + ".better: expected \"higher\", \"lower\" or \"same\"");
    gd.pattern = *metric;
    gd.origin = where;
    gd.higher_is_better = *better == "higher";
    gd.same = *better == "same";
    gd.abs = (*g)["abs"].value<double>().value_or(0.0);
    gd.rel = (*g)["rel"].value<double>().value_or(0.0);
    gd.fail = (*g)["fail"].value<bool>().value_or(true);
    if ((*g).contains("replace") && !(*g)["replace"].is_boolean()) throw CompareError(where + ".replace: expected true or false");
    gd.replace = (*g)["replace"].value<bool>().value_or(false);
    if (!(gd.abs >= 0.0) || !(gd.rel >= 0.0)) throw CompareError(where + ": abs and rel must be >= 0");
    out.push_back(gd);
  }
  return out;
}

namespace {
/// The default guard a metric declares, as a guard matching its name.
Guard declared_guard(const Metric& m, const std::string& pattern) {
  Guard d;
  d.pattern = pattern;
  d.higher_is_better = m.better == Better::Higher;
  d.same = m.better == Better::Neither;
  d.abs = m.guard.abs;
  d.rel = m.guard.rel;
  d.fail = m.guard.level == DefaultGuard::Fail;
  d.origin = "default guard";
  return d;
}
}  // namespace

std::vector<Guard> default_guards() {
  // Read off the declared metrics: one guard for each metric whose default
  // guard is not informational, its pattern the group's prefix with "*"
  // for the member ("*.convergence_rate", "baselines.*.genuine",
  // "timing.*/fcl_collide"), once however many kinds declare it.
  std::vector<Guard> g;
  for (const StudyKind& k : study_kinds())
    for (const MetricGroup& grp : k.metrics().groups)
      for (const Metric& m : grp.metrics) {
        if (m.guard.level == DefaultGuard::Info) continue;
        std::string pattern = grp.prefix;
        const std::size_t at = pattern.find("{key}");
        if (at != std::string::npos) pattern.replace(at, 5, "*");
        pattern += m.name;
        if (std::any_of(g.begin(), g.end(), [&](const Guard& x) { return x.pattern == pattern; })) continue;
        g.push_back(declared_guard(m, pattern));
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

/// The kind of a results file, after the check every reader makes
/// (studies/results_file.hpp); a file that fails it is bad input.
const StudyKind& kind_of(const json& r, const char* which) {
  try {
    return check_results(r, which);
  } catch (const FileError& e) {
    throw CompareError(e.what());
  }
}

/// Every leaf under `path` (an object member by member), as JSON text;
/// "absent" where the file has no such member.
void leaves(const json* j, const std::string& path, std::map<std::string, std::string>& out) {
  if (!j) {
    out[path] = "absent";
    return;
  }
  if (j->is_object() && !j->empty()) {
    for (const auto& [k, v] : j->items()) leaves(&v, path + "." + k, out);
    return;
  }
  out[path] = j->dump();
}

std::string shortened(const std::string& s) { return s.size() <= 70 ? s : s.substr(0, 60) + "...(" + std::to_string(s.size()) + " chars)"; }

/// "made DATE at git REV" from a results file's metadata ("" without).
std::string made(const json& r) {
  const json* m = at_path(r, "metadata");
  if (!m || !m->is_object()) return "";
  const auto str = [&](const char* key) {
    return m->contains(key) && (*m)[key].is_string() ? (*m)[key].get<std::string>() : std::string();
  };
  std::string s;
  if (!str("date_utc").empty()) s += "made " + str("date_utc");
  if (!str("git_revision").empty()) s += (s.empty() ? "" : ", ") + std::string("git ") + str("git_revision").substr(0, 12);
  return s;
}

/// Every compared entry of a results file, keyed as the report names it.
std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> entries(const json& r, const StudyKind& k) {
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> out;
  for (const json& e : r.at(k.entries)) out.emplace_back(k.entry_key(r, e), entry_metrics(k.metrics(), e));
  return out;
}

const Guard* first_match(const std::vector<Guard>& gs, const std::string& metric) {
  for (const Guard& g : gs)
    if (fnmatch(g.pattern.c_str(), metric.c_str(), 0) == 0) return &g;
  return nullptr;
}

/// f allows something d does not: a worse figure, a WARN for a FAIL, or
/// the other direction.
bool looser(const Guard& f, const Guard& d) {
  return (d.fail && !f.fail) || f.abs > d.abs || f.rel > d.rel || (d.same && !f.same) ||
         (!d.same && !f.same && d.higher_is_better != f.higher_is_better);
}

int rank(const std::string& v) {
  static const char* order[] = {"same", "better", "info", "new", "missing", "worse", "WARN", "FAIL"};
  for (int i = 0; i < 8; ++i)
    if (v == order[i]) return i;
  return 0;
}

/// The verdict of one guard on a change from ov to nv (both numbers).
std::string judge(const Guard& g, double ov, double nv) {
  const double worse = g.same ? std::abs(nv - ov) : g.higher_is_better ? ov - nv : nv - ov;
  const double allowed = std::max(g.abs, g.rel * std::abs(ov));
  // Below a part in 10^9 of the value, a change is rounding, not a trend.
  const double noise = 1e-9 * std::max(std::abs(ov), std::abs(nv));
  if (worse > allowed) return g.fail ? "FAIL" : "WARN";
  if (worse > noise) return "worse";
  if (worse < -noise) return "better";
  return "same";
}

}  // namespace

std::vector<std::string> run_mismatches(const json& o, const json& n) {
  const StudyKind& k = kind_of(o, "OLD");
  const StudyKind& kn = kind_of(n, "NEW");
  if (&kn != &k)
    return {std::string("study kind (schema): OLD ") + k.schema + " (" + k.name + "), NEW " + kn.schema + " (" + kn.name + ")"};
  const StudyKind::RunIdentity& id = k.identity;  // what makes two runs the same run
  std::vector<std::string> out;
  for (const char* path : id.top) {
    std::map<std::string, std::string> lo, ln;
    leaves(at_path(o, path), path, lo);
    leaves(at_path(n, path), path, ln);
    for (auto* side : {&lo, &ln})
      for (auto& [p, v] : *side)
        if (v == "absent" && id.absent_means.count(p)) v = id.absent_means.at(p);
    for (const auto& [p, v] : lo) {
      const auto it = ln.find(p);
      const std::string nv = it == ln.end() ? "absent" : it->second;
      if (nv != v) out.push_back(p + ": OLD " + shortened(v) + ", NEW " + shortened(nv));
    }
    for (const auto& [p, v] : ln)
      if (!lo.count(p)) out.push_back(p + ": OLD absent, NEW " + shortened(v));
  }
  // Per entry: each field that differs once, with the entries it differs in.
  std::map<std::string, const json*> by_key;
  for (const json& e : n.at(k.entries))
    if (e.is_object()) by_key[k.entry_key(n, e)] = &e;
  std::map<std::string, std::vector<std::string>> where;  // "field: OLD a, NEW b" -> entries
  std::vector<std::string> order;
  std::size_t shared = 0;
  for (const json& e : o.at(k.entries)) {
    if (!e.is_object()) continue;
    const std::string key = k.entry_key(o, e);
    const auto it = by_key.find(key);
    if (it == by_key.end()) continue;
    ++shared;
    for (const char* f : id.entry) {
      std::map<std::string, std::string> lo, ln;
      leaves(at_path(e, f), f, lo);
      leaves(at_path(*it->second, f), f, ln);
      for (const auto& [p, v] : ln)
        if (!lo.count(p)) lo[p] = "absent";
      for (const auto& [p, v] : lo) {
        const auto jt = ln.find(p);
        const std::string nv = jt == ln.end() ? "absent" : jt->second;
        if (nv == v) continue;
        const std::string line = p + ": OLD " + shortened(v) + ", NEW " + shortened(nv);
        if (!where.count(line)) order.push_back(line);
        where[line].push_back(key);
      }
    }
  }
  for (const std::string& line : order) {
    const auto& keys = where[line];
    std::string in;
    if (keys.size() == shared && shared > 1) in = "every " + std::string(k.entry_word) + " (" + std::to_string(shared) + ")";
    else {
      for (std::size_t i = 0; i < keys.size() && i < 4; ++i) in += (i ? ", " : "") + keys[i];
      if (keys.size() > 4) in += " and " + std::to_string(keys.size() - 4) + " more";
    }
    out.push_back(line + " (" + in + ")");
  }
  return out;
}

CompareReport compare_results(const json& o, const json& n, const std::vector<Guard>& guards, bool common_only) {
  CompareOptions opt;
  opt.guards = guards;
  opt.common_only = common_only;
  return compare_results(o, n, opt);
}

CompareReport compare_results(const json& o, const json& n, const CompareOptions& opt) try {
  const StudyKind& k = kind_of(o, "OLD");
  const StudyKind& kn = kind_of(n, "NEW");
  if (&kn != &k)
    throw CompareMismatch("OLD is a " + std::string(k.noun) + " results file but NEW is a " + kn.noun +
                              " results file: compare two files of the same kind",
                          run_mismatches(o, n));
  CompareReport rep;
  rep.mismatches = run_mismatches(o, n);
  if (!rep.mismatches.empty() && !opt.allow_mismatch) {
    std::string what = "OLD and NEW are not runs of the same thing; they differ in";
    for (const std::string& m : rep.mismatches) what += "\n  " + m;
    what += "\n(--allow-mismatch compares them anyway)";
    throw CompareMismatch(what, rep.mismatches);
  }
  rep.old_made = made(o);
  rep.new_made = made(n);
  {
    const json* od = at_path(o, "metadata.date_utc");
    const json* nd = at_path(n, "metadata.date_utc");
    if (od && nd && od->is_string() && nd->is_string() && od->get<std::string>() > nd->get<std::string>())
      rep.notes.push_back("OLD (" + od->get<std::string>() + ") was made after NEW (" + nd->get<std::string>() +
                          "): are OLD and NEW in that order on the command line?");
  }
  std::set<std::string> loose_noted;
  const std::string word = k.entry_word;
  std::map<std::string, std::vector<std::pair<std::string, double>>> newp;
  for (auto& [key, m] : entries(n, k)) newp[key] = std::move(m);
  std::map<std::string, bool> seen;
  for (const auto& [key, om] : entries(o, k)) {
    seen[key] = true;
    auto it = newp.find(key);
    if (it == newp.end()) {
      if (!opt.common_only) throw CompareError(word + " " + key + " is in OLD but missing from NEW (--common-pairs compares the shared ones)");
      rep.notes.push_back(word + " " + key + " is only in OLD: not compared");
      continue;
    }
    std::map<std::string, double> nmap(it->second.begin(), it->second.end());
    for (const auto& [metric, ov] : om) {
      const Metric* declared = find_metric(k.metrics(), metric);
      CompareRow row{key, metric, declared ? declared->unit : "", ov, NAN, "", false, ""};
      // The guards that apply: the default's and the thresholds file's, or
      // the file's alone where it says replace = true.
      std::vector<const Guard*> gs;
      // The default is the metric's own declaration in its kind's table.
      std::optional<Guard> own;
      if (opt.defaults && declared && declared->guard.level != DefaultGuard::Info) own = declared_guard(*declared, metric);
      const Guard* d = own ? &*own : nullptr;
      const Guard* f = first_match(opt.guards, metric);
      if (f && f->replace) gs = {f};
      else {
        if (d) gs.push_back(d);
        if (f) gs.push_back(f);
        if (d && f && looser(*f, *d) && loose_noted.insert(f->origin + "|" + declared->name).second)
          rep.notes.push_back(f->origin + " (metric = \"" + f->pattern + "\") is looser than the default guard of " + metric +
                              " (abs " + format("%g", d->abs) + ", rel " + format("%g", d->rel) + (d->fail ? ", fails" : ", warns") +
                              "), which still applies (replace = true replaces it)");
      }
      row.guarded = !gs.empty();
      for (const Guard* g : gs) row.guards += (row.guards.empty() ? "" : "; ") + g->origin;
      auto nv = nmap.find(metric);
      row.new_value = nv == nmap.end() ? NAN : nv->second;
      if (std::isnan(ov) && std::isnan(row.new_value)) row.verdict = "same";
      else if (std::isnan(row.new_value))
        // A figure that vanishes (missing, null, NaN) from NEW cannot pass:
        // any guarded figure, and any count, fails.
        row.verdict = row.guarded || row.unit == "count" ? "FAIL" : "missing";
      else if (std::isnan(ov)) row.verdict = "new";
      else if (gs.empty()) row.verdict = row.new_value == ov ? "same" : "info";
      else {
        row.verdict = "same";
        for (const Guard* g : gs) {
          const std::string v = judge(*g, ov, row.new_value);
          if (rank(v) > rank(row.verdict)) row.verdict = v;
        }
      }
      if (row.verdict == "FAIL") ++rep.failed;
      if (row.verdict == "WARN") ++rep.warned;
      rep.rows.push_back(row);
    }
  }
  for (const auto& [key, m] : newp)
    if (!seen.count(key)) {
      if (!opt.common_only) throw CompareError(word + " " + key + " is in NEW but missing from OLD (--common-pairs compares the shared ones)");
      rep.notes.push_back(word + " " + key + " is only in NEW: not compared");
    }
  if (rep.rows.empty()) throw CompareError("OLD and NEW share no " + word + ": nothing to compare");
  // One thresholds file serves every kind of results file, so a guard may
  // match nothing here; but it must match some metric compare can produce.
  for (const Guard& g : opt.guards) {
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
} catch (const json::exception& e) {
  // A member of the wrong type where compare reads it: bad input, not a regression.
  throw CompareError(std::string("not a well-formed results file: ") + e.what());
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
  if (!old_made.empty() || !new_made.empty())
    o << "OLD (the reference): " << (old_made.empty() ? "no metadata" : old_made) << "\nNEW (judged against it): "
      << (new_made.empty() ? "no metadata" : new_made) << "\n";
  if (!mismatches.empty()) {
    o << "MISMATCH: OLD and NEW are not runs of the same thing (compared with --allow-mismatch); they differ in\n";
    for (const auto& m : mismatches) o << "  " << m << "\n";
  }
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

json CompareReport::to_json() const {
  const auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json rs = json::array();
  for (const auto& r : rows)
    rs.push_back({{"entry", r.pair}, {"metric", r.metric}, {"unit", r.unit}, {"old", num(r.old_value)}, {"new", num(r.new_value)},
                  {"verdict", r.verdict}, {"guarded", r.guarded}, {"guards", r.guards}});
  std::size_t guarded = 0;
  for (const auto& r : rows) guarded += r.guarded;
  return {{"verdict", failed ? "REGRESSION" : "PASS"},
          {"exit_code", failed ? 1 : 0},
          {"fails", failed},
          {"warned", warned},
          {"compared", rows.size()},
          {"guarded", guarded},
          {"old_made", old_made},
          {"new_made", new_made},
          {"mismatches", mismatches},
          {"notes", notes},
          {"rows", rs}};
}

}  // namespace idcol::harness
