// The real EuRoC slice from pixels, in-process: the player's IMU and stereo
// images, the feature tracker configured as the feature_tracker process
// (config/feature_tracker.yaml), and the estimator as `vins` runs it on
// EuRoC (config/vins_euroc.yaml: static start, no ground truth used). The
// vehicle sits almost still for the 4.7 s (1.7 cm of true motion), so the
// estimate's motion since its start must follow the ground truth's to
// within the 2 cm. Exits with ctest's skip code 77 without
// VIMOT_DATA_DIR.
#include "tests/drivers/euroc_player/slice_test_main.h"

#include <algorithm>
#include <map>

#include "common/camera/camera_model.h"
#include "common/config/config.h"
#include "common/estimator/vio_estimator.h"
#include "common/estimator/vins_config.h"
#include "common/frontend/feature_tracker.h"
#include "common/frontend/tracker_options.h"
#include "common/math/quat.h"
#include "drivers/euroc_player/euroc_player.h"

TEST_CASE("vins from the slice's pixels and IMU follows the ground truth to within 2 cm", "[euroc][data]") {
  const std::string source(VIMOT_SOURCE_DIR);
  const vimot::estimator::VioOptions vio = vimot::estimator::load_vio_options(source + "/config/vins_euroc.yaml");
  REQUIRE(vio.init_mode == vimot::estimator::InitMode::kStatic);
  vimot::estimator::VioEstimator estimator(vio);
  const auto tracker_options = vimot::frontend::FeatureTrackerOptions::from_config(
      vimot::Config::load_file(source + "/config/feature_tracker.yaml"), "tracker");
  vimot::frontend::FeatureTracker tracker(tracker_options, vimot::load_euroc_cameras(slice_dir() + "/mav0"));

  vimot::euroc::PlayerOptions player_options;
  player_options.dataset = slice_dir();
  player_options.groundtruth_file = slice_dir() + "/groundtruth/V1_01_easy.csv";
  vimot::euroc::EurocPlayer player(player_options);

  std::map<int64_t, vimot::GroundTruth> truth;
  std::map<int64_t, vimot::estimator::ImuValue> estimates;  // after each processed frame
  int frames = 0, processed = 0;
  while (auto e = player.next()) {
    if (const auto* imu = std::get_if<vimot::ImuData>(&*e)) {
      estimator.feed_imu(*imu);
    } else if (const auto* g = std::get_if<vimot::GroundTruth>(&*e)) {
      truth[g->utime] = *g;
    } else {
      const auto& f = std::get<vimot::euroc::StereoFrame>(*e);
      const vimot::euroc::StereoImages images = player.load_images(f);
      const vimot::CameraFrame frame = tracker.track(f.utime, images.left, images.right, std::nullopt, std::nullopt);
      ++frames;
      if (estimator.feed_camera(frame) == vimot::estimator::FrameStatus::kProcessed) {
        ++processed;
        estimates[f.utime] = estimator.imu_value();
      }
    }
  }
  REQUIRE(estimator.initialized());
  // Every frame after the static start is processed.
  REQUIRE(processed >= frames - 12);
  REQUIRE(processed > 60);

  // The estimator's world G' has its own yaw; express the truth's motion in
  // it through the two orientations at the estimator's first frame.
  const int64_t t0 = estimates.begin()->first;
  REQUIRE(truth.count(t0) == 1);
  const Eigen::Matrix3d R_GtoI_true = vimot::quat_to_rot(truth.at(t0).q_GtoI);
  const Eigen::Matrix3d R_GptoI_est = vimot::quat_to_rot(estimates.begin()->second.q_GtoI);
  const Eigen::Matrix3d R_GtoGp = R_GptoI_est.transpose() * R_GtoI_true;
  double worst = 0.0;
  for (const auto& [utime, x] : estimates) {
    REQUIRE(truth.count(utime) == 1);
    const Eigen::Vector3d moved_est = x.p_IinG - estimates.begin()->second.p_IinG;
    const Eigen::Vector3d moved_true = R_GtoGp * (truth.at(utime).p_IinG - truth.at(t0).p_IinG);
    worst = std::max(worst, (moved_est - moved_true).norm());
  }
  INFO("processed " << processed << " of " << frames << " frames; worst position drift " << worst << " m");
  CHECK(worst < 0.02);
}
