#include "procs/log_replay/log_replay.h"

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "common/config/config.h"
#include "common/process/event_sink.h"
#include "common/process/lcm_conversions.h"
#include "common/process/lcm_type_registry.h"
#include "common/time/utime.h"
#include "procs/target_filter/target_filter_node.h"
#include "procs/vins/vins_node.h"

namespace vimot {
namespace {

using Bytes = std::vector<uint8_t>;

/// The replayed outputs by channel, encoded as the live process publishes
/// them, and optionally written to a log.
class Outputs {
 public:
  explicit Outputs(const std::string& out_log) {
    if (!out_log.empty()) sink_ = std::make_unique<LogFileSink>(out_log);
  }
  template <typename Msg>
  void add(const std::string& channel, const Msg& msg) {
    Bytes bytes(static_cast<std::size_t>(msg.getEncodedSize()));
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    if (sink_) sink_->write(channel, msg.utime, bytes.data(), static_cast<int>(bytes.size()));
    by_channel[channel].push_back(std::move(bytes));
  }
  /// A logged message copied into the output log (the ground truth).
  void copy(const std::string& channel, int64_t utime, const void* data, int size) {
    if (sink_) sink_->write(channel, utime, data, size);
  }
  std::map<std::string, std::vector<Bytes>> by_channel;

