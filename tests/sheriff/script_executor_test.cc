// Scripts against a real ProcessRunner: ordering, waits, run_script, errors.
#include <catch2/catch.hpp>

#include "procs/sheriff/script_executor.h"
#include "procs/sheriff/sheriff_config_parser.h"
#include "tests/sheriff/test_util.h"

using namespace vimot::sheriff;
using namespace vimot::sheriff::test;

namespace {

// Steps the script and polls the runner until the script is done.
bool RunScript(ScriptExecutor* script, ProcessRunner* runner) {
  return PollUntil(runner, [&] {
    script->Step();
    return script->done();
  });
}

Clock::time_point EventTime(const Recorder& rec, const std::string& text) {
  const int i = rec.EventIndex(text);
  REQUIRE(i >= 0);
  return rec.events[i].time;
}

}  // namespace

TEST_CASE("a script sequences starts, timed waits and status waits") {
  const SheriffConfig config = ParseSheriffConfig(R"(
    cmd "server" { exec = "echo server-up; sleep 30"; stop_signal = 15; }
    cmd "client" { exec = "sleep 0.1; echo client-done"; }
    script "bringup" {
      start cmd "server" wait "running";
      wait ms 200;
      start cmd "client";
      wait cmd "client" status "stopped";
      run_script "teardown";
    }
    script "teardown" {
      stop cmd "server" wait "stopped";
    }
  )", "script.pmd");
  Recorder rec;
  ProcessRunner runner(config.commands(), rec.Options());
  auto on_event = rec.Options().on_event;
  ScriptExecutor script(config, &runner, "bringup", on_event);
  REQUIRE(RunScript(&script, &runner));
  INFO(rec.AllEvents());
  CHECK_FALSE(script.failed());

  // wait ms 200 between the two starts.
  CHECK(EventTime(rec, "started 'client'") - EventTime(rec, "started 'server'") >=
        milliseconds(200));
  // wait status "stopped": the server is stopped only after the client ended.
  CHECK(rec.EventIndex("'client' exited with code 0") < rec.EventIndex("stopping 'server'"));
  // stop ... wait "stopped": the script ends only after the server stopped.
  CHECK(rec.EventIndex("'server' stopped") < rec.EventIndex("script 'bringup' finished"));
  CHECK(rec.HasOutput("[client] client-done"));
  CHECK(runner.state("server").status == CommandStatus::kStopped);
  CHECK(runner.state("client").status == CommandStatus::kExited);
  CHECK(runner.IsIdle());
}

TEST_CASE("groups, restart and wait group status") {
  const SheriffConfig config = ParseSheriffConfig(R"(
    group "0.base" {
      cmd "a" { exec = "sleep 30"; stop_signal = 15; }
      group "sub" { cmd "b" { exec = "sleep 30"; stop_signal = 15; } }
    }
    cmd "far" { exec = "sleep 30"; host = "elsewhere"; }
    script "s" {
      start group "0.base" wait "running";
      restart cmd "b" wait "running";
      start cmd "far";
      wait group "0.base" status "running";
      stop everything wait "stopped";
    }
  )", "groups.pmd");
  Recorder rec;
  ProcessRunner runner(config.commands(), rec.Options());
  ScriptExecutor script(config, &runner, "s", rec.Options().on_event);
  REQUIRE(RunScript(&script, &runner));
  INFO(rec.AllEvents());
  CHECK_FALSE(script.failed());
  CHECK(runner.state("a").start_count == 1);
  CHECK(runner.state("b").start_count == 2);
  CHECK(runner.state("far").status == CommandStatus::kRemote);
  CHECK(runner.state("a").status == CommandStatus::kStopped);
  CHECK(runner.state("b").status == CommandStatus::kStopped);
}

TEST_CASE("waiting for a command that can no longer run fails the script") {
  const SheriffConfig config = ParseSheriffConfig(R"(
    cmd "oneshot" { exec = "exit 4"; }
    cmd "idle" { exec = "true"; }
    script "s" {
      start cmd "oneshot";
      wait cmd "oneshot" status "stopped";
      wait cmd "oneshot" status "running";
      start cmd "idle";
    }
  )", "fail.pmd");
  Recorder rec;
  ProcessRunner runner(config.commands(), rec.Options());
  ScriptExecutor script(config, &runner, "s", rec.Options().on_event);
  REQUIRE(RunScript(&script, &runner));
  CHECK(script.failed());
  CHECK(script.error().find("cmd 'oneshot' will not run again (exited with code 4)") != std::string::npos);
  CHECK(script.error().find("fail.pmd:7:7") != std::string::npos);
  // Nothing after the failed wait ran.
  CHECK(runner.state("idle").start_count == 0);
}

TEST_CASE("CommandsStartedBy follows run_script") {
  const SheriffConfig config = ParseSheriffConfig(R"(
    group "g" { cmd "a" { exec = "x"; } cmd "b" { exec = "x"; } }
    cmd "c" { exec = "x"; }
    cmd "d" { exec = "x"; }
    script "outer" { start cmd "d"; run_script "inner"; stop cmd "c"; }
    script "inner" { restart group "g"; }
  )", "s.pmd");
  CHECK(ScriptExecutor::CommandsStartedBy(config, "outer") ==
        std::vector<std::string>{"a", "b", "d"});
  CHECK_THROWS_AS(ScriptExecutor::CommandsStartedBy(config, "nope"),
                  std::invalid_argument);
  ProcessRunner runner(config.commands());
  CHECK_THROWS_WITH(ScriptExecutor(config, &runner, "nope"),
                    Catch::Contains("unknown script 'nope'"));
}
