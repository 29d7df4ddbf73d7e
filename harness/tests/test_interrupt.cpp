// An interrupted run leaves no partial results file: the atomic writer's
// cancel path, and the command line under SIGINT.
#include <gtest/gtest.h>

#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io/files.hpp"

namespace idcol::harness {
namespace {

std::string make_temp_dir() {
  char templ[] = "/tmp/idcol_harness_test.XXXXXX";
  const char* d = ::mkdtemp(templ);
  EXPECT_NE(d, nullptr);
  return d ? d : "/tmp";
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
  }
  return out;
}

void remove_dir(const std::string& dir) {
  for (const auto& f : list_dir(dir)) ::unlink((dir + "/" + f).c_str());
  ::rmdir(dir.c_str());
}

bool exists(const std::string& p) { return ::access(p.c_str(), F_OK) == 0; }

TEST(AtomicFile, CommitPublishesCancelLeavesNothing) {
  const std::string dir = make_temp_dir();
  {
    AtomicFile f(dir + "/a.json");
    f.write("{\"partial\": ");
    EXPECT_TRUE(exists(f.temp_path()));
    EXPECT_FALSE(exists(dir + "/a.json"));
    f.cancel();
  }
  EXPECT_TRUE(list_dir(dir).empty());
  {
    AtomicFile f(dir + "/b.json");
    f.write("{}");
  }  // destroyed without commit
  EXPECT_TRUE(list_dir(dir).empty());
  write_file_atomically(dir + "/c.json", "{\"ok\": 1}\n");
  EXPECT_EQ(list_dir(dir), std::vector<std::string>{"c.json"});
  EXPECT_EQ(read_json_file(dir + "/c.json")["ok"], 1);
  // Replacing an existing file: the old one stays whole until the rename.
  {
    AtomicFile f(dir + "/c.json");
    f.write("{\"ok\": ");
  }
  EXPECT_EQ(read_json_file(dir + "/c.json")["ok"], 1);
  remove_dir(dir);
}

// The target is checked before any work: what is not a regular file's path
// is refused by name; a symbolic link is written through, not replaced.
TEST(AtomicFile, RefusesNonRegularTargetsAndWritesThroughLinks) {
  const std::string dir = make_temp_dir();
  auto refused = [](const std::string& path, const std::string& what) {
    try {
      AtomicFile f(path, "-o");
      ADD_FAILURE() << path << " accepted";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("-o " + path), std::string::npos) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
    }
  };
  ::mkdir((dir + "/sub").c_str(), 0755);
  refused(dir + "/sub", "a directory");
  refused("/dev/null", "a character device");
  ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0644), 0);
  refused(dir + "/fifo", "a FIFO");
  refused(dir + "/missing/r.json", "No such file or directory");
  // A link to a file, and a dangling one: the file pointed to is written.
  std::ofstream(dir + "/real.json") << "old";
  ASSERT_EQ(::symlink("real.json", (dir + "/link.json").c_str()), 0);
  ASSERT_EQ(::symlink("new.json", (dir + "/dangling.json").c_str()), 0);
  write_file_atomically(dir + "/link.json", "{\"via\": 1}\n");
  write_file_atomically(dir + "/dangling.json", "{\"via\": 2}\n");
  struct stat st {};
  ASSERT_EQ(::lstat((dir + "/link.json").c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
  EXPECT_EQ(read_json_file(dir + "/real.json")["via"], 1);
  EXPECT_EQ(read_json_file(dir + "/new.json")["via"], 2);
  // A link to a device is refused like the device.
  ASSERT_EQ(::symlink("/dev/full", (dir + "/full.json").c_str()), 0);
  refused(dir + "/full.json", "a character device");
  for (const char* f : {"sub"}) ::rmdir((dir + "/" + f).c_str());
  remove_dir(dir);
}

// Nothing exists beside the target until the first write, and a temporary
// whose process is gone (SIGKILL while writing) is removed by the next
// writer of the same target; a live process's temporary is left alone.
TEST(AtomicFile, TemporariesAreCreatedLateAndStaleOnesRemoved) {
  const std::string dir = make_temp_dir();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) std::_Exit(0);
  ::waitpid(child, nullptr, 0);  // a pid that no longer runs
  const std::string stale = "." + std::string("a.json.idcol-tmp.") + std::to_string(child) + ".AbC123";
  const std::string live = "." + std::string("a.json.idcol-tmp.") + std::to_string(::getpid()) + ".XyZ789";
  const std::string other = "." + std::string("b.json.idcol-tmp.") + std::to_string(child) + ".AbC123";
  for (const std::string& n : {stale, live, other}) std::ofstream(dir + "/" + n) << "";
  {
    AtomicFile f(dir + "/a.json");
    EXPECT_EQ(f.temp_path(), "");
    std::vector<std::string> names = list_dir(dir);
    std::sort(names.begin(), names.end());
    std::vector<std::string> want{live, other};
    std::sort(want.begin(), want.end());
    EXPECT_EQ(names, want);
    f.write("{}");
    EXPECT_EQ(f.temp_path().find(dir + "/.a.json.idcol-tmp." + std::to_string(::getpid()) + "."), 0u) << f.temp_path();
    f.commit();
  }
  EXPECT_TRUE(exists(dir + "/a.json"));
  for (const std::string& n : {live, other}) ::unlink((dir + "/" + n).c_str());
  remove_dir(dir);
}

