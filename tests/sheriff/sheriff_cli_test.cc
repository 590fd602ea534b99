// vimot-sheriff end to end: the binary, its output and its exit status.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "tests/sheriff/proc_scan.h"
#include "tests/sheriff/test_util.h"

using vimot::sheriff::test::CountRunning;
using vimot::sheriff::test::TempDir;

namespace {

struct Result {
  int exit_code{-1};
  std::string output;  // stdout and stderr together.
};

// Runs vimot-sheriff with `args` (already shell-quoted) and collects output.
Result RunSheriff(const std::string& args) {
  const std::string command = std::string("'") + VIMOT_SHERIFF_BIN + "' " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  Result result;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    result.output.append(buffer, n);
  }
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string WriteConfig(const TempDir& dir, const std::string& name,
                        const std::string& text) {
  const std::string path = dir.path() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("--help prints usage and the config format") {
  const Result r = RunSheriff("--help");
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("usage: vimot-sheriff") == 0);
  CHECK(r.output.find("--exit-when CMD") != std::string::npos);
  CHECK(r.output.find("wait cmd|group") != std::string::npos);
}

TEST_CASE("--list prints groups, commands and scripts") {
  TempDir dir;
  const std::string path = WriteConfig(dir, "list.pmd", R"(
    group "0.sensors" { cmd "sim" { exec = "${VIMOT_BIN}/vimot-sim"; auto_respawn = "true"; } }
    script "all" { start group "0.sensors"; wait ms 10; }
  )");
  const Result r = RunSheriff("--list '" + path + "'");
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("group \"0.sensors\"") != std::string::npos);
  CHECK(r.output.find("cmd \"sim\"  host=localhost auto_respawn") != std::string::npos);
  CHECK(r.output.find("exec: ${VIMOT_BIN}/vimot-sim") != std::string::npos);
  CHECK(r.output.find("    wait ms 10;") != std::string::npos);
}

TEST_CASE("a bad config or command line exits 2 with a message") {
  TempDir dir;
  const std::string bad = WriteConfig(dir, "bad.pmd", "cmd \"a\" {\n  exec = \"x\"\n}\n");
  Result r = RunSheriff("'" + bad + "'");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("bad.pmd:3:1: error: expected ';' after the value of 'exec', "
                      "found '}'") != std::string::npos);

  r = RunSheriff("'" + dir.path() + "/missing.pmd'");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("cannot open sheriff config") != std::string::npos);

  const std::string ok = WriteConfig(dir, "ok.pmd", "cmd \"a\" { exec = \"true\"; }\n");
  r = RunSheriff("--exit-when b '" + ok + "'");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("unknown command 'b'") != std::string::npos);
  r = RunSheriff("--duration soon '" + ok + "'");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("--duration needs a positive number") != std::string::npos);
  r = RunSheriff("--bogus '" + ok + "'");
  CHECK(r.exit_code == 2);
  r = RunSheriff("");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("no config file given") != std::string::npos);
}

TEST_CASE("a demo run: simulator to completion, services stopped, its exit code") {
  TempDir dir;
  const std::string path = WriteConfig(dir, "demo.pmd", R"(
    group "0.sim" { cmd "sim" { exec = "echo bin=$VIMOT_BIN; exit 7"; } }
    group "1.services" { cmd "logger" { exec = "sleep 30"; stop_signal = 15; } }
  )");
  // VIMOT_BIN defaults to the binary's directory when not set.
  const Result r = RunSheriff("--exit-when=sim '" + path + "'");
  INFO(r.output);
  CHECK(r.exit_code == 7);
  std::string bin_dir = VIMOT_SHERIFF_BIN;
  bin_dir = bin_dir.substr(0, bin_dir.rfind('/'));
  if (std::getenv("VIMOT_BIN") == nullptr) {
    CHECK(r.output.find("[sim] bin=" + bin_dir + "\n") != std::string::npos);
  }
  CHECK(r.output.find("[sheriff] 'logger' stopped") != std::string::npos);
}

TEST_CASE("a directory as the config or a too deep config exits 2 with a message") {
  TempDir dir;
  Result r = RunSheriff("'" + dir.path() + "'");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("is a directory, not a file") != std::string::npos);

  std::string chain;
  for (int i = 0; i < 40000; ++i) {
    chain += "script \"s" + std::to_string(i) + "\" { run_script \"s" + std::to_string(i + 1) + "\"; }\n";
  }
  chain += "script \"s40000\" { wait ms 1; }\n";
  r = RunSheriff("'" + WriteConfig(dir, "chain.pmd", chain) + "'");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("run_script nests scripts more than 64 deep") != std::string::npos);
}

TEST_CASE("kill -9 of the sheriff leaves none of its commands running") {
  TempDir dir;
  // A program run directly, the program of a shell list, and a pipeline.
  const std::string path = WriteConfig(dir, "kill.pmd", R"(
    cmd "direct" { exec = "sleep 30.131"; stop_time_allowed = 1; }
    cmd "list" { exec = "sleep 30.132; true"; stop_time_allowed = 1; }
    cmd "pipeline" { exec = "sleep 30.133 | cat"; stop_time_allowed = 1; }
  )");
  const std::string log = dir.path() + "/sheriff.log";
  const pid_t sheriff = ::fork();
  REQUIRE(sheriff >= 0);
  if (sheriff == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
    ::execl(VIMOT_SHERIFF_BIN, VIMOT_SHERIFF_BIN, path.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto running = [] {
    return CountRunning({"sleep", "30.131"}) + CountRunning({"sleep", "30.132"}) +
           CountRunning({"sleep", "30.133"});
  };
  const auto wait_for = [](const std::function<bool()>& done) {
    const auto end = std::chrono::steady_clock::now() + vimot::sheriff::test::kConditionTimeout;
    while (!done() && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return done();
  };
  const bool started = wait_for([&] { return running() == 3; });
  ::kill(sheriff, SIGKILL);
  int status = 0;
  ::waitpid(sheriff, &status, 0);
  REQUIRE(started);
  CHECK(WIFSIGNALED(status));
  // Within the commands' stop_time_allowed (1 s) and a margin.
  CHECK(wait_for([&] { return running() == 0; }));
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  INFO(text.str());
  CHECK(text.str().find("[sheriff watchdog] the sheriff ended without stopping its commands") != std::string::npos);
}
