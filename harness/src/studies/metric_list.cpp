#include "studies/metric_list.hpp"

#include <algorithm>

#include "io/keys.hpp"
#include "io/text.hpp"
#include "studies/study.hpp"

namespace idcol::harness {

using nlohmann::json;

namespace {

std::vector<std::string> split(const std::string& dotted) {
  std::vector<std::string> out;
  std::size_t from = 0;
  for (std::size_t dot; (dot = dotted.find('.', from)) != std::string::npos; from = dot + 1) out.push_back(dotted.substr(from, dot - from));
  out.push_back(dotted.substr(from));
  return out;
}

/// The member at a dotted path, made (as objects) where missing.
json& make_path(json& j, const std::string& dotted) {
  json* n = &j;
  for (const std::string& k : split(dotted)) {
    if (!n->is_object()) *n = json::object();
    n = &(*n)[k];
  }
  return *n;
}

std::string path_of(const Metric& m) { return m.path && *m.path ? m.path : m.name; }

const char* better_name(Better b) { return b == Better::Higher ? "higher" : b == Better::Lower ? "lower" : "neither"; }

const char* merge_name(MergeRule r) {
  switch (r) {
    case MergeRule::Sum: return "sum";
    case MergeRule::Max: return "max";
    case MergeRule::Ratio: return "ratio";
    case MergeRule::Quantile: return "quantile";
    case MergeRule::Same: return "same";
  }
  return "?";
}

const char* level_name(DefaultGuard::Level l) { return l == DefaultGuard::Fail ? "fail" : l == DefaultGuard::Warn ? "warn" : "info"; }

}  // namespace

json full_entry_of(const MetricTable& t, const std::map<std::string, std::vector<std::string>>& members) {
  json entry = json::object();
  for (const MetricGroup& g : t.groups) {
    std::string where = g.where;
    std::vector<std::string> names = {""};
    if (!where.empty() && where.back() == '*') {
      where = where.size() >= 2 ? where.substr(0, where.size() - 2) : "";
      const auto given = members.find(g.where);
      names = given != members.end() ? given->second : std::vector<std::string>{"cold"};
    }
    for (const std::string& member : names) {
      std::string at = where;
      if (!member.empty()) at += (at.empty() ? "" : ".") + member;
      json& o = at.empty() ? entry : make_path(entry, at);
      if (!o.is_object()) o = json::object();
      for (const Metric& m : g.metrics) {
        if (m.needs) {
          json& record = make_path(o, m.needs);
          if (record.is_null()) record = json::object();
        }
        make_path(o, path_of(m)) = 0;
      }
    }
  }
  return entry;
}

std::string metric_key(const Metric& m) {
  const std::vector<std::string> parts = split(path_of(m));
  const auto statistic = [](const std::string& k) {
    return std::any_of(key::kStatistics.begin(), key::kStatistics.end(), [&](const char* s) { return k == s; });
  };
  for (auto p = parts.rbegin(); p != parts.rend(); ++p)
    if (!statistic(*p)) return *p;
  return parts.back();
}

json metrics_listing(const StudyKind& k) {
  json out = json::array();
  for (const MetricGroup& g : k.metrics().groups)
    for (const Metric& m : g.metrics)
      out.push_back({{"kind", k.name},
                     {"name", std::string(g.prefix) + m.name},
                     {"where", g.where},
                     {"path", path_of(m)},
                     {"key", metric_key(m)},
                     {"unit", m.unit},
                     {"better", better_name(m.better)},
                     {"merge", merge_name(m.merge)},
                     {"guard", {{"level", level_name(m.guard.level)}, {"abs", m.guard.abs}, {"rel", m.guard.rel}}},
                     {"timing", m.timing},
                     {"scale", m.scale},
                     {"needs", m.needs ? json(m.needs) : json(nullptr)},
                     {"ratio_to", g.ratio_to ? json(g.ratio_to) : json(nullptr)}});
  return out;
}

std::string metrics_text(const StudyKind& k) {
  std::string o = format("%s (schema %s), per %s:\n", k.name, k.schema, k.entry_word);
  o += format("  %-44s %-26s %-10s %-7s %-8s %s\n", "name", "key", "unit", "better", "merge", "default guard");
  for (const json& m : metrics_listing(k)) {
    const json& g = m.at("guard");
    std::string guard = g.at("level").get<std::string>();
    if (guard != "info") guard += format(" (abs %g, rel %g)", g.at("abs").get<double>(), g.at("rel").get<double>());
    if (m.at("timing").get<bool>()) guard += ", timing";
    o += format("  %-44s %-26s %-10s %-7s %-8s %s\n", m.at("name").get<std::string>().c_str(), m.at("key").get<std::string>().c_str(),
                m.at("unit").get<std::string>().c_str(), m.at("better").get<std::string>().c_str(),
                m.at("merge").get<std::string>().c_str(), guard.c_str());
  }
  return o;
}

}  // namespace idcol::harness
