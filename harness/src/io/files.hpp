// Writers: the atomic file, results files, the Markdown table and run
// metadata. A results file is only ever seen complete: it is written to a
// temporary file in the same directory, fsynced and renamed over the target.
#pragma once

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "idcol/options.hpp"
#include "io/record.hpp"
#include "io/text.hpp"
#include "io/solver_options.hpp"

namespace idcol::harness {

/// A file that appears at `path` only on commit().
///
/// The target is checked when the object is built, before any work: a
/// directory, a device, a FIFO or a socket is refused (naming the path and
/// what it is), as is a directory that does not exist or cannot be written.
/// A symbolic link is written through: its final target is replaced, the
/// link stays. `path` "-" is standard output, written on commit().
///
/// The data go to a hidden temporary file ".<name>.idcol-tmp.<pid>.XXXXXX"
/// in the target's directory, created at the first write (late, so that a
/// run killed by SIGKILL before it has results leaves nothing) and renamed
/// over the target on commit(); destroying or cancelling the object without
/// commit() removes it. A temporary left by a process that no longer exists
/// (SIGKILL during the write) is removed by the next AtomicFile of the same
/// target. A glob such as out/*.json never sees a temporary (dot files).
class AtomicFile {
 public:
  /// `option` names the path in error messages (e.g. "-o", "--failures").
  /// Throws std::runtime_error if the target is not a regular file's path or
  /// its directory cannot be written.
  explicit AtomicFile(std::string path, std::string option = "output");
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The temporary file's stream (created on first use).
  std::FILE* stream();
  void write(const std::string& s);
  /// fflush, fsync, rename onto the target, fsync the directory (for "-":
  /// copy to standard output). Throws on error. The same as stage() then
  /// publish().
  void commit();
  /// Makes the temporary complete without showing it: flushes it, checks
  /// that no write to it failed (also those made through stream()) and
  /// fsyncs it. Throws on error, leaving the target as it was. Several files
  /// that belong together are all staged before any is published, so that a
  /// full disk leaves every old one in place.
  void stage();
  /// Renames the staged temporary onto the target (for "-": copies it to
  /// standard output, checking the write). Throws on error.
  void publish();
  /// Removes the temporary file (idempotent).
  void cancel();
  /// The temporary file's path ("" before the first write, and for "-").
  const std::string& temp_path() const { return tmp_; }

 private:
  void open();
  std::string path_, option_, target_, tmp_;
  std::FILE* f_ = nullptr;
  bool to_stdout_ = false, done_ = false, staged_ = false;
};

/// Refuses (std::invalid_argument, naming both) an output that is the same
/// file as an input or as another output, e.g. `run x.toml -o x.toml` or
/// `-o a.json --failures a.json`. Each entry is (role, path), role being the
/// option or "the scene"; "-" (standard output) may appear once.
void require_distinct_files(const std::vector<std::pair<std::string, std::string>>& inputs,
                            const std::vector<std::pair<std::string, std::string>>& outputs);


/// Writes `text` to `path` atomically.
void write_file_atomically(const std::string& path, const std::string& text);
/// Reads a whole JSON file; throws std::runtime_error naming the file.
nlohmann::json read_json_file(const std::string& path);

/// "idcol_harness 0.1.0, built from git <rev>", the compiler and build type,
/// and the libraries' versions: what --version prints.
std::string version_text();

/// Machine and build metadata: project version, libraries' versions (FCL,
/// libccd, GLPK, Eigen, toml++, nlohmann_json), OS and kernel, CPU model, core count, compiler, flags, build
/// type, git revision (configure time, and run time if the checkout is there),
/// date (UTC), host, the command line.
nlohmann::json collect_metadata(int argc, char** argv);


}  // namespace idcol::harness
