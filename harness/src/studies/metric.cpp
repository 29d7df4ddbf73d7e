#include "studies/metric.hpp"

#include <cmath>
#include <cstdint>

namespace idcol::harness {

using nlohmann::json;

const json* at_path(const json& j, const std::string& path) {
  const json* n = &j;
  std::size_t from = 0;
  while (from <= path.size()) {
    const std::size_t dot = path.find('.', from);
    const std::string key = path.substr(from, dot == std::string::npos ? std::string::npos : dot - from);
    if (!n->is_object() || !n->contains(key)) return nullptr;
    n = &(*n)[key];
    if (dot == std::string::npos) return n;
    from = dot + 1;
  }
  return n;
}

double number_at(const json& j, const std::string& path) {
  const json* n = at_path(j, path);
  return n && n->is_number() ? n->get<double>() : NAN;
}

namespace {

std::string path_of(const Metric& m) { return m.path && *m.path ? m.path : m.name; }

std::string with_key(std::string prefix, const std::string& key) {
  const std::size_t at = prefix.find("{key}");
  if (at != std::string::npos) prefix.replace(at, 5, key);
  return prefix;
}

/// The objects of a group in an entry, with the name of each ("" where the
/// path names one object).
std::vector<std::pair<std::string, const json*>> objects(const MetricGroup& g, const json& entry) {
  std::vector<std::pair<std::string, const json*>> out;
  std::string where = g.where;
  const bool each = where.size() >= 1 && where.back() == '*';
  if (each) where = where.substr(0, where.size() >= 2 ? where.size() - 2 : 0);
  const json* o = where.empty() ? &entry : at_path(entry, where);
  if (!o) return out;
  if (!each) return {{"", o}};
  if (!o->is_object()) return out;
  for (const auto& [k, v] : o->items()) out.emplace_back(k, &v);
  return out;
}

}  // namespace

std::vector<std::pair<std::string, double>> entry_metrics(const MetricTable& t, const json& entry) {
  std::vector<std::pair<std::string, double>> out;
  if (t.valid_key && entry.is_object() && entry.contains(t.valid_key) && entry[t.valid_key] == false) return out;
  for (const MetricGroup& g : t.groups) {
    const auto objs = objects(g, entry);
    if (g.ratio_to) {
      const json* ref = nullptr;
      for (const auto& [k, o] : objs)
        if (k == g.ratio_to) ref = o;
      if (!ref) continue;
      for (const auto& [k, o] : objs) {
        if (k == g.ratio_to) continue;
        for (const Metric& m : g.metrics)
          out.emplace_back(with_key(g.prefix, k) + m.name, number_at(*o, path_of(m)) / number_at(*ref, path_of(m)) * m.scale);
      }
      continue;
    }
    for (const auto& [k, o] : objs)
      for (const Metric& m : g.metrics) {
        if (m.needs && !at_path(*o, m.needs)) continue;
        out.emplace_back(with_key(g.prefix, k) + m.name, number_at(*o, path_of(m)) * m.scale);
      }
  }
  return out;
}

void for_each_metric_value(const MetricTable& t, const json& entry,
                           const std::function<void(const Metric&, const std::string&, const json&)>& f) {
  if (t.valid_key && entry.is_object() && entry.contains(t.valid_key) && entry[t.valid_key] == false) return;
  for (const MetricGroup& g : t.groups) {
    std::string where = g.where;
    if (!where.empty() && where.back() == '*') where.resize(where.size() >= 2 ? where.size() - 2 : 0);
    for (const auto& [k, o] : objects(g, entry)) {
      const std::string at = k.empty() ? where : where.empty() ? k : where + "." + k;
      for (const Metric& m : g.metrics) {
        if (m.needs && !at_path(*o, m.needs)) continue;
        if (const json* v = at_path(*o, path_of(m))) f(m, at.empty() ? path_of(m) : at + "." + path_of(m), *v);
      }
    }
  }
}

namespace {
bool is_count(const Metric& m) { return std::string(m.unit) == "count"; }
bool is_fraction(const Metric& m) { return std::string(m.unit) == "fraction"; }
}  // namespace

bool metric_value_ok(const Metric& m, const json& v, bool as_double) {
  if (v.is_null()) return true;
  if (!v.is_number()) return false;
  const double x = v.get<double>();
  if (!std::isfinite(x)) return true;  // a results file in memory: written as null
  if (is_count(m) && m.merge != MergeRule::Ratio) {
    if (v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0)) return true;
    return as_double && v.is_number_float() && x >= 0.0 && x < 0x1p64 && std::floor(x) == x;
  }
  if (is_count(m)) return x >= 0.0;
  if (is_fraction(m)) return x >= 0.0 && x <= 1.0;
  return true;
}

std::string metric_value_expected(const Metric& m) {
  if (is_count(m) && m.merge != MergeRule::Ratio) return "a count (an integer in [0, 2^64)) or null";
  if (is_count(m)) return "a mean count (a number >= 0) or null";
  if (is_fraction(m)) return "a fraction (a number in [0, 1]) or null";
  return "a number or null";
}

const Metric* find_metric(const MetricTable& t, const std::string& full) {
  for (const MetricGroup& g : t.groups) {
    const std::string prefix = g.prefix;
    const std::size_t at = prefix.find("{key}");
    const std::string head = at == std::string::npos ? prefix : prefix.substr(0, at);
    const std::string tail = at == std::string::npos ? "" : prefix.substr(at + 5);
    for (const Metric& m : g.metrics) {
      const std::string name = tail + m.name;
      if (full.size() < head.size() + name.size()) continue;
      if (full.compare(0, head.size(), head) != 0) continue;
      if (full.compare(full.size() - name.size(), name.size(), name) != 0) continue;
      // With {key}, the key fills what lies between; without it, nothing may.
      if (at == std::string::npos && full.size() != head.size() + name.size()) continue;
      if (at != std::string::npos && full.size() == head.size() + name.size()) continue;
      return &m;
    }
  }
  return nullptr;
}

}  // namespace idcol::harness
