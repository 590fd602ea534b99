#include "common/target/target_filter_config.h"

#include <stdexcept>

namespace vimot {
namespace target {

namespace {

double positive(const Config& c, const std::string& key, double fallback) {
  const double v = c.get_or<double>(key, fallback);
  if (!(v > 0.0)) c.fail(key, "must be > 0, got " + std::to_string(v));
  return v;
}

double non_negative(const Config& c, const std::string& key, double fallback) {
  const double v = c.get_or<double>(key, fallback);
  if (!(v >= 0.0)) c.fail(key, "must be >= 0, got " + std::to_string(v));
  return v;
}

int at_least(const Config& c, const std::string& key, int fallback, int min) {
  const int v = c.get_or<int>(key, fallback);
  if (v < min) c.fail(key, "must be >= " + std::to_string(min) + ", got " + std::to_string(v));
  return v;
}

}  // namespace

TargetUpdateMode parse_target_mode(const std::string& s) {
  if (s == "skf") return TargetUpdateMode::kSkf;
  if (s == "ekf") return TargetUpdateMode::kEkf;
  if (s == "off") return TargetUpdateMode::kOff;
  if (s == "adaptive") return TargetUpdateMode::kAdaptive;
  throw std::invalid_argument("target mode must be skf, ekf, adaptive or off, got '" + s + "'");
}

TargetRepresentation parse_target_representation(const std::string& s) {
  if (s == "local") return TargetRepresentation::kLocal;
  if (s == "global") return TargetRepresentation::kGlobal;
  throw std::invalid_argument("target representation must be local or global, got '" + s + "'");
}

TargetInitMode parse_init_mode(const std::string& s) {
  if (s == "features") return TargetInitMode::kFeatures;
  if (s == "ground_truth") return TargetInitMode::kGroundTruth;
  throw std::invalid_argument("target init mode must be features or ground_truth, got '" + s + "'");
}

TargetSection target_section_from_config(const Config& config) {
  TargetSection t;
  if (!config.has("target")) return t;
  const Config c = config.sub("target");
  config.check_keys("target", {"mode", "representation", "sigma_t", "planar", "chi2_multiplier", "min_clone_times",
                               "observability_constraint", "init", "init_sigmas", "points", "adaptive",
                               "prediction_horizon_s"});
  TargetFilterOptions& o = t.filter;
  if (c.has("mode")) {
    const std::string mode = c.get<std::string>("mode");
    t.enabled = mode != "none";
    try {
      if (t.enabled) o.mode = parse_target_mode(mode);
    } catch (const std::invalid_argument& e) {
      c.fail("mode", std::string(e.what()) + " (or none)");
    }
  }
  if (c.has("representation")) {
    try {
      o.representation = parse_target_representation(c.get<std::string>("representation"));
    } catch (const std::invalid_argument& e) {
      c.fail("representation", e.what());
    }
  }
  // sigma_t 0 is a constant-velocity target (the filter accepts it).
  o.sigma_t = non_negative(c, "sigma_t", o.sigma_t);
  o.planar = c.get_or<bool>("planar", o.planar);
  o.chi2_multiplier = positive(c, "chi2_multiplier", o.chi2_multiplier);
  o.min_clone_times = at_least(c, "min_clone_times", o.min_clone_times, 2);
  o.observability_constraint = c.get_or<bool>("observability_constraint", o.observability_constraint);
  if (c.has("init")) {
    c.check_keys("init", {"mode", "frames", "min_points", "max_point_distance", "sigma_w"});
    const Config i = c.sub("init");
    if (i.has("mode")) {
      try {
        o.init_mode = parse_init_mode(i.get<std::string>("mode"));
      } catch (const std::invalid_argument& e) {
        i.fail("mode", e.what());
      }
    }
    TargetFeatureInit& f = o.feature_init;
    f.frames = at_least(i, "frames", f.frames, 2);
    f.min_points = at_least(i, "min_points", f.min_points, 1);
    f.max_point_distance = positive(i, "max_point_distance", f.max_point_distance);
    f.sigma_w = positive(i, "sigma_w", f.sigma_w);
  }
  if (c.has("init_sigmas")) {
    c.check_keys("init_sigmas", {"theta", "p", "v", "w"});
    const Config s = c.sub("init_sigmas");
    o.init_sigmas.theta = positive(s, "theta", o.init_sigmas.theta);
    o.init_sigmas.p = positive(s, "p", o.init_sigmas.p);
    o.init_sigmas.v = positive(s, "v", o.init_sigmas.v);
    o.init_sigmas.w = positive(s, "w", o.init_sigmas.w);
  }
  if (c.has("points")) {
    c.check_keys("points", {"max", "init_clone_times", "max_lost_frames", "relinearize"});
    const Config p = c.sub("points");
    o.max_target_points = at_least(p, "max", o.max_target_points, 0);
    o.point_init_clone_times = at_least(p, "init_clone_times", o.point_init_clone_times, 2);
    o.point_max_lost_frames = at_least(p, "max_lost_frames", o.point_max_lost_frames, 1);
    o.relinearize_points = p.get_or<bool>("relinearize", o.relinearize_points);
  }
  if (c.has("adaptive")) {
    c.check_keys("adaptive", {"window", "sigma_min", "sigma_max", "nis_max", "max_step", "hold_s", "horizon", "restart"});
    const Config a = c.sub("adaptive");
    AdaptiveNoiseOptions& ad = o.adaptive;
    ad.window = at_least(a, "window", ad.window, 2);
    ad.sigma_min = positive(a, "sigma_min", ad.sigma_min);
    ad.sigma_max = positive(a, "sigma_max", ad.sigma_max);
    ad.nis_max = positive(a, "nis_max", ad.nis_max);
    ad.max_step = positive(a, "max_step", ad.max_step);
    ad.hold_s = non_negative(a, "hold_s", ad.hold_s);
    ad.horizon = at_least(a, "horizon", ad.horizon, 1);
    ad.restart = a.get_or<bool>("restart", ad.restart);
    if (ad.horizon > ad.window) a.fail("horizon", "must be <= window (" + std::to_string(ad.window) + ")");
    if (!(ad.sigma_max >= ad.sigma_min)) a.fail("sigma_max", "must be >= sigma_min");
    if (!(ad.nis_max > 1.0)) a.fail("nis_max", "must be > 1, got " + std::to_string(ad.nis_max));
    if (!(ad.max_step > 1.0)) a.fail("max_step", "must be > 1, got " + std::to_string(ad.max_step));
  }
  t.prediction_horizon_s = non_negative(c, "prediction_horizon_s", t.prediction_horizon_s);
  return t;
}

}  // namespace target
}  // namespace vimot