// A long but legal name (up to NAME_MAX, 255 bytes) is written: the
// temporary beside it keeps only the first 200 bytes of the name, so the 26
// or so bytes it adds do not make it too long.
TEST(AtomicFile, ALongLegalNameIsWritten) {
  const std::string dir = make_temp_dir();
  for (std::size_t n : {200u, 230u, 245u, 255u}) {
    const std::string name = std::string(n - 5, 'r') + ".json";
    write_file_atomically(dir + "/" + name, "{\"n\": " + std::to_string(n) + "}\n");
    EXPECT_EQ(read_json_file(dir + "/" + name)["n"], n);
    AtomicFile f(dir + "/" + name);
    f.write("{}");
    EXPECT_EQ(f.temp_path().find(dir + "/." + name.substr(0, 200) + ".idcol-tmp."), 0u) << f.temp_path();
    f.cancel();
    ::unlink((dir + "/" + name).c_str());
  }
  EXPECT_TRUE(list_dir(dir).empty());
  remove_dir(dir);
}

TEST(AtomicFile, AnOutputThatIsAnInputOrAnotherOutputIsRefused) {
  const std::string dir = make_temp_dir();
  std::ofstream(dir + "/s.toml") << "name = \"s\"\n";
  ASSERT_EQ(::symlink("s.toml", (dir + "/alias.toml").c_str()), 0);
  auto refused = [](const std::vector<std::pair<std::string, std::string>>& in,
                    const std::vector<std::pair<std::string, std::string>>& out, const std::string& what) {
    try {
      require_distinct_files(in, out);
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused({{"the scene", dir + "/s.toml"}}, {{"-o", dir + "/s.toml"}}, "-o " + dir + "/s.toml is the scene");
  refused({{"the scene", dir + "/s.toml"}}, {{"-o", dir + "/alias.toml"}}, "destroy an input");
  refused({{"the scene", dir + "/s.toml"}}, {{"-o", dir + "/a.json"}, {"--failures", dir + "/./a.json"}},
          "--failures " + dir + "/./a.json is the same file as -o " + dir + "/a.json");
  EXPECT_NO_THROW(require_distinct_files({{"the scene", dir + "/s.toml"}},
                                         {{"-o", dir + "/a.json"}, {"--failures", ""}, {"--per-pose", dir + "/a.csv"}}));
  EXPECT_NO_THROW(require_distinct_files({{"the scene", dir + "/s.toml"}}, {{"-o", "-"}, {"--failures", dir + "/f.json"}}));
  ::unlink((dir + "/alias.toml").c_str());
  remove_dir(dir);
}

TEST(CommandLine, SigintLeavesNoPartialResults) {
  const std::string dir = make_temp_dir();
  const std::string scene = dir + "/long.toml";
  std::ofstream(scene) << R"(
name = "long"
[shapes]
SE = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
[sweep]
generator = "paper"
poses = 100000000
[run]
pairs = "all"
passes = ["cold"]
record = ["timing", "iterations", "residuals", "failures", "per_pose"]
)";
  const std::string out = dir + "/results.json";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    ::execl(IDCOL_HARNESS_EXE, IDCOL_HARNESS_EXE, "run", scene.c_str(), "-o", out.c_str(), "--no-progress", nullptr);
    std::_Exit(127);
  }
  // Wait until the run has started writing its per-pose rows (the only
  // output written during the run; main.cpp installs the SIGINT handler
  // before it), then interrupt it.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (list_dir(dir).size() < 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const bool started = list_dir(dir).size() >= 2;
  ::kill(pid, SIGINT);
  ASSERT_TRUE(started) << "the run never opened its outputs";
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(exists(out));
  EXPECT_EQ(list_dir(dir), std::vector<std::string>{"long.toml"});  // no temp, per-pose or failures files
  remove_dir(dir);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs the harness with `args` in a child whose files may not grow beyond
/// `limit_bytes` (RLIMIT_FSIZE, SIGXFSZ ignored: a write past it fails with
/// EFBIG as on a full disk); returns the exit status, stderr in *err.
int run_with_file_size_limit(const std::vector<std::string>& args, rlim_t limit_bytes, const std::string& err_path) {
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen(err_path.c_str(), "w", stderr);
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit lim{limit_bytes, limit_bytes};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    std::vector<char*> argv{const_cast<char*>(IDCOL_HARNESS_EXE)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(IDCOL_HARNESS_EXE, argv.data());
    std::_Exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A run commits all its outputs or none: when one of them cannot be written
// (here the per-pose CSV, past a file size limit that the failures file and
// the results fit under), the old results and the old failures file beside
// them stay as they were, and no temporary is left.
TEST(CommandLine, AFailedWriteLeavesEveryOldOutput) {
  const std::string dir = make_temp_dir();
  const std::string scene = dir + "/s.toml";
  std::ofstream(scene) << R"(
name = "s"
[shapes]
A = { family = "sphere", R = 1.0 }
B = { family = "superellipsoid", a = 0.5, b = 1.0, c = 1.5, n = 8 }
[sweep]
generator = "paper"
poses = 2000
[run]
pairs = "all"
passes = ["cold"]
record = ["iterations", "failures", "per_pose"]
)";
  const std::string out = dir + "/r.json", fails = dir + "/r.failures.json", poses = dir + "/r.poses.csv";
  std::ofstream(out) << "old results\n";
  std::ofstream(fails) << "old failures\n";
  std::ofstream(poses) << "old poses\n";
  const std::string err = dir + "/err.txt";
  // 2000 poses x 3 pairs of per-pose rows are far over 64 KiB; the
  // failures file (no failure) and the results are a few KiB each.
  EXPECT_EQ(run_with_file_size_limit({"run", scene, "-o", out, "--no-progress"}, 64 * 1024, err), 1);
  const std::string msg = read_text(err);
  EXPECT_NE(msg.find("--per-pose " + poses), std::string::npos) << msg;
  EXPECT_NE(msg.find("no output written"), std::string::npos) << msg;
  EXPECT_EQ(read_text(out), "old results\n");
  EXPECT_EQ(read_text(fails), "old failures\n");
  EXPECT_EQ(read_text(poses), "old poses\n");
  std::vector<std::string> names = list_dir(dir);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"err.txt", "r.failures.json", "r.json", "r.poses.csv", "s.toml"}));
  // Without the limit all three are replaced.
  EXPECT_EQ(run_with_file_size_limit({"run", scene, "-o", out, "--no-progress"}, RLIM_INFINITY, err), 0) << read_text(err);
  EXPECT_EQ(read_json_file(out).value("schema", std::string()).empty(), false);
  EXPECT_EQ(read_json_file(fails)["failures"].size(), 0u);
  EXPECT_NE(read_text(poses), "old poses\n");
  remove_dir(dir);
}

