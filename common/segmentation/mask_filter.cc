#include "common/segmentation/mask_filter.h"

#include <optional>
#include <stdexcept>

#include "common/config/config.h"
#include "common/segmentation/blob.h"

namespace vimot::segmentation {

void MaskFilterOptions::validate() const {
  morphology.validate();
  if (min_blob_area_px < 1) throw std::invalid_argument("min_blob_area_px must be >= 1");
  kalman.validate();
}

MaskFilterOptions MaskFilterOptions::from_config(const Config& cfg, const std::string& section) {
  const std::string s = section.empty() ? "" : section + ".";
  cfg.check_keys(section, {"morphology", "min_blob_area_px", "kalman"});
  cfg.check_keys(s + "morphology", {"erode_kernel_px", "dilate_kernel_px"});
  cfg.check_keys(s + "kalman",
                 {"center_sigma_px", "size_sigma_px", "center_accel_noise", "size_accel_noise",
                  "init_center_velocity_sigma", "init_size_velocity_sigma", "gate_probability",
                  "max_consecutive_rejections", "max_coast_s"});
  MaskFilterOptions o;
  const auto read = [&](const std::string& key, auto* value) { *value = cfg.get_or(s + key, *value); };
  read("morphology.erode_kernel_px", &o.morphology.erode_kernel_px);
  read("morphology.dilate_kernel_px", &o.morphology.dilate_kernel_px);
  read("min_blob_area_px", &o.min_blob_area_px);
  BoxKalmanOptions& k = o.kalman;
  read("kalman.center_sigma_px", &k.center_sigma_px);
  read("kalman.size_sigma_px", &k.size_sigma_px);
  read("kalman.center_accel_noise", &k.center_accel_noise);
  read("kalman.size_accel_noise", &k.size_accel_noise);
  read("kalman.init_center_velocity_sigma", &k.init_center_velocity_sigma);
  read("kalman.init_size_velocity_sigma", &k.init_size_velocity_sigma);
  read("kalman.gate_probability", &k.gate_probability);
  read("kalman.max_consecutive_rejections", &k.max_consecutive_rejections);
  read("kalman.max_coast_s", &k.max_coast_s);
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError("config '" + cfg.source() + "': " + s + e.what());
  }
  return o;
}

MaskFilter::MaskFilter(const MaskFilterOptions& options) : options_(options), kalman_(options.kalman) {
  options_.validate();
}

BoxEstimate MaskFilter::process(int64_t utime, const cv::Mat& mask) {
  BoxEstimate e;
  e.utime = utime;
  std::optional<Blob> blob;
  if (!mask.empty()) {
    blob = largest_blob(open_mask(mask, options_.morphology), options_.min_blob_area_px);
  }
  if (blob) {
    e.raw_valid = true;
    e.raw_box = blob->box;
    e.num_blobs = blob->num_blobs;
  }
  e.outcome = kalman_.step(utime, blob ? &blob->box : nullptr);
  e.filtered_valid = kalman_.valid();
  if (e.filtered_valid) {
    e.filtered_box = kalman_.box();
    e.filtered_velocity = kalman_.center_velocity();
    e.filtered_covariance = kalman_.box_covariance();
    e.frames_since_raw = kalman_.frames_since_fused();
  }
  return e;
}

}  // namespace vimot::segmentation
