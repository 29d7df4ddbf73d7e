// The benchmarks' main: Google Benchmark's, with one line of context first
// (and, where the target provides them, the revision, compiler, flags and CPU).
// Debian's libbenchmark package is compiled without NDEBUG, so every run
// prints "***WARNING*** Library was built as DEBUG. Timings may be
// affected." That warning is about the benchmark library, not about the code
// it times; the context line just above it says so, and records this
// build's own mode in the JSON output's context as well.
#pragma once

#include <benchmark/benchmark.h>

#include <fstream>
#include <string>

#if __has_include("example_revision.h")
#include "example_revision.h"  // IDCOL_BENCH_GIT, where the benchmark's target asks for it (core/CMakeLists.txt)
#endif

namespace idcol::bench {

inline void add_library_note() {
#ifdef NDEBUG
  const char* mine = "this benchmark and the library it times are compiled with NDEBUG (optimised)";
#else
  const char* mine = "this benchmark is compiled WITHOUT NDEBUG: configure with -DCMAKE_BUILD_TYPE=Release to time it";
#endif
  benchmark::AddCustomContext("idcol_note", std::string("a 'Library was built as DEBUG' warning below concerns Debian's "
                                                        "libbenchmark package, not idcol; ") + mine);
  // The provenance a results file carries, where the target provides it.
#ifdef IDCOL_BENCH_GIT
  benchmark::AddCustomContext("idcol_git_revision", IDCOL_BENCH_GIT);
  benchmark::AddCustomContext("idcol_compiler", __VERSION__);
#endif
#ifdef IDCOL_EXAMPLE_FLAGS
  benchmark::AddCustomContext("idcol_flags", IDCOL_EXAMPLE_FLAGS);
  std::ifstream f("/proc/cpuinfo");
  for (std::string line; std::getline(f, line);)
    if (line.rfind("model name", 0) == 0) {
      benchmark::AddCustomContext("idcol_cpu", line.substr(line.find(':') + 2));
      break;
    }
#endif
}

}  // namespace idcol::bench

#define IDCOL_BENCHMARK_MAIN()                        \
  int main(int argc, char** argv) {                   \
    ::benchmark::Initialize(&argc, argv);             \
    if (::benchmark::ReportUnrecognizedArguments(argc, argv)) return 1; \
    ::idcol::bench::add_library_note();               \
    ::benchmark::RunSpecifiedBenchmarks();            \
    ::benchmark::Shutdown();                          \
    return 0;                                         \
  }
