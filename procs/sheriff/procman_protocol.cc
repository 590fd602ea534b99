#include "procs/sheriff/procman_protocol.h"

#include <cmath>

namespace vimot::sheriff {

ProcmanCommand ToProcmanCommand(const CommandSpec& spec) {
  ProcmanCommand cmd;
  cmd.exec = spec.exec;
  cmd.name = spec.name;
  cmd.group = spec.group;
  cmd.auto_respawn = spec.auto_respawn;
  cmd.stop_signal = spec.stop_signal;
  cmd.stop_time_allowed_s = static_cast<double>(spec.stop_time_allowed.count()) / 1000.0;
  return cmd;
}

CommandSpec ToCommandSpec(const ProcmanCommand& cmd) {
  CommandSpec spec;
  spec.name = cmd.name;
  spec.exec = cmd.exec;
  spec.host = "localhost";
  spec.group = cmd.group;
  spec.auto_respawn = cmd.auto_respawn;
  // A sheriff may send 0 or garbage; procman's defaults then apply.
  spec.stop_signal = cmd.stop_signal > 0 ? cmd.stop_signal : kDefaultStopSignal;
  spec.stop_time_allowed =
      std::isfinite(cmd.stop_time_allowed_s) && cmd.stop_time_allowed_s > 0.0
          ? std::chrono::milliseconds(
                static_cast<long long>(std::llround(cmd.stop_time_allowed_s * 1000.0)))
          : kDefaultStopTimeAllowed;
  return spec;
}

}  // namespace vimot::sheriff
