// procman's deputy protocol without a network: RemoteCommands (the
// sheriff's half) and DeputyNode (the deputy's) exchange orders and info
// directly, the way vimot-sheriff --lcm and vimot-deputy do over LCM, and
// run real child processes.
#include <catch2/catch.hpp>

#include <signal.h>

#include <optional>

#include "procs/deputy/deputy_node.h"
#include "procs/sheriff/remote_commands.h"
#include "procs/sheriff/sheriff_config_parser.h"
#include "tests/sheriff/test_util.h"

using namespace vimot::sheriff;
using namespace vimot::sheriff::test;
using vimot::deputy::DeputyNode;
using vimot::deputy::DeputyOptions;

namespace {

constexpr char kConfig[] = R"(
  cmd "talker" {
    exec = "echo hello from talker; exec sleep 30";
    host = "vehicle";
    stop_signal = 15;
    stop_time_allowed = 5;
  }
  cmd "stubborn" {
    exec = "trap '' TERM; echo ready; while true; do sleep 0.05; done";
    host = "vehicle";
    stop_signal = 15;
    stop_time_allowed = 1;
  }
  cmd "quitter" { exec = "exit 3"; host = "vehicle"; }
  cmd "ground" { exec = "sleep 30"; host = "ground"; }
)";

int64_t Now() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// One sheriff, one deputy ("vehicle"), and the messages between them.
struct Link {
  SheriffConfig config = ParseSheriffConfig(kConfig, "test.pmd");
  RemoteCommands sheriff{config, {"test-sheriff", "vehicle"}};
  std::vector<DeputyOutput> outputs;
  DeputyNode deputy{Options(), [this](const DeputyOutput& o) { outputs.push_back(o); }};
  DeputyInfo last_info;

  static DeputyOptions Options() {
    DeputyOptions o;
    o.host = "vehicle";
    o.runner.respawn_backoff_initial = milliseconds(20);
    return o;
  }

  /// One round: orders out, deputy runs, info back.
  void Exchange() {
    for (const DeputyOrders& orders : sheriff.Orders(Now())) deputy.OnOrders(orders, Now());
    deputy.Poll(milliseconds(20), Now());
    last_info = deputy.Info(Now());
    sheriff.OnInfo(last_info);
  }

  bool Until(const std::function<bool()>& done) {
    const Clock::time_point end = Clock::now() + kConditionTimeout;
    while (!done()) {
      if (Clock::now() > end) return false;
      Exchange();
    }
    return true;
  }

  CommandStatus Status(const std::string& name) { return sheriff.state(name).status; }

  std::optional<CommandReport> Report(const std::string& name) {
    const auto id = SheriffIdOf(name);
    for (const CommandReport& r : last_info.cmds) {
      if (r.sheriff_id == id) return r;
    }
    return std::nullopt;
  }

  int32_t SheriffIdOf(const std::string& name) {
    for (const DeputyOrders& orders : sheriff.Orders(0)) {
      for (const CommandOrder& c : orders.cmds) {
        if (c.cmd.name == name) return c.sheriff_id;
      }
    }
    return -1;
  }

  bool Printed(int32_t id, const std::string& text) const {
    for (const DeputyOutput& o : outputs) {
      if (o.sheriff_id == id && o.text == text && o.deputy_name == "vehicle") return true;
    }
    return false;
  }
};

bool Alive(pid_t pid) { return pid > 0 && ::kill(pid, 0) == 0; }

}  // namespace

