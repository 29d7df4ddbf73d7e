// Command-line counts of the examples and benchmark drivers: a whole number
// within its range, or the program ends with status 2 and a line that names
// the tool, the argument and the value it got (never a wrapped count, a
// silent 0 from atoi, or a crash allocating it).
#pragma once

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace idcol::examples {

/// text as a whole number in [lo, hi]; anything else (a sign or trailing
/// characters, nothing, out of range) exits 2 with
/// "TOOL: NAME must be an integer in [lo, hi], got 'TEXT'".
inline long count_arg(const char* tool, const char* name, const char* text, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
    std::fprintf(stderr, "%s: %s must be an integer in [%ld, %ld], got '%s'\n", tool, name, lo, hi, text);
    std::exit(2);
  }
  return v;
}

/// At most max_args positional arguments, none of them an option (-h,
/// --help, ...): otherwise the usage line on stderr (stdout for a help
/// request, status 0) and exit 2.
inline void positional_args(const char* usage, int argc, char** argv, int max_args) {
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "--help")) {
      std::printf("usage: %s\n", usage);
      std::exit(0);
    }
  if (argc - 1 > max_args) {
    std::fprintf(stderr, "usage: %s (got %d arguments)\n", usage, argc - 1);
    std::exit(2);
  }
}

}  // namespace idcol::examples
