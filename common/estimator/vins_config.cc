#include "common/estimator/vins_config.h"

#include <stdexcept>

#include "common/config/config.h"

namespace vimot {
namespace estimator {

namespace {

InitMode read_mode(const Config& cfg) {
  cfg.check_keys("init", {"mode", "perturb_seed"});
  const std::string mode = cfg.get_or<std::string>("init.mode", "ground_truth");
  if (mode == "ground_truth") return InitMode::kGroundTruth;
  if (mode == "static") return InitMode::kStatic;
  cfg.fail("init.mode", "must be 'ground_truth' or 'static', got '" + mode + "'");
}

}  // namespace

const std::vector<std::string>& vins_config_keys() {
  static const std::vector<std::string> keys = {"calibration_file", "channels", "init", "estimator", "output",
                                                "input"};
  return keys;
}

VioOptions vio_options_from_config(const Config& cfg) {
  if (cfg.has("estimator.init.mode")) {
    cfg.fail("estimator.init.mode", "is set by the top-level 'init.mode' of a vins config");
  }
  const bool has_calib = cfg.has("calibration_file");
  const Config calib = has_calib ? Config::load_file(cfg.resolve_path(cfg.get<std::string>("calibration_file")))
                                 : cfg;
  VioOptions o = VioOptions::from_config(cfg, calib, "estimator");
  o.init_mode = read_mode(cfg);
  return o;
}

VioOptions load_vio_options(const std::string& vins_yaml) {
  const Config cfg = Config::load_file(vins_yaml);
  cfg.check_keys("", vins_config_keys());
  return vio_options_from_config(cfg);
}

VinsStartOptions start_options_from_config(const Config& cfg) {
  VinsStartOptions s;
  s.mode = read_mode(cfg);
  const int64_t seed = cfg.get_or<int64_t>("init.perturb_seed", 0);
  if (seed < 0) cfg.fail("init.perturb_seed", "must be >= 0 (0 = no perturbation), got " + std::to_string(seed));
  s.perturb_seed = static_cast<uint64_t>(seed);
  return s;
}

VinsStartOptions load_start_options(const std::string& vins_yaml) {
  return start_options_from_config(Config::load_file(vins_yaml));
}

}  // namespace estimator
}  // namespace vimot
