#include "io/files.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/utsname.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <ctime>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "io/text.hpp"

// Set by harness/CMakeLists.txt; builds that compile the sources by hand
// (scripts/fuzz_scene.sh) may leave them out.
#ifndef IDCOL_HARNESS_VERSION
#define IDCOL_HARNESS_VERSION "unknown"
#endif
#ifndef IDCOL_HARNESS_LIBRARIES
#define IDCOL_HARNESS_LIBRARIES ""
#endif

namespace idcol::harness {

using nlohmann::json;

namespace {
std::string dir_of(const std::string& path) {
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}
[[noreturn]] void sys_fail(const std::string& what, const std::string& path) {
  throw std::runtime_error(what + " " + path + ": " + std::strerror(errno));
}
}  // namespace

namespace {
std::string base_of(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

const char* kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

/// The file a path names once every symbolic link of its last component is
/// followed (a dangling link: the path it points to).
std::string follow_links(const std::string& path, const std::string& option) {
  std::string p = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    std::vector<char> buf(PATH_MAX + 1);
    const ssize_t n = ::readlink(p.c_str(), buf.data(), buf.size() - 1);
    if (n < 0) sys_fail("cannot read the link", p);
    std::string t(buf.data(), static_cast<std::size_t>(n));
    p = (t.empty() || t[0] == '/') ? t : dir_of(p) + "/" + t;
  }
  throw std::runtime_error(option + " " + path + ": too many levels of symbolic links");
}

const std::string kTmpTag = ".idcol-tmp.";

/// ".<name>.idcol-tmp.": what the temporaries of `target` start with. A long
/// name is cut to its first 200 bytes, so that the temporary's name (the tag,
/// a pid and six letters added) stays within NAME_MAX (255) for every name
/// the target may have.
std::string temp_prefix(const std::string& target) {
  return "." + base_of(target).substr(0, 200) + kTmpTag;
}

/// Removes the temporaries of `target` whose writing process no longer
/// exists (a run killed with SIGKILL while it wrote them).
void remove_stale_temporaries(const std::string& target) {
  const std::string dir = dir_of(target), prefix = temp_prefix(target);
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());  // "<pid>.XXXXXX"
    char* end = nullptr;
    const long pid = std::strtol(rest.c_str(), &end, 10);
    if (pid <= 0 || end == rest.c_str() || *end != '.') continue;
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) ::unlink((dir + "/" + name).c_str());
  }
  ::closedir(d);
}
}  // namespace

