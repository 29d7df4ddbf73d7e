#include "stats/stats.hpp"

#include "io/keys.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

namespace idcol::harness {

using nlohmann::json;

std::uint64_t count_from_json(const json& j, const std::string& key) {
  // nlohmann reads a non-negative integer as unsigned, a negative one as
  // signed, and one of 2^64 or more as a float.
  if (j.is_number_unsigned()) return j.get<std::uint64_t>();
  if (j.is_number_integer() && j.get<std::int64_t>() >= 0) return static_cast<std::uint64_t>(j.get<std::int64_t>());
  throw BadCount(key + ": expected a count (an integer in [0, 2^64)), got " + j.dump() +
                 (j.is_number_integer() ? " (negative)" : j.is_number_float() ? " (not an integer, or 2^64 or more)" : ""));
}

std::uint64_t add_counts(std::uint64_t a, std::uint64_t b, const std::string& key) {
  if (b > UINT64_MAX - a)
    throw BadCount(key + ": " + std::to_string(a) + " + " + std::to_string(b) + " passes 2^64 - 1, the largest count");
  return a + b;
}

LogHistogram::LogHistogram(int e0, int decades, int per_decade, bool keep_sum)
    : e0_(e0), decades_(decades), per_decade_(per_decade), keep_sum_(keep_sum), bins_(static_cast<std::size_t>(decades) * per_decade, 0) {}

void LogHistogram::add(double v) {
  ++count_;
  if (!std::isfinite(v)) {
    ++nonfinite_;
    return;
  }
  if (keep_sum_) sum_ += v;
  if (v > max_) max_ = v;
  if (!(v > 0.0)) {
    ++under_;
    return;
  }
  const double pos = (std::log10(v) - e0_) * per_decade_;
  if (pos < 0.0) {
    ++under_;
  } else if (pos >= static_cast<double>(bins_.size())) {
    ++over_;
  } else {
    ++bins_[static_cast<std::size_t>(pos)];
  }
}

void LogHistogram::merge(const LogHistogram& o) {
  if (o.e0_ != e0_ || o.decades_ != decades_ || o.per_decade_ != per_decade_ || o.keep_sum_ != keep_sum_)
    throw std::invalid_argument("LogHistogram::merge: histograms have different binning");
  for (std::size_t i = 0; i < bins_.size(); ++i) bins_[i] = add_counts(bins_[i], o.bins_[i], "bins");
  under_ = add_counts(under_, o.under_, "under");
  over_ = add_counts(over_, o.over_, "over");
  nonfinite_ = add_counts(nonfinite_, o.nonfinite_, "nonfinite");
  count_ = add_counts(count_, o.count_, "count");
  sum_ += o.sum_;
  max_ = std::max(max_, o.max_);
}

double LogHistogram::mean() const {
  const std::uint64_t finite = count_ - nonfinite_;
  return finite && keep_sum_ ? sum_ / static_cast<double>(finite) : std::numeric_limits<double>::quiet_NaN();
}

double LogHistogram::quantile(double q) const {
  const std::uint64_t finite = count_ - nonfinite_;
  if (finite == 0) return std::numeric_limits<double>::quiet_NaN();
  std::uint64_t rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(finite)));
  if (rank < 1) rank = 1;
  if (rank > finite) rank = finite;
  std::uint64_t seen = under_;
  if (rank <= seen) return 0.0;
  for (std::size_t i = 0; i < bins_.size(); ++i) {
    seen += bins_[i];
    if (rank <= seen) return std::pow(10.0, e0_ + (static_cast<double>(i) + 0.5) / per_decade_);
  }
  return max_;
}

json LogHistogram::to_json() const {
  json sparse = json::array();
  for (std::size_t i = 0; i < bins_.size(); ++i)
    if (bins_[i]) sparse.push_back({i, bins_[i]});
  return {{"log10_low", e0_},         {"decades", decades_}, {"bins_per_decade", per_decade_},
          {"count", count_},          {"under", under_},     {"over", over_},
          {"nonfinite", nonfinite_},  {key::max, count_ - nonfinite_ ? json(max_) : json(nullptr)},
          {"sum", keep_sum_ ? json(sum_) : json(nullptr)},              {"bins", sparse}};
}

LogHistogram LogHistogram::from_json(const json& j) {
  LogHistogram h(j.at("log10_low").get<int>(), j.at("decades").get<int>(), j.at("bins_per_decade").get<int>(),
                 !j.at("sum").is_null());
  h.count_ = count_from_json(j.at("count"), "count");
  h.under_ = count_from_json(j.at("under"), "under");
  h.over_ = count_from_json(j.at("over"), "over");
  h.nonfinite_ = count_from_json(j.at("nonfinite"), "nonfinite");
  if (!j.at(key::max).is_null()) h.max_ = j.at(key::max).get<double>();
  if (h.keep_sum_) h.sum_ = j.at("sum").get<double>();
  for (const auto& b : j.at("bins")) {
    const std::uint64_t i = count_from_json(b.at(0), "bins[i][0] (a bin index)");
    if (i >= h.bins_.size())
      throw BadCount("bins: bin index " + std::to_string(i) + " past the " + std::to_string(h.bins_.size()) + " bins of the binning");
    h.bins_[i] = count_from_json(b.at(1), "bins");
  }
  return h;
}

