// Writing a results file whole: through a temporary file and a rename, so
// that an interrupted run leaves the old file as it was. Shared by the
// examples (run_info.hpp) and the benchmarks that write results files
// (bench_throughput.cpp).
#pragma once

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

namespace idcol::examples {

/// Writes `text` to `path` through `path.tmp` and a rename; throws
/// std::runtime_error naming the file when either step fails.
inline void write_whole(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.flush();
    if (!f) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + " to " + path);
  }
}

}  // namespace idcol::examples