TEST_CASE("sheriff starts, stops and restarts a command on a deputy") {
  Link link;
  const int32_t id = link.SheriffIdOf("talker");
  // Orders go to each host's deputy: vehicle gets three commands, ground one.
  const std::vector<DeputyOrders> orders = link.sheriff.Orders(Now());
  REQUIRE(orders.size() == 2);
  CHECK(orders[0].host == "ground");
  CHECK(orders[1].host == "vehicle");
  CHECK(orders[1].cmds.size() == 3);

  CHECK(link.Status("talker") == CommandStatus::kStopped);
  link.sheriff.Start("talker");
  CHECK(link.Status("talker") == CommandStatus::kRespawnPending);
  REQUIRE(link.Until([&] { return link.Status("talker") == CommandStatus::kRunning; }));
  const pid_t first_pid = link.sheriff.state("talker").pid;
  CHECK(Alive(first_pid));
  REQUIRE(link.Report("talker"));
  CHECK(link.Report("talker")->pid == first_pid);
  CHECK(link.Report("talker")->actual_runid == 1);
  CHECK(link.Report("talker")->cmd.exec == "echo hello from talker; exec sleep 30");
  // The command's output reaches the printf channel under its sheriff id.
  REQUIRE(link.Until([&] { return link.Printed(id, "hello from talker\n"); }));

  link.sheriff.Restart("talker");
  CHECK(link.Status("talker") == CommandStatus::kStopping);
  REQUIRE(link.Until([&] {
    return link.Status("talker") == CommandStatus::kRunning &&
           link.sheriff.state("talker").pid != first_pid;
  }));
  CHECK(!Alive(first_pid));
  CHECK(link.Report("talker")->actual_runid == 2);
  CHECK(link.sheriff.state("talker").start_count == 2);
  const pid_t second_pid = link.sheriff.state("talker").pid;

  link.sheriff.Stop("talker");
  REQUIRE(link.Until([&] { return link.Status("talker") == CommandStatus::kStopped &&
                                  link.Report("talker")->pid == 0; }));
  CHECK(!Alive(second_pid));
  // Stopped by its stop signal: the reported status is waitpid()'s.
  CHECK(link.Report("talker")->exit_code == SIGTERM);
  REQUIRE(link.sheriff.state("talker").last_exit);
  CHECK(link.sheriff.state("talker").last_exit->signal == SIGTERM);
}

TEST_CASE("deputy reports memory and CPU of a running command") {
  Link link;
  link.sheriff.Start("talker");
  REQUIRE(link.Until([&] { return link.Status("talker") == CommandStatus::kRunning; }));
  // Running from the fork on; while the wrapper execs the program the
  // kernel reports no resident pages for a moment: wait for the program.
  DeputyInfo info;
  CHECK(link.Until([&] {
    info = link.deputy.Info(Now());
    return !info.cmds.empty() && info.cmds.at(0).mem_rss_bytes > 0;
  }));
  CHECK(info.host == "vehicle");
  CHECK(info.phys_mem_total_bytes > 0);
  CHECK(info.phys_mem_free_bytes <= info.phys_mem_total_bytes);
  CHECK(info.cpu_load >= 0.0f);
  CHECK(info.cpu_load <= 1.0f);
  const CommandReport& r = info.cmds.at(0);
  // `sleep` maps at least a page and its vsize covers its rss.
  CHECK(r.mem_rss_bytes > 0);
  CHECK(r.mem_vsize_bytes >= r.mem_rss_bytes);
  CHECK(r.cpu_usage >= 0.0f);
  CHECK(r.cpu_usage <= 1.0f);
  link.sheriff.Stop("talker");
  REQUIRE(link.Until([&] { return link.Status("talker") == CommandStatus::kStopped; }));
  CHECK(link.Report("talker")->mem_rss_bytes == 0);
}

TEST_CASE("a command that ignores its stop signal is killed after stop_time_allowed") {
  Link link;
  link.sheriff.Start("stubborn");
  REQUIRE(link.Until([&] { return link.Printed(link.SheriffIdOf("stubborn"), "ready\n"); }));
  const Clock::time_point stop_at = Clock::now();
  link.sheriff.Stop("stubborn");
  REQUIRE(link.Until([&] { return link.Status("stubborn") == CommandStatus::kStopped; }));
  const auto took = Clock::now() - stop_at;
  CHECK(took >= milliseconds(1000));
  CHECK(link.Report("stubborn")->exit_code == SIGKILL);
}

TEST_CASE("a command that exits on its own reports its exit code") {
  Link link;
  link.sheriff.Start("quitter");
  REQUIRE(link.Until([&] { return link.Status("quitter") == CommandStatus::kExited; }));
  CHECK(link.Report("quitter")->exit_code == (3 << 8));
  // Even when it started and ended between two reports.
  REQUIRE(link.sheriff.state("quitter").last_exit);
  CHECK(link.sheriff.state("quitter").last_exit->exit_code == 3);
  CHECK(link.sheriff.state("quitter").start_count == 1);
  CHECK(link.sheriff.state("quitter").exit_count == 1);
  // Same run id: the deputy does not start it again by itself.
  for (int i = 0; i < 5; ++i) link.Exchange();
  CHECK(link.Status("quitter") == CommandStatus::kExited);
  CHECK(link.Report("quitter")->actual_runid == 1);
}