bool LogHistogram::same_counts(const LogHistogram& o) const {
  return bins_ == o.bins_ && under_ == o.under_ && over_ == o.over_ && nonfinite_ == o.nonfinite_ && count_ == o.count_;
}

void PassStats::add(const SolveResult& r, bool chain_start, double time_ns) {
  ++solves;
  ++by_status[static_cast<int>(r.status)];
  chain_starts += chain_start;
  warm_fell_back += r.warm_start_fell_back;
  used_continuation += r.used_continuation;
  restarts += static_cast<std::uint64_t>(r.restarts);
  const bool conv = r.converged();
  if (has_iterations) {
    iter_sum += static_cast<std::uint64_t>(r.iterations);
    iter_max = std::max(iter_max, r.iterations);
    ++iter_hist[r.iterations];
  }
  if (has_residuals) {
    residual_all.add(r.residual_norm);
    if (conv) residual_converged.add(r.residual_norm);
  }
  if (has_timing) {
    time_all.add(time_ns);
    if (conv) time_converged.add(time_ns);
  }
}

void CheckCounts::add(const AnswerCheck& c) {
  ++checked;
  false_surface += c.surface_failed;
  false_normal += c.normal_failed;
  false_oracle += c.oracle_disagrees;
  oracle_failed += c.oracle_failed_to_answer;
  false_total += !c.genuine();
  worst_surface = std::max(worst_surface, c.surface);
  worst_normal = std::max(worst_normal, c.normal);
  worst_alpha_error = std::max(worst_alpha_error, c.alpha_error);
}

namespace {
const Fields<CheckCounts> kCheckCounts = {{key::checked, &CheckCounts::checked}, {key::oracle_failed, &CheckCounts::oracle_failed}};
const Fields<CheckCounts> kFalseConvergence = {{key::total, &CheckCounts::false_total}, {"surface", &CheckCounts::false_surface},
                                               {"normal", &CheckCounts::false_normal}, {"oracle", &CheckCounts::false_oracle}};
const Fields<CheckCounts, double> kCheckWorst = {{key::worst_surface_error, &CheckCounts::worst_surface},
                                                 {key::worst_normal_error, &CheckCounts::worst_normal},
                                                 {key::worst_alpha_error, &CheckCounts::worst_alpha_error}};
const Fields<PassStats> kPassCounts = {{key::solves, &PassStats::solves}, {"chain_starts", &PassStats::chain_starts},
                                       {"warm_start_fell_back", &PassStats::warm_fell_back},
                                       {"used_continuation", &PassStats::used_continuation}, {"restarts", &PassStats::restarts}};
}  // namespace

void CheckCounts::merge(const CheckCounts& o) {
  add_fields(*this, o, kCheckCounts);
  add_fields(*this, o, kFalseConvergence);
  max_fields(*this, o, kCheckWorst);
}

json CheckCounts::to_json() const {
  json j = json::object(), f = json::object();
  write_fields(*this, j, kCheckCounts);
  write_fields(*this, f, kFalseConvergence);
  write_fields(*this, j, kCheckWorst);
  j[key::false_convergence] = f;
  return j;
}

CheckCounts CheckCounts::from_json(const json& j) {
  CheckCounts c;
  read_fields(c, j, kCheckCounts);
  read_fields(c, j.at(key::false_convergence), kFalseConvergence);
  read_fields(c, j, kCheckWorst);
  return c;
}

void PassStats::merge(const PassStats& o) {
  if (o.has_timing != has_timing || o.has_iterations != has_iterations || o.has_residuals != has_residuals ||
      o.has_checks != has_checks)
    throw std::invalid_argument("PassStats::merge: the two record different things");
  checks.merge(o.checks);
  add_fields(*this, o, kPassCounts);
  for (int i = 0; i < kNumSolveStatuses; ++i)
    by_status[i] = add_counts(by_status[i], o.by_status[i], std::string("status.") + to_string(static_cast<SolveStatus>(i)));
  iter_sum = add_counts(iter_sum, o.iter_sum, "iterations.sum");
  iter_max = std::max(iter_max, o.iter_max);
  for (const auto& [k, c] : o.iter_hist) iter_hist[k] = add_counts(iter_hist[k], c, "iterations.histogram");
  residual_all.merge(o.residual_all);
  residual_converged.merge(o.residual_converged);
  time_all.merge(o.time_all);
  loop_wall_s += o.loop_wall_s;
  loop_cpu_s += o.loop_cpu_s;
  involuntary_switches += o.involuntary_switches;
  time_converged.merge(o.time_converged);
}

