// vimot-sheriff: headless procman sheriff for this machine. See --help and
// docs/sheriff.md.

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "common/time/utime.h"
#include "procs/sheriff/host_info.h"
#include "procs/sheriff/procman_lcm.h"
#include "procs/sheriff/remote_sheriff.h"
#include "procs/sheriff/sheriff.h"
#include "procs/sheriff/sheriff_config_parser.h"

namespace {

using vimot::sheriff::ExecutableDirectory;
using vimot::sheriff::HostName;
using vimot::sheriff::Sheriff;
using vimot::sheriff::SheriffOptions;

// Exit status for a bad command line or config, distinct from the 1 of "a
// managed command failed".
constexpr int kUsageError = 2;

constexpr char kUsage[] = R"(usage: vimot-sheriff [options] CONFIG.pmd

Headless procman sheriff: starts the commands of a libbot2 procman config on
this machine, prints their output as "[name] line", respawns auto_respawn
commands, and on Ctrl-C / SIGTERM stops everything in reverse start order
(a second Ctrl-C kills what is left).

options:
  --script NAME     run script NAME instead of starting every command
  --group NAME      start only group NAME and its subgroups ("a/b" = nested)
  --exit-when CMD   when CMD ends (exits and is not respawned, or exits with
                    code 0), stop everything else and exit with CMD's status
  --duration SEC    stop everything after SEC seconds (decimals allowed)
  --list            print the config's groups, commands and scripts and exit
  --lcm             run nothing here: send procman orders (PMD_ORDERS2) to the
                    deputy of each command's host (vimot-deputy or libbot2's
                    bot-procman-deputy) and follow their PMD_INFO2 and
                    PMD_PRINTF; --exit-when is not available
  --lcm-url URL     LCM URL for --lcm (default: $LCM_DEFAULT_URL, else LCM's)
  --local-host NAME deputy of commands with host "localhost" (default: this
                    machine's hostname)
  -h, --help        print this help

config format (libbot2 procman, '#' starts a comment):
  group "0.sensors" {                   # groups nest: "0.sensors/imu"
    cmd "sim" {
      exec = "${VIMOT_BIN}/vimot-sim";  # /bin/sh -c; ${VAR} and $VAR come from
                                        # the environment, $$ is a literal $
      host = "localhost";               # other hosts: reported, not started
      auto_respawn = "true";            # restart on exit; back-off 1 s
                                        # doubling up to 30 s
      stop_signal = 15;                 # default 2 (SIGINT)
      stop_time_allowed = 5;            # s before SIGKILL, default 7
    }
  }
  cmd "logger" { exec = "lcm-logger -f out.lcm"; }
  script "start_all" {
    start group "0.sensors";            # start|stop|restart cmd|group|everything
    start cmd "logger" wait "running";  # optional: wait "running"|"stopped"
    wait ms 500;
    wait cmd "sim" status "stopped";    # wait cmd|group "x" status "..."
    run_script "other";
  }

environment: VIMOT_BIN is set for the commands to the directory of this
binary unless already set.

exit status: that of the --exit-when command (128+N if killed by signal N);
128+N when stopped by signal N; 0 after --duration; when everything ended on
its own, 0 if all exited with 0, else 1; 1 if a script failed; 2 for a bad
command line or config.
)";

// Written by the signal handler, read by the loop: lock-free atomics are
// async-signal-safe, and exchange() loses no signal between read and reset.
std::atomic<int> g_pending_signal{0};

void OnSignal(int signal) { g_pending_signal.store(signal); }

void InstallSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  // No SA_RESTART: the signal must interrupt the runner's poll() so the stop
  // begins at once.
  action.sa_flags = 0;
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &action, nullptr);
  // A closed stdout (`vimot-sheriff ... | head`) must not kill the sheriff
  // before it has stopped its children.
  signal(SIGPIPE, SIG_IGN);
}

struct CommandLine {
  SheriffOptions options;
  std::string config_path;
  bool list{false};
  bool lcm{false};
  std::string lcm_url;
  std::string local_host;
  bool help{false};
};

CommandLine ParseCommandLine(int argc, char** argv) {
  CommandLine cl;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string arg = args[i];
    std::optional<std::string> inline_value;
    if (arg.rfind("--", 0) == 0 && arg.find('=') != std::string::npos) {
      inline_value = arg.substr(arg.find('=') + 1);
      arg = arg.substr(0, arg.find('='));
    }
    const auto value = [&]() -> std::string {
      if (inline_value) return *inline_value;
      if (i + 1 >= args.size()) {
        throw std::invalid_argument(arg + " needs a value");
      }
      return args[++i];
    };
    if (arg == "-h" || arg == "--help") {
      cl.help = true;
    } else if (arg == "--list") {
      cl.list = true;
    } else if (arg == "--lcm") {
      cl.lcm = true;
    } else if (arg == "--lcm-url") {
      cl.lcm_url = value();
    } else if (arg == "--local-host") {
      cl.local_host = value();
    } else if (arg == "--script") {
      cl.options.script = value();
    } else if (arg == "--group") {
      cl.options.group = value();
    } else if (arg == "--exit-when") {
      cl.options.exit_when = value();
    } else if (arg == "--duration") {
      const std::string text = value();
      char* end = nullptr;
      errno = 0;
      const double seconds = std::strtod(text.c_str(), &end);
      if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(seconds) ||
          seconds <= 0.0) {
        throw std::invalid_argument(
            "--duration needs a positive number of seconds, got '" + text + "'");
      }
      cl.options.duration =
          std::chrono::milliseconds(static_cast<long long>(std::ceil(seconds * 1000.0)));
    } else if (arg.size() > 1 && arg[0] == '-') {
      throw std::invalid_argument("unknown option '" + arg + "'");
    } else if (cl.config_path.empty()) {
      cl.config_path = arg;
    } else {
      throw std::invalid_argument("more than one config file given ('" +
                                  cl.config_path + "' and '" + arg + "')");
    }
  }
  if (!cl.help && cl.config_path.empty()) {
    throw std::invalid_argument("no config file given");
  }
  if (!cl.lcm && (!cl.lcm_url.empty() || !cl.local_host.empty())) {
    throw std::invalid_argument("--lcm-url and --local-host only apply with --lcm");
  }
  return cl;
}

