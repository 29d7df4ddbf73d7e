#include "idcol_harness/compare.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "idcol_harness/writers.hpp"

namespace idcol::harness {

using nlohmann::json;

std::vector<Guard> load_guards(const std::string& path) {
  toml::table t;
  try {
    t = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw CompareError(path + ": not a valid TOML file: " + std::string(e.description()));
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
    gd.higher_is_better = *better == "higher";
    gd.abs = (*g)["abs"].value<double>().value_or(0.0);
    gd.rel = (*g)["rel"].value<double>().value_or(0.0);
    gd.fail = (*g)["fail"].value<bool>().value_or(true);
    if (!(gd.abs >= 0.0) || !(gd.rel >= 0.0)) throw CompareError(where + ": abs and rel must be >= 0");
    out.push_back(gd);
  }
  return out;
}

namespace {
double num(const json& j) { return j.is_number() ? j.get<double>() : NAN; }
std::string pair_key(const json& p) { return p.at("body1").get<std::string>() + "-" + p.at("body2").get<std::string>(); }

void check_results(const json& r, const char* which) {
  if (!r.is_object() || !r.contains("schema") || r.at("schema") != kResultsSchema || !r.contains("pairs") ||
      !r.at("pairs").is_array())
    throw CompareError(std::string(which) + ": not an idcol-harness results file (no schema \"" + kResultsSchema +
                       "\" or no pairs)");
}
}  // namespace

std::vector<std::pair<std::string, double>> pair_metrics(const json& p) {
  std::vector<std::pair<std::string, double>> m;
  for (const auto& [name, pass] : p.at("passes").items()) {
    m.emplace_back(name + ".convergence_rate", num(pass.at("convergence_rate")));
    m.emplace_back(name + ".failures", num(pass.at("failures")));
    if (pass.contains("iterations")) {
      m.emplace_back(name + ".iterations.mean", num(pass["iterations"]["mean"]));
      m.emplace_back(name + ".iterations.max", num(pass["iterations"]["max"]));
    }
  }
  if (p.contains("baselines")) {
    const json& b = p["baselines"];
    m.emplace_back("baselines.genuine_total", num(b.at("genuine_total")));
    m.emplace_back("baselines.idcol_outside_bracket", num(b.at("idcol_outside_bracket")));
    m.emplace_back("baselines.oracle_failed", num(b.at("oracle_failed")));
    for (const auto& [name, s] : b.at("status").items())
      for (const char* k : {"genuine", "band", "failed"}) m.emplace_back("baselines." + name + "." + k, num(s.at(k)));
    for (const char* e : {"alpha_abs_err", "alpha_rel_err"})
      for (const char* q : {"mean", "p99", "max"}) m.emplace_back(std::string("baselines.") + e + "." + q, num(b.at(e).at(q)));
    for (const char* q : {"p99", "max"}) m.emplace_back(std::string("baselines.normal_angle_rad.") + q, num(b.at("normal_angle_rad").at(q)));
    const json& tm = b.at("timing").at("methods");
    if (tm.contains("fcl_collide")) {
      const double ref = num(tm["fcl_collide"]["median_ns"]);
      for (const auto& [name, t] : tm.items())
        if (name != "fcl_collide") m.emplace_back("timing." + name + "/fcl_collide", num(t.at("median_ns")) / ref);
    }
  }
  if (p.contains("derivatives")) {
    const json& d = p["derivatives"];
    m.emplace_back("derivatives.agreement", num(d.at("agreement")));
    m.emplace_back("derivatives.disagree_unflagged", num(d.at("disagree_unflagged")));
    m.emplace_back("derivatives.worst_error", num(d.at("worst_error")));
  }
  return m;
}

CompareReport compare_results(const json& o, const json& n, const std::vector<Guard>& guards) {
  check_results(o, "OLD");
  check_results(n, "NEW");
  CompareReport rep;
  if (o.contains("sweep") && n.contains("sweep") && o["sweep"] != n["sweep"])
    rep.notes.push_back("the sweeps differ (poses, generator or solver settings): OLD " + o["sweep"].dump() + ", NEW " +
                        n["sweep"].dump());
  std::map<std::string, const json*> newp;
  for (const auto& p : n.at("pairs")) newp[pair_key(p)] = &p;
  std::map<std::string, bool> seen;
  for (const auto& p : o.at("pairs")) {
    const std::string key = pair_key(p);
    seen[key] = true;
    auto it = newp.find(key);
    if (it == newp.end()) throw CompareError("pair " + key + " is in OLD but missing from NEW");
    const auto om = pair_metrics(p);
    const auto nm = pair_metrics(*it->second);
    std::map<std::string, double> nmap(nm.begin(), nm.end());
    for (const auto& [metric, ov] : om) {
      CompareRow row{key, metric, ov, NAN, ""};
      const Guard* g = nullptr;
      for (const Guard& gd : guards)
        if (fnmatch(gd.pattern.c_str(), metric.c_str(), 0) == 0) {
          g = &gd;
          break;
        }
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
        if (worse > allowed) row.verdict = g->fail ? "FAIL" : "WARN";
        else if (worse > 0) row.verdict = "worse";
        else if (worse < 0) row.verdict = "better";
        else row.verdict = "same";
      }
      if (row.verdict == "FAIL") ++rep.failed;
      if (row.verdict == "WARN") ++rep.warned;
      rep.rows.push_back(row);
    }
  }
  for (const auto& [key, p] : newp)
    if (!seen.count(key)) throw CompareError("pair " + key + " is in NEW but missing from OLD");
  return rep;
}

std::string CompareReport::text() const {
  std::ostringstream o;
  for (const auto& note : notes) o << "note: " << note << "\n";
  std::string cur;
  char buf[512];
  for (const auto& r : rows) {
    if (r.pair != cur) {
      cur = r.pair;
      std::snprintf(buf, sizeof buf, "\n%s\n  %-40s %14s %14s %12s  %s\n", cur.c_str(), "metric", "old", "new", "change", "verdict");
      o << buf;
    }
    std::string change;
    if (std::isnan(r.old_value) || std::isnan(r.new_value)) change = "n/a";
    else if (r.old_value != 0.0) {
      std::snprintf(buf, sizeof buf, "%+.2f%%", 100.0 * (r.new_value - r.old_value) / std::abs(r.old_value));
      change = buf;
    } else {
      std::snprintf(buf, sizeof buf, "%+.4g", r.new_value - r.old_value);
      change = buf;
    }
    std::snprintf(buf, sizeof buf, "  %-40s %14.6g %14.6g %12s  %s%s\n", r.metric.c_str(), r.old_value, r.new_value,
                  change.c_str(), r.verdict.c_str(), r.verdict == "FAIL" ? "  <<<" : "");
    o << buf;
  }
  std::snprintf(buf, sizeof buf, "\n%zu metrics compared: %d FAIL, %d WARN -> %s\n", rows.size(), failed, warned,
                failed ? "REGRESSION" : "PASS");
  o << buf;
  return o.str();
}

}  // namespace idcol::harness
