// Writers: the atomic file, results files, the Markdown table and run
// metadata. A results file is only ever seen complete: it is written to a
// temporary file in the same directory, fsynced and renamed over the target.
#pragma once

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "idcol_harness/record.hpp"
#include "idcol_harness/solver_options.hpp"

namespace idcol::harness {

/// A file that appears at `path` only on commit(). Until then the data go to
/// a temporary file "<path>.tmp.XXXXXX" in the same directory; destroying or
/// cancelling the object without commit() removes it, so an interrupted run
/// leaves no partial file behind.
class AtomicFile {
 public:
  /// Throws std::runtime_error if the temporary file cannot be created.
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* stream() { return f_; }
  void write(const std::string& s);
  /// fflush, fsync, rename onto the target, fsync the directory. Throws on error.
  void commit();
  /// Removes the temporary file (idempotent).
  void cancel();
  const std::string& temp_path() const { return tmp_; }

 private:
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
  bool done_ = false;
};

/// Writes `text` to `path` atomically.
void write_file_atomically(const std::string& path, const std::string& text);
/// Reads a whole JSON file; throws std::runtime_error naming the file.
nlohmann::json read_json_file(const std::string& path);

/// Machine and build metadata: CPU model, core count, compiler, flags, build
/// type, git revision (configure time, and run time if the checkout is there),
/// date (UTC), host, the command line.
nlohmann::json collect_metadata(int argc, char** argv);


/// The paper's Table 1 layout from a results file: body 1 by body 2, each
/// cell "cold / **warm**" mean time per solve (us), then the same layout for
/// convergence rate, median time and mean iterations.
std::string markdown_table(const nlohmann::json& results, const std::string& results_path);

}  // namespace idcol::harness