namespace {
json nan_to_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json time_summary(const LogHistogram& h) {
  return {{"count", h.count()},
          {"mean_ns", nan_to_null(h.mean())},
          {key::median_ns, nan_to_null(h.quantile(0.5))},
          {"p90_ns", nan_to_null(h.quantile(0.9))},
          {key::p99_ns, nan_to_null(h.quantile(0.99))},
          {"max_ns", h.count() ? nan_to_null(h.max()) : json(nullptr)},
          {"histogram", h.to_json()}};
}
json residual_summary(const LogHistogram& h) {
  return {{"count", h.count()},
          {key::max, h.count() ? nan_to_null(h.max()) : json(nullptr)},
          {"p50", nan_to_null(h.quantile(0.5))},
          {key::p99, nan_to_null(h.quantile(0.99))},
          {"histogram", h.to_json()}};
}
}  // namespace

json PassStats::to_json() const {
  json status = json::object();
  for (int i = 0; i < kNumSolveStatuses; ++i) status[to_string(static_cast<SolveStatus>(i))] = by_status[i];
  json j = {{key::convergence_rate, convergence_rate()},
            {key::failures, solves - converged() - by_status[static_cast<int>(SolveStatus::Concentric)]},
            {"status", status}};
  write_fields(*this, j, kPassCounts);
  if (has_iterations) {
    json hist = json::object();
    for (const auto& [k, c] : iter_hist) hist[std::to_string(k)] = c;
    j[key::iterations] = {{key::mean, solves ? json(static_cast<double>(iter_sum) / solves) : json(nullptr)},  // no solves: no mean
                       {key::max, iter_max},
                       {"sum", iter_sum},
                       {"histogram", hist}};
  }
  if (has_residuals)
    j["residual"] = {{key::all, residual_summary(residual_all)}, {"converged", residual_summary(residual_converged)}};
  if (has_checks) j[key::checks] = checks.to_json();
  if (has_timing)
    j[key::time] = {{key::all, time_summary(time_all)},
                 {"converged", time_summary(time_converged)},
                 {"loop", {{"wall_seconds", loop_wall_s},
                           {"thread_cpu_seconds", loop_cpu_s},
                           {"descheduled_seconds", descheduled_seconds(loop_wall_s, loop_cpu_s)},
                           {"involuntary_context_switches", involuntary_switches}}}};
  return j;
}

PassStats PassStats::from_json(const json& j) {
  PassStats s;
  read_fields(s, j, kPassCounts);
  // A status newer than the file (results written before it existed) counts 0.
  for (int i = 0; i < kNumSolveStatuses; ++i) {
    const char* name = to_string(static_cast<SolveStatus>(i));
    const json& st = j.at("status");
    s.by_status[i] = st.contains(name) ? count_from_json(st.at(name), std::string("status.") + name) : 0;
  }
  if (j.contains(key::iterations)) {
    s.has_iterations = true;
    const json& it = j.at(key::iterations);
    s.iter_sum = count_from_json(it.at("sum"), "iterations.sum");
    s.iter_max = it.at(key::max).get<int>();
    for (const auto& [k, c] : it.at("histogram").items()) {
      // The keys are iteration counts; a key that is not one is named (std::stoi's own error named nothing).
      const bool digits = !k.empty() && k.size() <= 9 && std::all_of(k.begin(), k.end(), [](char d) { return d >= '0' && d <= '9'; });
      if (!digits || (k.size() > 1 && k[0] == '0'))
        throw BadCount("iterations.histogram: key \"" + k + "\" is not an iteration count (an integer in [0, 10^9))");
      s.iter_hist[std::atoi(k.c_str())] = count_from_json(c, "iterations.histogram[\"" + k + "\"]");
    }
  }
  if (j.contains("residual")) {
    s.has_residuals = true;
    s.residual_all = LogHistogram::from_json(j.at("residual").at(key::all).at("histogram"));
    s.residual_converged = LogHistogram::from_json(j.at("residual").at("converged").at("histogram"));
  }
  if (j.contains(key::checks)) {
    s.has_checks = true;
    s.checks = CheckCounts::from_json(j.at(key::checks));
  }
  if (j.contains(key::time)) {
    s.has_timing = true;
    s.time_all = LogHistogram::from_json(j.at(key::time).at(key::all).at("histogram"));
    s.time_converged = LogHistogram::from_json(j.at(key::time).at("converged").at("histogram"));
    const json& loop = j.at(key::time).at("loop");
    s.loop_wall_s = loop.at("wall_seconds").get<double>();
    s.loop_cpu_s = loop.at("thread_cpu_seconds").get<double>();
    s.involuntary_switches = loop.at("involuntary_context_switches").get<std::uint64_t>();
  }
  return s;
}

json without_timing(json pairs) {
  for (auto& p : pairs)
    for (auto& [name, pass] : p.at("passes").items()) pass.erase(key::time);
  return pairs;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + i, v.end());
  return v[i];
}

}  // namespace idcol::harness
