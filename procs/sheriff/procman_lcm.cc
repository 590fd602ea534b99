#include "procs/sheriff/procman_lcm.h"

#include <cstdint>

namespace vimot::sheriff {

namespace {

bot_procman::command2_t ToLcm(const ProcmanCommand& cmd) {
  bot_procman::command2_t msg;
  msg.exec_str = cmd.exec;
  msg.command_name = cmd.name;
  msg.group = cmd.group;
  msg.auto_respawn = cmd.auto_respawn;
  msg.stop_signal = static_cast<int8_t>(cmd.stop_signal);
  msg.stop_time_allowed = static_cast<float>(cmd.stop_time_allowed_s);
  msg.num_options = 0;
  return msg;
}

ProcmanCommand FromLcm(const bot_procman::command2_t& msg) {
  ProcmanCommand cmd;
  cmd.exec = msg.exec_str;
  cmd.name = msg.command_name;
  cmd.group = msg.group;
  cmd.auto_respawn = msg.auto_respawn;
  cmd.stop_signal = msg.stop_signal;
  cmd.stop_time_allowed_s = msg.stop_time_allowed;
  return cmd;
}

}  // namespace

const ProcmanLayouts& procman_layouts() {
  static const LcmStruct command2{"command2_t", {
      {"exec_str", LcmKind::kString},
      {"command_name", LcmKind::kString},
      {"group", LcmKind::kString},
      {"auto_respawn", LcmKind::kBoolean},
      {"stop_signal", LcmKind::kInt8},
      {"stop_time_allowed", LcmKind::kFloat},
      {"num_options", LcmKind::kInt32},
      {"option_names", LcmKind::kString, "num_options"},
      {"option_values", LcmKind::kString, "num_options"}}};
  static const LcmStruct sheriff_cmd2{"sheriff_cmd2_t", {
      {"cmd", command2},
      {"desired_runid", LcmKind::kInt32},
      {"force_quit", LcmKind::kInt8},
      {"sheriff_id", LcmKind::kInt32}}};
  static const LcmStruct deputy_cmd2{"deputy_cmd2_t", {
      {"cmd", command2},
      {"pid", LcmKind::kInt32},
      {"actual_runid", LcmKind::kInt32},
      {"exit_code", LcmKind::kInt32},
      {"cpu_usage", LcmKind::kFloat},
      {"mem_vsize_bytes", LcmKind::kInt64},
      {"mem_rss_bytes", LcmKind::kInt64},
      {"sheriff_id", LcmKind::kInt32}}};
  static const LcmStruct orders2{"orders2_t", {
      {"utime", LcmKind::kInt64},
      {"host", LcmKind::kString},
      {"sheriff_name", LcmKind::kString},
      {"ncmds", LcmKind::kInt32},
      {"cmds", sheriff_cmd2, "ncmds"},
      {"num_options", LcmKind::kInt32},
      {"option_names", LcmKind::kString, "num_options"},
      {"option_values", LcmKind::kString, "num_options"}}};
  static const LcmStruct info2{"info2_t", {
      {"utime", LcmKind::kInt64},
      {"host", LcmKind::kString},
      {"cpu_load", LcmKind::kFloat},
      {"phys_mem_total_bytes", LcmKind::kInt64},
      {"phys_mem_free_bytes", LcmKind::kInt64},
      {"swap_total_bytes", LcmKind::kInt64},
      {"swap_free_bytes", LcmKind::kInt64},
      {"ncmds", LcmKind::kInt32},
      {"cmds", deputy_cmd2, "ncmds"},
      {"num_options", LcmKind::kInt32},
      {"option_names", LcmKind::kString, "num_options"},
      {"option_values", LcmKind::kString, "num_options"}}};
  static const LcmStruct printf_msg{"printf_t", {
      {"utime", LcmKind::kInt64},
      {"deputy_name", LcmKind::kString},
      {"sheriff_id", LcmKind::kInt32},
      {"text", LcmKind::kString}}};
  static const LcmStruct discovery{"discovery_t", {
      {"utime", LcmKind::kInt64},
      {"host", LcmKind::kString},
      {"nonce", LcmKind::kInt64}}};
  static const ProcmanLayouts layouts{command2, sheriff_cmd2, deputy_cmd2, orders2,
                                      info2,    printf_msg,   discovery};
  return layouts;
}

bot_procman::orders2_t ToLcm(const DeputyOrders& orders) {
  bot_procman::orders2_t msg;
  msg.utime = orders.utime;
  msg.host = orders.host;
  msg.sheriff_name = orders.sheriff_name;
  for (const CommandOrder& order : orders.cmds) {
    bot_procman::sheriff_cmd2_t c;
    c.cmd = ToLcm(order.cmd);
    c.desired_runid = order.desired_runid;
    c.force_quit = order.force_quit ? 1 : 0;
    c.sheriff_id = order.sheriff_id;
    msg.cmds.push_back(c);
  }
  msg.ncmds = static_cast<int32_t>(msg.cmds.size());
  msg.num_options = 0;
  return msg;
}

bot_procman::info2_t ToLcm(const DeputyInfo& info) {
  bot_procman::info2_t msg;
  msg.utime = info.utime;
  msg.host = info.host;
  msg.cpu_load = info.cpu_load;
  msg.phys_mem_total_bytes = info.phys_mem_total_bytes;
  msg.phys_mem_free_bytes = info.phys_mem_free_bytes;
  msg.swap_total_bytes = info.swap_total_bytes;
  msg.swap_free_bytes = info.swap_free_bytes;
  for (const CommandReport& report : info.cmds) {
    bot_procman::deputy_cmd2_t c;
    c.cmd = ToLcm(report.cmd);
    c.pid = report.pid;
    c.actual_runid = report.actual_runid;
    c.exit_code = report.exit_code;
    c.cpu_usage = report.cpu_usage;
    c.mem_vsize_bytes = report.mem_vsize_bytes;
    c.mem_rss_bytes = report.mem_rss_bytes;
    c.sheriff_id = report.sheriff_id;
    msg.cmds.push_back(c);
  }
  msg.ncmds = static_cast<int32_t>(msg.cmds.size());
  msg.num_options = 0;
  return msg;
}

bot_procman::printf_t ToLcm(const DeputyOutput& output) {
  bot_procman::printf_t msg;
  msg.utime = output.utime;
  msg.deputy_name = output.deputy_name;
  msg.sheriff_id = output.sheriff_id;
  msg.text = output.text;
  return msg;
}

DeputyOrders FromLcm(const bot_procman::orders2_t& msg) {
  DeputyOrders orders;
  orders.utime = msg.utime;
  orders.host = msg.host;
  orders.sheriff_name = msg.sheriff_name;
  for (const bot_procman::sheriff_cmd2_t& c : msg.cmds) {
    orders.cmds.push_back({FromLcm(c.cmd), c.desired_runid, c.force_quit != 0, c.sheriff_id});
  }
  return orders;
}

DeputyInfo FromLcm(const bot_procman::info2_t& msg) {
  DeputyInfo info;
  info.utime = msg.utime;
  info.host = msg.host;
  info.cpu_load = msg.cpu_load;
  info.phys_mem_total_bytes = msg.phys_mem_total_bytes;
  info.phys_mem_free_bytes = msg.phys_mem_free_bytes;
  info.swap_total_bytes = msg.swap_total_bytes;
  info.swap_free_bytes = msg.swap_free_bytes;
  for (const bot_procman::deputy_cmd2_t& c : msg.cmds) {
    CommandReport report;
    report.cmd = FromLcm(c.cmd);
    report.pid = c.pid;
    report.actual_runid = c.actual_runid;
    report.exit_code = c.exit_code;
    report.cpu_usage = c.cpu_usage;
    report.mem_vsize_bytes = c.mem_vsize_bytes;
    report.mem_rss_bytes = c.mem_rss_bytes;
    report.sheriff_id = c.sheriff_id;
    info.cmds.push_back(std::move(report));
  }
  return info;
}

DeputyOutput FromLcm(const bot_procman::printf_t& msg) {
  return {msg.utime, msg.deputy_name, msg.sheriff_id, msg.text};
}

}  // namespace vimot::sheriff
