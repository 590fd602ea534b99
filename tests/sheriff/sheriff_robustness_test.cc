// Issue 12, the sheriff: a command's process group is never lost, the pid and
// exit status are the program's own, and deep configs are clear errors.
// (That commands die with a SIGKILLed sheriff is in sheriff_cli_test.cc: it
// needs the real binary.)
#include <catch2/catch.hpp>

#include <signal.h>

#include <string>

#include "procs/sheriff/process_runner.h"
#include "procs/sheriff/sheriff_config_parser.h"
#include "tests/sheriff/proc_scan.h"
#include "tests/sheriff/test_util.h"

using namespace vimot::sheriff;
using namespace vimot::sheriff::test;

TEST_CASE("one simple command is exec'd by the shell; lists, pipelines and builtins are not") {
  CHECK(ShellCommandLine("sleep 1") == "exec sleep 1");
  CHECK(ShellCommandLine("  /bin/prog --x 'a;b' \"c|d\" > out.txt") == "exec   /bin/prog --x 'a;b' \"c|d\" > out.txt");
  CHECK(ShellCommandLine("prog a\\;b") == "exec prog a\\;b");
  CHECK(ShellCommandLine("a; b") == "a; b");
  CHECK(ShellCommandLine("a | b") == "a | b");
  CHECK(ShellCommandLine("a && b") == "a && b");
  CHECK(ShellCommandLine("a &") == "a &");
  CHECK(ShellCommandLine("prog 2>&1") == "exec prog 2>&1");
  CHECK(ShellCommandLine("prog <&3") == "exec prog <&3");
  CHECK(ShellCommandLine("prog &>log") == "prog &>log");
  CHECK(ShellCommandLine("a & b") == "a & b");
  CHECK(ShellCommandLine("a&&b") == "a&&b");
  CHECK(ShellCommandLine("(a)") == "(a)");
  CHECK(ShellCommandLine("a\nb") == "a\nb");
  CHECK(ShellCommandLine("X=1 prog") == "X=1 prog");
  CHECK(ShellCommandLine("cd /tmp") == "cd /tmp");
  CHECK(ShellCommandLine("exit 3") == "exit 3");
  CHECK(ShellCommandLine("trap 'x' TERM") == "trap 'x' TERM");
  CHECK(ShellCommandLine("echo 'unterminated") == "echo 'unterminated");
  CHECK(ShellCommandLine("") == "");
}

TEST_CASE("the pid and a clean exit on the stop signal are the program's own, not the shell's") {
  Recorder rec;
  // The program (an inner shell here) handles SIGTERM and exits 0. Run
  // through an outer `sh -c` that stays, the outer shell would die of the
  // signal and the stop would read "signal 15".
  CommandSpec clean = Command(
      "clean", "sh -c 'trap \"exit 0\" TERM; echo ready; while :; do sleep 0.05; done'");
  CommandSpec sleeper = Command("sleeper", "sleep 30.125");
  ProcessRunner runner({clean, sleeper}, rec.Options());
  runner.Start("clean");
  runner.Start("sleeper");
  REQUIRE(PollUntil(&runner, [&] { return rec.HasOutput("[clean] ready"); }));
  // The pid is the wrapper's until its exec, microseconds after the fork:
  // wait for the exec, then it must be the program's own.
  CHECK(PollUntil(&runner, [&] { return Program(runner.state("sleeper").pid) == "sleep"; }));
  CHECK(Program(runner.state("clean").pid) == "sh");

  runner.Stop("clean");
  runner.Stop("sleeper");
  REQUIRE(PollUntil(&runner, [&] { return runner.IsIdle(); }));
  const CommandState& c = runner.state("clean");
  REQUIRE(c.last_exit.has_value());
  CHECK(c.last_exit->signal == 0);
  CHECK(c.last_exit->exit_code == 0);
  CHECK(rec.EventIndex("'clean' stopped; it ended with code 0") >= 0);
  // A program without a handler ends by the signal: that is what was asked.
  CHECK(runner.state("sleeper").last_exit->signal == SIGTERM);
  CHECK(rec.EventIndex("'sleeper' stopped; it ended with signal 15 (Terminated), its stop signal, as asked") >= 0);
  CHECK(CountRunning({"sleep", "30.125"}) == 0);
}

TEST_CASE("kill -9 of a command's shell stops the rest of its group before the respawn") {
  Recorder rec;
  RunnerOptions options = rec.Options();
  options.respawn_backoff_initial = milliseconds(50);
  // The shell stays (a list), with the program as its child.
  CommandSpec spec = Command("wrapped", "sleep 30.25; true");
  spec.auto_respawn = true;
  spec.stop_time_allowed = milliseconds(2000);
  pid_t old_group = 0;
  int old_members_at_respawn = -1;
  const auto on_event = options.on_event;
  options.on_event = [&](const std::string& message) {
    if (message.find("respawned 'wrapped'") != std::string::npos) {
      old_members_at_respawn = LiveGroupMembers(old_group);
    }
    on_event(message);
  };
  ProcessRunner runner({spec}, options);
  runner.Start("wrapped");
  old_group = runner.state("wrapped").pid;
  REQUIRE(PollUntil(&runner, [&] { return LiveGroupMembers(old_group) == 2; }));  // sh + sleep
  CHECK(CountRunning({"sleep", "30.25"}) == 1);

  REQUIRE(::kill(old_group, SIGKILL) == 0);  // the shell only
  REQUIRE(PollUntil(&runner, [&] { return runner.state("wrapped").start_count == 2; }));
  INFO(rec.AllEvents());
  CHECK(old_members_at_respawn == 0);
  CHECK(rec.EventIndex("'wrapped' (pid " + std::to_string(old_group) +
                       ") ended with signal 9 (Killed) but left processes in its group") >= 0);
  const pid_t new_group = runner.state("wrapped").pid;
  REQUIRE(PollUntil(&runner, [&] { return LiveGroupMembers(new_group) == 2; }));
  CHECK(CountRunning({"sleep", "30.25"}) == 1);  // exactly one instance
  CHECK(runner.state("wrapped").last_exit->signal == SIGKILL);
}

