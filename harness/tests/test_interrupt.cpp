// An interrupted run leaves no partial results file: the atomic writer's
// cancel path, and the command line under SIGINT.
#include <gtest/gtest.h>

#include <dirent.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "idcol_harness/writers.hpp"

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
  // Wait until the run has opened its three temporary outputs (main.cpp
  // installs the SIGINT handler before it creates them), then interrupt it.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (list_dir(dir).size() < 4 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const bool started = list_dir(dir).size() >= 4;
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

}  // namespace
}  // namespace idcol::harness