TEST_CASE("deputy ignores other hosts' and stale orders, and drops commands left out") {
  Link link;
  link.sheriff.Start("talker");
  link.sheriff.Start("ground");
  std::vector<DeputyOrders> orders = link.sheriff.Orders(Now());
  REQUIRE(orders[0].host == "ground");
  CHECK_FALSE(link.deputy.OnOrders(orders[0], Now()));
  CHECK(link.deputy.Info(Now()).cmds.empty());

  DeputyOrders stale = orders[1];
  stale.utime = Now() - 120'000'000;
  CHECK_FALSE(link.deputy.OnOrders(stale, Now()));
  CHECK(link.deputy.Info(Now()).cmds.empty());

  REQUIRE(link.deputy.OnOrders(orders[1], Now()));
  CHECK(link.deputy.sheriff_name() == "test-sheriff");
  REQUIRE(link.Until([&] { return link.Status("talker") == CommandStatus::kRunning; }));
  const pid_t pid = link.sheriff.state("talker").pid;

  // Orders without the command: the deputy stops it and forgets it.
  DeputyOrders without = link.sheriff.Orders(Now())[1];
  without.cmds.clear();
  link.deputy.OnOrders(without, Now());
  const Clock::time_point end = Clock::now() + kConditionTimeout;
  while (!link.deputy.Info(Now()).cmds.empty() && Clock::now() < end) {
    link.deputy.Poll(milliseconds(20), Now());
  }
  CHECK(link.deputy.Info(Now()).cmds.empty());
  CHECK(!Alive(pid));
}

TEST_CASE("an auto_respawn command exits and the deputy starts it again") {
  SheriffConfig config = ParseSheriffConfig(R"(
    cmd "flaky" { exec = "echo up; sleep 0.1; exit 1"; host = "vehicle"; auto_respawn = "true"; }
  )", "respawn.pmd");
  RemoteCommands sheriff(config, {"test-sheriff", "vehicle"});
  DeputyOptions options = Link::Options();
  DeputyNode deputy(options, {});
  sheriff.Start("flaky");
  const Clock::time_point end = Clock::now() + kConditionTimeout;
  while (sheriff.state("flaky").start_count < 3 && Clock::now() < end) {
    for (const DeputyOrders& o : sheriff.Orders(Now())) deputy.OnOrders(o, Now());
    deputy.Poll(milliseconds(20), Now());
    sheriff.OnInfo(deputy.Info(Now()));
  }
  CHECK(sheriff.state("flaky").start_count >= 3);
  CHECK(sheriff.state("flaky").respawn_count >= 2);
  // Respawns keep the run id: the sheriff asked for one run only.
  CHECK(deputy.Info(Now()).cmds.at(0).actual_runid == 1);
}

TEST_CASE("a command that cannot be started reports status 127 and why") {
  SheriffConfig config = ParseSheriffConfig(R"(
    cmd "broken" { exec = "${VIMOT_DEPUTY_TEST_UNDEFINED_VARIABLE}/x"; host = "vehicle"; }
  )", "broken.pmd");
  RemoteCommands sheriff(config, {"test-sheriff", "vehicle"});
  std::vector<DeputyOutput> outputs;
  DeputyNode deputy(Link::Options(), [&](const DeputyOutput& o) { outputs.push_back(o); });
  sheriff.Start("broken");
  for (int i = 0; i < 3; ++i) {
    for (const DeputyOrders& o : sheriff.Orders(Now())) deputy.OnOrders(o, Now());
    deputy.Poll(milliseconds(20), Now());
    sheriff.OnInfo(deputy.Info(Now()));
  }
  CHECK(sheriff.state("broken").status == CommandStatus::kExited);
  REQUIRE(sheriff.state("broken").last_exit);
  CHECK(sheriff.state("broken").last_exit->exit_code == 127);
  bool named = false;
  for (const DeputyOutput& o : outputs) {
    named |= o.text.find("VIMOT_DEPUTY_TEST_UNDEFINED_VARIABLE") != std::string::npos;
  }
  CHECK(named);
}