AtomicFile::AtomicFile(std::string path, std::string option) : path_(std::move(path)), option_(std::move(option)) {
  if (path_.empty()) throw std::runtime_error(option_ + ": empty path");
  if (path_ == "-") {
    to_stdout_ = true;
    target_ = "-";
    return;
  }
  target_ = follow_links(path_, option_);
  struct stat st {};
  if (::stat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw std::runtime_error(option_ + " " + path_ + ": " + kind_of(st.st_mode) +
                             ", not a regular file (give a file's path, or - for standard output)");
  remove_stale_temporaries(target_);
  // Can the directory take the file? A probe created and removed at once, so
  // that an unwritable path fails before the run, not after it.
  open();
  cancel();
  done_ = false;
  tmp_.clear();
}

AtomicFile::~AtomicFile() { cancel(); }

void AtomicFile::open() {
  if (done_ || staged_) throw std::runtime_error("AtomicFile: write after stage, commit or cancel: " + path_);
  if (f_) return;
  if (to_stdout_) {
    f_ = std::tmpfile();  // anonymous: copied to standard output on commit
    if (!f_) sys_fail("cannot create a temporary file for", "standard output");
    return;
  }
  std::string templ = dir_of(target_) + "/" + temp_prefix(target_) + std::to_string(::getpid()) + ".XXXXXX";
  const int fd = ::mkstemp(templ.data());
  if (fd < 0) throw std::runtime_error(option_ + " " + path_ + ": cannot create a file in " + dir_of(target_) + ": " + std::strerror(errno));
  tmp_ = templ;
  f_ = ::fdopen(fd, "wb");
  if (!f_) {
    ::close(fd);
    ::unlink(tmp_.c_str());
    sys_fail("cannot open", tmp_);
  }
}

std::FILE* AtomicFile::stream() {
  open();
  return f_;
}

void AtomicFile::write(const std::string& s) {
  open();
  if (std::fwrite(s.data(), 1, s.size(), f_) != s.size())
    sys_fail("cannot write", (tmp_.empty() ? std::string("the copy of standard output") : tmp_) + " (for " + option_ + " " + path_ + ")");
}

void AtomicFile::commit() {
  stage();
  publish();
}

void AtomicFile::stage() {
  if (done_ || staged_) throw std::runtime_error("AtomicFile::stage after stage, commit or cancel: " + path_);
  open();  // an empty file is still a file
  const std::string& what = to_stdout_ ? std::string("the copy of standard output") : tmp_;
  // A failed fprintf through stream() leaves only the error indicator; a
  // flush that has nothing left to write would not see it.
  if (std::ferror(f_))
    throw std::runtime_error("cannot write " + what + " (for " + option_ + " " + path_ + "): a write to it failed (a full disk, a file size limit?)");
  if (std::fflush(f_) != 0) sys_fail("cannot write", what + " (for " + option_ + " " + path_ + ")");
  if (!to_stdout_) {
    if (::fsync(::fileno(f_)) != 0) sys_fail("cannot fsync", tmp_);
    // mkstemp makes the file 0600; results files are ordinary files.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(::fileno(f_), 0666 & ~mask);
    const int rc = std::fclose(f_);
    f_ = nullptr;
    if (rc != 0) sys_fail("cannot close", tmp_);
  }
  staged_ = true;
}

void AtomicFile::publish() {
  if (!staged_ || done_) throw std::runtime_error("AtomicFile::publish without stage, or after commit or cancel: " + path_);
  if (to_stdout_) {
    std::rewind(f_);
    char buf[1 << 14];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f_)) > 0)
      if (std::fwrite(buf, 1, n, stdout) != n) sys_fail("cannot write", "standard output");
    if (std::fflush(stdout) != 0) sys_fail("cannot write", "standard output");
    std::fclose(f_);
    f_ = nullptr;
    done_ = true;
    return;
  }
  if (std::rename(tmp_.c_str(), target_.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp_.c_str());
    errno = e;
    sys_fail("cannot rename onto", target_);
  }
  done_ = true;
  const int dfd = ::open(dir_of(target_).c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

void AtomicFile::cancel() {
  if (f_) {
    std::fclose(f_);
    f_ = nullptr;
  }
  if (!done_ && !tmp_.empty()) ::unlink(tmp_.c_str());
  done_ = true;
}

namespace {
/// What identifies a file: device and inode when it exists, else its
/// absolute path with the links of its directories resolved.
std::string file_identity(const std::string& path) {
  if (path == "-") return "-";
  const std::string t = follow_links(path, path);
  struct stat st {};
  if (::stat(t.c_str(), &st) == 0) return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  std::error_code ec;
  const auto w = std::filesystem::weakly_canonical(std::filesystem::absolute(t, ec), ec);
  return "path " + (ec ? t : w.string());
}
}  // namespace

void require_distinct_files(const std::vector<std::pair<std::string, std::string>>& inputs,
                            const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::vector<std::string> out_ids;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto& [role, path] = outputs[i];
    if (path.empty()) {
      out_ids.emplace_back();
      continue;
    }
    const std::string id = file_identity(path);
    for (const auto& [in_role, in_path] : inputs)
      if (path != "-" && id == file_identity(in_path))
        throw std::invalid_argument(role + " " + path + " is " + in_role + " " + in_path +
                                    ": writing it would destroy an input (give another path)");
    for (std::size_t j = 0; j < i; ++j)
      if (!out_ids[j].empty() && id == out_ids[j])
        throw std::invalid_argument(role + " " + path + " is the same file as " + outputs[j].first + " " + outputs[j].second +
                                    ": each output needs a path of its own");
    out_ids.push_back(id);
  }
}

void write_file_atomically(const std::string& path, const std::string& text) {
  AtomicFile f(path);
  f.write(text);
  f.commit();
}

