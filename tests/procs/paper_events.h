#pragma once
// The paper scenario's event stream for the process-logic tests.

#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/sim/simulator.h"

namespace vimot {

inline std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

/// All events of `duration` s of config/sim_paper.yaml with noise seed 5.
inline std::vector<sim::SimEvent> simulate(double duration) {
  sim::SimConfig cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  cfg.seed = 5;
  cfg.duration = duration;
  cfg.ground_truth_events = true;
  sim::Simulator s(cfg);
  std::vector<sim::SimEvent> events;
  s.run([&](const sim::SimEvent& e) { events.push_back(e); });
  return events;
}

}  // namespace vimot
