// libFuzzer target for the solver's inputs: bytes -> two shapes, a pose and
// options (decoding and properties in solve_case.hpp). Build with
// scripts/fuzz.sh or -DIDCOL_BUILD_FUZZERS=ON (clang only).
//
// A property violation aborts with the shapes and pose at 17 digits; the
// crashing input then belongs in corpus/solve/ (minimised with
// -minimize_crash=1) and its story in core/src/solver/tests/test_fuzz_regressions.cpp.
#include <cstdio>
#include <cstdlib>

#include "solve_case.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string err = idcol::fuzz::run_case(data, size);
  if (!err.empty()) {
    std::fprintf(stderr, "idcol fuzz_solve property violated: %s\n", err.c_str());
    std::abort();
  }
  return 0;
}