json read_json_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path + ": " + std::strerror(errno));
  try {
    return json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::runtime_error(path + ": not valid JSON: " + e.what());
  }
}

namespace {
std::string run_command(const std::string& cmd) {
  std::string out;
  if (std::FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

/// The rest of the first line of `path` that starts with `prefix`, after
/// `sep` ("unknown" if none).
std::string line_value(const char* path, const std::string& prefix, const std::string& sep) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(prefix, 0) == 0) {
      const auto c = line.find(sep);
      return c == std::string::npos ? line : line.substr(c + sep.size());
    }
  return "unknown";
}

std::string cpu_model() { return line_value("/proc/cpuinfo", "model name", ": "); }
/// "FCL=0.7.0,libccd=2.1,Bullet=3.24 (double precision),..." (CMake) as an object.
json library_versions() {
  json libs = json::object();
  std::stringstream ss(IDCOL_HARNESS_LIBRARIES);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto eq = item.find('=');
    if (eq != std::string::npos) libs[item.substr(0, eq)] = item.substr(eq + 1).empty() ? "unknown" : item.substr(eq + 1);
  }
  for (const char* l : {"FCL", "libccd", "Bullet", "GLPK"})
    if (!libs.contains(l)) libs[l] = "not in this build";
  return libs;
}

std::string os_name() {
  std::string v = line_value("/etc/os-release", "PRETTY_NAME=", "=");
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  return v;
}

std::string kernel() {
  struct utsname u {};
  if (::uname(&u) != 0) return "unknown";
  return std::string(u.sysname) + " " + u.release + " " + u.machine;
}

std::string run_time_revision() {
  const std::string src = IDCOL_HARNESS_SOURCE_DIR;
  return run_command("git -C '" + src + "' rev-parse HEAD 2>/dev/null");
}
}  // namespace

std::string version_text() {
  const std::string rev = run_time_revision();
  std::string t = std::string("idcol_harness ") + IDCOL_HARNESS_VERSION + ", built from git " + IDCOL_HARNESS_GIT_REVISION;
  if (!rev.empty() && rev != IDCOL_HARNESS_GIT_REVISION) t += " (source tree now at " + rev + ")";
  t += "\n" + std::string(IDCOL_HARNESS_COMPILER) + ", " + IDCOL_HARNESS_BUILD_TYPE + (IDCOL_HARNESS_NATIVE ? ", -march=native" : "") + "\n";
  const json libs = library_versions();
  for (const auto& [name, v] : libs.items()) t += name + " " + v.get<std::string>() + "\n";
  return t;
}

json collect_metadata(int argc, char** argv) {
  json m;
  m["idcol_version"] = IDCOL_HARNESS_VERSION;
  m["libraries"] = library_versions();
  m["os"] = os_name();
  m["kernel"] = kernel();
  m["cpu_model"] = cpu_model();
  m["logical_cores"] = std::thread::hardware_concurrency();
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);
  m["host"] = host;
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  m["date_utc"] = date;
  m["compiler"] = IDCOL_HARNESS_COMPILER;
  m["cxx_flags"] = IDCOL_HARNESS_CXX_FLAGS;
  m["build_type"] = IDCOL_HARNESS_BUILD_TYPE;
  m["native"] = static_cast<bool>(IDCOL_HARNESS_NATIVE);
  m["git_revision_configure"] = IDCOL_HARNESS_GIT_REVISION;
  const std::string src = IDCOL_HARNESS_SOURCE_DIR;
  const std::string rev = run_time_revision();
  m["git_revision"] = rev.empty() ? json(nullptr) : json(rev);
  if (!rev.empty())
    // Dirty: a tracked file outside results/ differs from the revision. The
    // results files themselves are left out: a regeneration that rewrites
    // several of them in turn would otherwise mark every run after the first.
    m["git_dirty"] =
        !run_command("git -C '" + src + "' status --porcelain --untracked-files=no -- . ':(exclude)results' 2>/dev/null").empty();
  std::vector<std::string> args(argv, argv + argc);
  m["command_line"] = args;
  return m;
}
}  // namespace idcol::harness
