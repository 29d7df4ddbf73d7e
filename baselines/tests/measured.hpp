// A figure that a test measures and the documentation quotes. The test
// prints it for whoever reads its output, and records it on itself as a
// gtest property, which --gtest_output=json keeps: scripts/record_test_figures.py
// runs the tests and collects every such property into
// results/test_figures.json, from which baselines/README.md quotes them
// (scripts/check_doc_figures.py checks each quote against that file).
#pragma once

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace idcol::test {

/// Records `key` = value on the running test, at 17 significant digits. A
/// '/' in the key nests it in the results file (pair/method/figure), so a
/// key holds no '.', which the documentation's paths use as a separator.
inline void measured(const std::string& key, double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  ::testing::Test::RecordProperty(key, text);
}

}  // namespace idcol::test
