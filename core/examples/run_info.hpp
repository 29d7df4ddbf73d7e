// What the example programs and benchmarks of the contact-physics layer
// write beside their figures: the machine, the compiler, the flags, the git
// revision; and the whole-file write that never leaves a half-written
// results file behind.
#pragma once

#include <cstdio>
#include <ctime>
#include <fstream>
#include <stdexcept>
#include <string>

#include "write_whole.hpp"  // write_whole

#if __has_include("example_revision.h")
#include "example_revision.h"  // IDCOL_BENCH_GIT: the revision this binary was built from
#endif
#ifndef IDCOL_BENCH_GIT
#define IDCOL_BENCH_GIT "unknown"
#endif
#ifndef IDCOL_EXAMPLE_FLAGS
#define IDCOL_EXAMPLE_FLAGS "unknown"
#endif

namespace idcol::examples {

inline std::string cpu_model() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

inline std::string json_str(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

inline std::string utc_date() {
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

/// The command line, as run.
inline std::string command_line(int argc, char** argv) {
  std::string c;
  for (int i = 0; i < argc; ++i) c += (i ? " " : "") + std::string(argv[i]);
  return c;
}

/// "command", "machine", "compiler", "flags", "git_revision" and "date" members of a
/// results file.
inline std::string provenance_json(const std::string& command) {
  return "\"command\": " + json_str(command) + ", \"date\": " + json_str(utc_date()) +
         ", \"machine\": {\"cpu\": " + json_str(cpu_model()) +
         "}, \"compiler\": " + json_str(__VERSION__) + ", \"flags\": " + json_str(IDCOL_EXAMPLE_FLAGS) +
         ", \"git_revision\": " + json_str(IDCOL_BENCH_GIT);
}


}  // namespace idcol::examples