TEST_CASE("a command whose shell was killed, without respawn, counts as exited once its group is gone") {
  Recorder rec;
  CommandSpec spec = Command("wrapped", "sleep 30.375; true");
  spec.stop_time_allowed = milliseconds(2000);
  ProcessRunner runner({spec}, rec.Options());
  runner.Start("wrapped");
  const pid_t group = runner.state("wrapped").pid;
  REQUIRE(PollUntil(&runner, [&] { return LiveGroupMembers(group) == 2; }));
  REQUIRE(::kill(group, SIGKILL) == 0);
  REQUIRE(PollUntil(&runner, [&] { return runner.state("wrapped").status == CommandStatus::kExited; }));
  CHECK(LiveGroupMembers(group) == 0);
  CHECK(runner.IsIdle());
}

TEST_CASE("StopAll while a killed shell's group is being stopped ends it as stopped, not respawned") {
  Recorder rec;
  RunnerOptions options = rec.Options();
  options.respawn_backoff_initial = milliseconds(50);
  // The program ignores the stop signal, so its group outlives the shell
  // until SIGKILL.
  CommandSpec spec = Command("stubborn", "sh -c 'trap \"\" TERM; echo ready; while :; do sleep 0.05; done'; true");
  spec.auto_respawn = true;
  spec.stop_time_allowed = milliseconds(1000);
  ProcessRunner runner({spec}, options);
  runner.Start("stubborn");
  const pid_t group = runner.state("stubborn").pid;
  REQUIRE(PollUntil(&runner, [&] { return rec.HasOutput("[stubborn] ready"); }));
  REQUIRE(::kill(group, SIGKILL) == 0);
  REQUIRE(PollUntil(&runner, [&] { return rec.EventIndex("left processes in its group") >= 0; }));
  runner.StopAll();
  REQUIRE(PollUntil(&runner, [&] { return runner.IsIdle(); }));
  INFO(rec.AllEvents());
  CHECK(runner.state("stubborn").status == CommandStatus::kStopped);
  CHECK(runner.state("stubborn").start_count == 1);
  // The stop ends when SIGKILL is sent; the kernel ends the members a moment
  // later, so wait for that rather than read /proc in the same instant.
  CHECK(PollUntil(&runner, [&] { return LiveGroupMembers(group) == 0; }));
}

namespace {
ConfigParseError ParseError(const std::string& text) {
  try {
    ParseSheriffConfig(text, "deep.pmd");
  } catch (const ConfigParseError& e) {
    return e;
  }
  FAIL("expected a ConfigParseError");
  throw std::logic_error("unreachable");
}

// Scripts s0 -> s1 -> ... -> s<n-1>, each running the next.
std::string ChainedScripts(int n) {
  std::string text;
  for (int i = 0; i < n; ++i) {
    text += "script \"s" + std::to_string(i) + "\" { " +
            (i + 1 < n ? "run_script \"s" + std::to_string(i + 1) + "\"; " : std::string("wait ms 1; ")) + "}\n";
  }
  return text;
}

std::string NestedGroups(int n) {
  std::string text;
  for (int i = 0; i < n; ++i) text += "group \"g\" {\n";
  text += "cmd \"c\" { exec = \"true\"; }\n";
  for (int i = 0; i < n; ++i) text += "}\n";
  return text;
}
}  // namespace

TEST_CASE("40 000 chained run_scripts and 50 000 nested groups are clear errors, not a stack overflow") {
  const ConfigParseError chain = ParseError(ChainedScripts(40000));
  CHECK(chain.message().find("run_script nests scripts more than 64 deep") != std::string::npos);
  const ConfigParseError groups = ParseError(NestedGroups(50000));
  CHECK(groups.message() == "groups nest more than 32 levels deep (group \"g\")");
  CHECK(groups.location().line == 33);
  std::string path = "g";
  for (int i = 1; i < 50000; ++i) path += "/g";
  const ConfigParseError attr = ParseError("cmd \"c\" { exec = \"true\"; group = \"" + path + "\"; }");
  CHECK(attr.message().find("nests more than 32 levels deep") != std::string::npos);
  // The order of the scripts in the file does not hide the depth.
  std::string reversed;
  for (int i = 99; i >= 0; --i) {
    reversed += "script \"s" + std::to_string(i) + "\" { " +
                (i < 99 ? "run_script \"s" + std::to_string(i + 1) + "\"; " : std::string("wait ms 1; ")) + "}\n";
  }
  CHECK(ParseError(reversed).message().find("more than 64 deep") != std::string::npos);
}

TEST_CASE("configs at the depth limits are accepted") {
  const SheriffConfig chain = ParseSheriffConfig(ChainedScripts(kMaxScriptNesting), "ok.pmd");
  CHECK(chain.scripts().size() == static_cast<std::size_t>(kMaxScriptNesting));
  const SheriffConfig groups = ParseSheriffConfig(NestedGroups(kMaxGroupDepth), "ok.pmd");
  CHECK(groups.groups().size() == static_cast<std::size_t>(kMaxGroupDepth));
  CHECK(groups.FindCommand("c")->group.size() == 2 * kMaxGroupDepth - 1);
}

TEST_CASE("a directory given as the config is an error") {
  TempDir dir;
  try {
    LoadSheriffConfig(dir.path());
    FAIL("expected an exception");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()) == "sheriff config '" + dir.path() + "' is a directory, not a file");
  }
}
