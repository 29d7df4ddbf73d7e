// What is read off the declared metrics (studies/metric_list.hpp): the entry
// compare takes the names a guard may match from holds every declared
// metric of its kind, and each metric's key is a key of its path that is not
// a summary statistic.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "io/keys.hpp"
#include "studies/metric.hpp"
#include "studies/metric_list.hpp"
#include "studies/study.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

TEST(MetricList, FullEntryHoldsEveryDeclaredMetric) {
  for (const StudyKind& k : study_kinds()) {
    SCOPED_TRACE(k.name);
    std::set<const Metric*> read;
    for (const auto& [name, value] : entry_metrics(k.metrics(), json::parse(k.full_entry))) {
      const Metric* m = find_metric(k.metrics(), name);
      ASSERT_NE(m, nullptr) << name;
      read.insert(m);
    }
    for (const MetricGroup& g : k.metrics().groups)
      for (const Metric& m : g.metrics) EXPECT_TRUE(read.count(&m)) << g.prefix << m.name << " is not in the kind's full entry";
  }
}

TEST(MetricList, EachMetricIsNamedByAKeyOfItsPath) {
  EXPECT_STREQ((key::dotted<key::iterations, key::mean>), "iterations.mean");
  EXPECT_STREQ((key::dotted<key::time, key::all, key::median_ns>), "time.all.median_ns");
  std::size_t n = 0;
  for (const StudyKind& k : study_kinds())
    for (const json& m : metrics_listing(k)) {
      ++n;
      const std::string key = m.at("key"), path = "." + m.at("path").get<std::string>() + ".";
      EXPECT_NE(path.find("." + key + "."), std::string::npos) << m.at("name") << ": key " << key << " not in its path";
      for (const char* s : key::kStatistics) EXPECT_NE(key, s) << m.at("name");
      EXPECT_EQ(m.at("kind"), k.name);
    }
  EXPECT_GE(n, 40u);
}

}  // namespace
}  // namespace idcol::harness