 private:
  std::unique_ptr<LogFileSink> sink_;
};

/// What a log event on an input channel does: false if it is malformed.
using InputHandler = std::function<bool(const void* data, int size)>;

/// Decodes and converts as the live process's subscription does, then feeds.
template <typename Msg, typename Feed>
InputHandler input(Feed feed) {
  return [feed](const void* data, int size) {
    Msg msg;
    if (!decode_untrusted(data, size, &msg)) return false;
    try {
      const auto plain = from_lcm(msg);
      feed(plain);
    } catch (const std::invalid_argument&) {
      return false;
    }
    return true;
  };
}

std::string channel_of(const Config& cfg, const std::string& role, const std::string& fallback) {
  return cfg.get_or<std::string>("channels." + role, fallback);
}

/// The Nodes of the replayed processes with their channels.
struct Replay {
  std::unique_ptr<VinsNode> vins;
  std::unique_ptr<TargetFilterNode> target;
  std::map<std::string, std::vector<InputHandler>> inputs;
  std::vector<std::string> output_channels;
  std::string imu_channel;
  std::string truth_channel;  // copied to the output log
};

}  // namespace

bool ReplayReport::identical() const {
  if (channels.empty()) return false;
  int64_t compared = 0;
  for (const ChannelComparison& c : channels) {
    if (!c.equal()) return false;
    compared += c.recorded;
  }
  return compared > 0;
}

ReplayReport replay_log(const std::string& log_path, const ReplaySetup& setup) {
  if (setup.vins_config.empty() && setup.target_filter_config.empty()) {
    throw std::invalid_argument("replay_log: no process to replay (give a vins or a target_filter config)");
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error("cannot open LCM log '" + log_path + "'");

  ReplayReport report;
  Outputs outputs(setup.out_log);
  const auto on_event = [&report](const NodeEvent& e) {
    if (e.kind == NodeEvent::Kind::kError) ++report.node_errors;
    if (e.kind == NodeEvent::Kind::kDropped || e.kind == NodeEvent::Kind::kLost) ++report.node_dropped;
  };
  Replay r;
  if (!setup.vins_config.empty()) {
    const Config cfg = Config::load_file(setup.vins_config);
    VinsNodeOptions options = vins_node_options_from_config(cfg);
    if (setup.perturb_seed >= 0) options.perturb_seed = static_cast<uint64_t>(setup.perturb_seed);
    const std::string state = channel_of(cfg, "state", "VINS_STATE");
    r.vins = std::make_unique<VinsNode>(
        options, [&outputs, state](const NavState& s) { outputs.add(state, to_lcm(s)); }, on_event);
    VinsNode& node = *r.vins;
    r.imu_channel = channel_of(cfg, "imu", "IMU");
    r.truth_channel = channel_of(cfg, "ground_truth", "GROUND_TRUTH");
    r.inputs[r.imu_channel].push_back(input<imu_t>([&node](const ImuData& m) { node.on_imu(m); }));
    r.inputs[channel_of(cfg, "features", "FEATURES")].push_back(
        input<features_t>([&node](const CameraFrame& m) { node.on_frame(m); }));
    // As the process: ground truth only when it starts from it.
    if (options.init_from_ground_truth) {
      r.inputs[channel_of(cfg, "ground_truth", "GROUND_TRUTH")].push_back(
          input<ground_truth_t>([&node](const GroundTruth& m) { node.on_ground_truth(m); }));
    }
    r.output_channels.push_back(state);
  }
  if (!setup.target_filter_config.empty()) {
    const Config cfg = Config::load_file(setup.target_filter_config);
    TargetFilterNodeOptions options = node_options_from_config(cfg);
    if (setup.perturb_seed >= 0) options.perturb_seed = static_cast<uint64_t>(setup.perturb_seed);
    const std::string nav = channel_of(cfg, "nav_state", "NAV_STATE");
    const std::string target = channel_of(cfg, "target_state", "TARGET_STATE");
    const std::string prediction = channel_of(cfg, "target_prediction", "TARGET_PREDICTION");
    TargetFilterNode::Callbacks callbacks;
    callbacks.on_nav_state = [&outputs, nav](const NavState& s) { outputs.add(nav, to_lcm(s)); };
    callbacks.on_target_state = [&outputs, target](const TargetStateEstimate& s) { outputs.add(target, to_lcm(s)); };
    callbacks.on_target_prediction = [&outputs, prediction](const TargetPosePrediction& p) {
      outputs.add(prediction, to_lcm(p));
    };
    callbacks.on_event = on_event;
    r.target = std::make_unique<TargetFilterNode>(options, callbacks);
    TargetFilterNode& node = *r.target;
    const std::string imu = channel_of(cfg, "imu", "IMU");
    if (r.imu_channel.empty()) r.imu_channel = imu;
    if (r.truth_channel.empty()) r.truth_channel = channel_of(cfg, "ground_truth", "GROUND_TRUTH");
    r.inputs[imu].push_back(input<imu_t>([&node](const ImuData& m) { node.on_imu(m); }));
    r.inputs[channel_of(cfg, "features", "FEATURES")].push_back(
        input<features_t>([&node](const CameraFrame& m) { node.on_frame(m); }));
    // The process always subscribes ground truth (robot start, target start).
    r.inputs[channel_of(cfg, "ground_truth", "GROUND_TRUTH")].push_back(
        input<ground_truth_t>([&node](const GroundTruth& m) { node.on_ground_truth(m); }));
    for (const std::string& c : {nav, target, prediction}) r.output_channels.push_back(c);
  }
  for (const std::string& c : r.output_channels) {
    if (r.inputs.count(c) != 0) throw std::invalid_argument("replay_log: channel " + c + " is both input and output");
  }

  std::map<std::string, std::vector<Bytes>> recorded;
  for (const std::string& c : r.output_channels) recorded[c];
  int64_t first_imu = -1;
  int64_t last_imu = -1;
  const double cpu_start_ms = thread_cpu_ms();
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++report.events;
    const int64_t utime = vimot_message_utime(ev->data, ev->datalen);
    if (ev->channel == r.truth_channel) outputs.copy(ev->channel, utime, ev->data, ev->datalen);
    const auto in = r.inputs.find(ev->channel);
    if (in != r.inputs.end() && utime < setup.from_utime) continue;
    if (in != r.inputs.end()) {
      ++report.inputs;
      for (const InputHandler& handle : in->second) {
        if (!handle(ev->data, ev->datalen)) {
          ++report.malformed;
          break;  // the same bytes are malformed for every Node
        }
      }
      if (ev->channel == r.imu_channel && utime >= 0) {
        if (first_imu < 0) first_imu = utime;
        last_imu = utime;
      }
      continue;
    }
    const auto out = recorded.find(ev->channel);
    if (out != recorded.end() && utime >= setup.from_utime) {
      const auto* data = static_cast<const uint8_t*>(ev->data);
      out->second.emplace_back(data, data + ev->datalen);
    }
  }
  // The live process flushes its queue at the end of input (the IMU wait runs out).
  if (r.vins) r.vins->flush();
  if (r.target) r.target->flush();
  report.cpu_s = 1e-3 * (thread_cpu_ms() - cpu_start_ms);
  report.data_span_s = first_imu < 0 ? 0.0 : utime_to_seconds(last_imu - first_imu);

  for (const std::string& name : r.output_channels) {
    const std::vector<Bytes>& live = recorded[name];
    const std::vector<Bytes>& replayed = outputs.by_channel[name];
    ChannelComparison c;
    c.channel = name;
    c.recorded = static_cast<int64_t>(live.size());
    c.replayed = static_cast<int64_t>(replayed.size());
    // In order; a replayed message the log lacks (lcm-logger lost it under
    // load) is passed over when the recorded one follows within a few. A
    // process respawned from its checkpoint publishes again what it had
    // published after it: a recorded message equal to one matched shortly
    // before is such a copy, and the order goes on from there.
    constexpr std::size_t kLookahead = 50;
    std::size_t j = 0;
    std::size_t matched = 0;  // replayed messages before this one were matched once
    for (std::size_t i = 0; i < live.size(); ++i) {
      std::size_t k = j;
      while (k < replayed.size() && k < j + kLookahead && replayed[k] != live[i]) ++k;
      if (k == replayed.size() || k == j + kLookahead) {
        k = j;
        while (k > 0 && k + kLookahead > j && replayed[k - 1] != live[i]) --k;
        if (k == 0 || k + kLookahead == j) {
          c.first_difference = static_cast<int64_t>(i);
          break;
        }
        --k;
      }
      if (k < matched) {
        ++c.republished;
      } else {
        c.not_logged += static_cast<int64_t>(k - std::max(j, matched));
        ++c.identical;
      }
      j = k + 1;
      matched = std::max(matched, j);
    }
    if (c.first_difference < 0) c.not_logged += static_cast<int64_t>(replayed.size() - matched);
    if (c.first_difference >= 0 && static_cast<std::size_t>(c.first_difference) < live.size()) {
      const Bytes& m = live[static_cast<std::size_t>(c.first_difference)];
      c.first_difference_utime = vimot_message_utime(m.data(), static_cast<int>(m.size()));
    }
    report.channels.push_back(c);
  }
  return report;
}

}  // namespace vimot