// table, info and compare report a standard output that cannot be written
// (here /dev/full) with a message and a non-zero status.
TEST(CommandLine, AnUnwritableStandardOutputIsAnError) {
  const std::string dir = make_temp_dir();
  const std::string scene = dir + "/s.toml";
  std::ofstream(scene) << R"(
name = "s"
[shapes]
A = { family = "sphere", R = 1.0 }
[sweep]
generator = "paper"
poses = 10
[run]
pairs = "all"
passes = ["cold"]
record = ["iterations"]
)";
  const std::string out = dir + "/r.json", err = dir + "/err.txt";
  ASSERT_EQ(run_with_file_size_limit({"run", scene, "-o", out, "--no-progress"}, RLIM_INFINITY, err), 0) << read_text(err);
  const std::string exe = IDCOL_HARNESS_EXE;
  for (const auto& [args, want] : std::vector<std::pair<std::string, int>>{
           {"table " + out, 1}, {"info " + out, 1}, {"compare " + out + " " + out, 2}, {"shapes", 1}, {"--version", 1}}) {
    const int rc = std::system((exe + " " + args + " > /dev/full 2> " + err).c_str());
    EXPECT_TRUE(WIFEXITED(rc)) << args;
    EXPECT_EQ(WEXITSTATUS(rc), want) << args;
    const std::string msg = read_text(err);
    EXPECT_NE(msg.find("cannot write standard output"), std::string::npos) << args << ": " << msg;
  }
  remove_dir(dir);
}

}  // namespace
}  // namespace idcol::harness