// A malformed message from the network is dropped, never thrown out of
// lcm.handle().
template <typename Msg>
std::optional<Msg> Decode(const lcm::ReceiveBuffer* rbuf) {
  Msg msg;
  if (!vimot::sheriff::DecodeProcman(rbuf->data, static_cast<int>(rbuf->data_size), &msg)) {
    return std::nullopt;
  }
  return msg;
}

// --lcm: the run is RemoteSheriff's; this loop moves its messages.
int RunOverLcm(vimot::sheriff::SheriffConfig config, CommandLine cl) {
  using vimot::sheriff::FromLcm;
  using vimot::sheriff::ToLcm;
  lcm::LCM lcm(cl.lcm_url);
  if (!lcm.good()) {
    std::cerr << "vimot-sheriff: cannot open LCM '" << cl.lcm_url << "'\n";
    return kUsageError;
  }
  vimot::sheriff::RemoteOptions remote;
  remote.local_host = cl.local_host.empty() ? HostName() : cl.local_host;
  remote.sheriff_name = "vimot-sheriff@" + HostName() + ":" + std::to_string(getpid());
  std::optional<vimot::sheriff::RemoteSheriff> sheriff;
  try {
    sheriff.emplace(std::move(config), std::move(cl.options), remote);
  } catch (const std::exception& e) {
    std::cerr << "vimot-sheriff: " << e.what() << "\n";
    return kUsageError;
  }
  lcm.subscribeFunction(
      vimot::sheriff::kInfoChannel,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, vimot::sheriff::RemoteSheriff* s) {
        if (auto msg = Decode<bot_procman::info2_t>(rbuf)) s->OnInfo(FromLcm(*msg));
      },
      &*sheriff);
  lcm.subscribeFunction(
      vimot::sheriff::kPrintfChannel,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, vimot::sheriff::RemoteSheriff* s) {
        const auto msg = Decode<bot_procman::printf_t>(rbuf);
        if (!msg) return;
        const vimot::sheriff::DeputyOutput out = FromLcm(*msg);
        const auto prefix = s->OutputPrefix(out);
        if (!prefix) return;  // another sheriff's command
        std::string text = out.text;
        if (!text.empty() && text.back() == '\n') text.pop_back();
        std::cout << *prefix << text << std::endl;
      },
      &*sheriff);

  bot_procman::discovery_t discovery;
  discovery.utime = vimot::wall_clock_utime();
  discovery.host = HostName();
  discovery.nonce = getpid();
  lcm.publish(vimot::sheriff::kDiscoverChannel, &discovery);

  InstallSignalHandlers();
  sheriff->Begin();
  while (true) {
    if (lcm.handleTimeout(50) < 0 && g_pending_signal.load() == 0) {
      std::cerr << "vimot-sheriff: LCM receive failed\n";
      return 1;
    }
    if (const auto code = sheriff->Step(g_pending_signal.exchange(0))) return *code;
    for (const auto& orders : sheriff->DueOrders(vimot::wall_clock_utime())) {
      const bot_procman::orders2_t msg = ToLcm(orders);
      lcm.publish(vimot::sheriff::kOrdersChannel, &msg);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CommandLine cl;
  try {
    cl = ParseCommandLine(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::cerr << "vimot-sheriff: " << e.what() << "\n"
              << "run 'vimot-sheriff --help' for usage\n";
    return kUsageError;
  }
  if (cl.help) {
    std::cout << kUsage;
    return 0;
  }

  vimot::sheriff::SheriffConfig config;
  try {
    config = vimot::sheriff::LoadSheriffConfig(cl.config_path);
  } catch (const std::exception& e) {
    std::cerr << "vimot-sheriff: " << e.what() << "\n";
    return kUsageError;
  }
  if (cl.list) {
    for (const auto& w : config.warnings()) std::cerr << w.ToString() << "\n";
    std::cout << vimot::sheriff::DescribeConfig(config);
    return 0;
  }

  if (cl.lcm) return RunOverLcm(std::move(config), std::move(cl));
  if (std::getenv("VIMOT_BIN") == nullptr) {
    if (const auto dir = ExecutableDirectory()) {
      cl.options.runner.environment["VIMOT_BIN"] = *dir;
    }
  }
  std::optional<Sheriff> sheriff;
  try {
    sheriff.emplace(std::move(config), std::move(cl.options));
  } catch (const std::exception& e) {
    // The options do not fit the config, or an exec uses an undefined
    // variable: nothing has been started.
    std::cerr << "vimot-sheriff: " << e.what() << "\n";
    return kUsageError;
  }
  InstallSignalHandlers();
  try {
    return sheriff->Run([]() { return g_pending_signal.exchange(0); });
  } catch (const std::exception& e) {
    // ~Sheriff kills whatever is still running.
    std::cerr << "vimot-sheriff: internal error: " << e.what() << "\n";
    return 1;
  }
}
