// Simulated camera measurements checked against truth computed here: the
// true poses and points projected through the calibration's extrinsics,
// visibility (depth, range, image, back faces, occlusion by the target box)
// decided by brute force with an independent segment-face test, and the
// noise and track-loss statistics.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <set>

#include "common/sim/simulator.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

std::vector<CameraFrame> frames_of(Simulator& sim) {
  std::vector<CameraFrame> frames;
  sim.run([&frames](const SimEvent& e) {
    if (const auto* f = std::get_if<CameraFrame>(&e)) frames.push_back(*f);
  });
  return frames;
}

SimConfig clean_paper_config(double duration) {
  SimConfig c = test::paper_config();
  c.camera.pixel_noise = 0.0;
  c.camera.track_loss_probability = 0.0;
  c.imu.noise = false;
  c.duration = duration;
  return c;
}

// Point in G of a landmark at sim time t.
Eigen::Vector3d point_in_G(const Simulator& sim, const Landmark& lm, double t) {
  if (!lm.is_target) return lm.p;
  const SplineState T = *sim.target_state(t);
  return T.R_BtoG * lm.p + T.p_BinG;
}

struct CameraInG {
  Eigen::Matrix3d R_GtoC;
  Eigen::Vector3d p_CinG;
};

// Camera pose from the true IMU pose and the calibration: p_C = R_ItoC p_I + p_IinC.
CameraInG camera_in_G(const Simulator& sim, int cam, double t) {
  const SplineState I = sim.robot_state(t);
  const CameraCalibration& calib = sim.cameras()[static_cast<std::size_t>(cam)];
  CameraInG c;
  c.R_GtoC = calib.R_ItoC * I.R_BtoG.transpose();
  // The camera centre is where p_C = 0.
  c.p_CinG = I.p_BinG + I.R_BtoG * (calib.R_ItoC.transpose() * -calib.p_IinC);
  return c;
}

// Segment a→b (in T) crosses the box: intersect each face plane and check
// the hit lies inside the face rectangle (independent of the slab test).
bool segment_crosses_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& half) {
  const Eigen::Vector3d d = b - a;
  for (int k = 0; k < 3; ++k) {
    for (const double sgn : {-1.0, 1.0}) {
      if (std::abs(d(k)) < 1e-15) continue;
      const double lambda = (sgn * half(k) - a(k)) / d(k);
      if (lambda <= 1e-9 || lambda >= 1.0 - 1e-9) continue;
      const Eigen::Vector3d p = a + lambda * d;
      bool inside = true;
      for (int j = 0; j < 3; ++j) {
        if (j != k && std::abs(p(j)) > half(j)) inside = false;
      }
      if (inside) return true;
    }
  }
  return false;
}

}  // namespace

TEST_CASE("Noise-free pixels re-project from the true poses and points in both cameras") {
  Simulator sim(clean_paper_config(3.0));
  const std::vector<CameraFrame> frames = frames_of(sim);
  REQUIRE(frames.size() == 31);
  std::size_t n_obs[2] = {0, 0}, n_target = 0;
  double max_px_err = 0.0, max_norm_err = 0.0;
  for (const CameraFrame& f : frames) {
    const double t = sim.sim_time(f.utime);
    for (const FeatureObservation& o : f.observations) {
      // The 3D point behind the track id; a wrong mapping would fail the
      // re-projection below, so this also checks landmark_of_feature().
      const int64_t lm_id = sim.landmark_of_feature(o.feature_id);
      REQUIRE(lm_id >= 0);
      const Landmark& lm = sim.landmarks().at(static_cast<std::size_t>(lm_id));
      CHECK(o.is_target == lm.is_target);
      const CameraInG cam = camera_in_G(sim, o.camera_id, t);
      const Eigen::Vector3d p_C = cam.R_GtoC * (point_in_G(sim, lm, t) - cam.p_CinG);
      const Eigen::Vector2d n_true = p_C.head<2>() / p_C.z();
      const Eigen::Vector2d px_true = sim.camera_models()[static_cast<std::size_t>(o.camera_id)].distort(n_true);
      max_px_err = std::max(max_px_err, (o.pixel - px_true).norm());
      max_norm_err = std::max(max_norm_err, (o.normalized - n_true).norm());
      ++n_obs[o.camera_id];
      n_target += o.is_target;
    }
  }
  INFO("max pixel error " << max_px_err << ", max normalized error " << max_norm_err);
  CHECK(max_px_err < 1e-6);
  CHECK(max_norm_err < 1e-9);
  CHECK(n_obs[0] > 1000);
  CHECK(n_obs[1] > 1000);
  CHECK(n_target > 500);
}

TEST_CASE("Exactly the geometrically visible points are reported: occluded and back-face points are not") {
  SimConfig config = clean_paper_config(6.0);
  config.map.floor_points = 30000;  // ~3.5 /m²: dense enough that the box hides some floor
  Simulator sim(config);
  const std::vector<CameraFrame> frames = frames_of(sim);
  const SimConfig& c = sim.config();
  const Eigen::Vector3d half = 0.5 * c.target.size;
  std::size_t occluded_in_view = 0, back_faces_in_view = 0, compared = 0;
  for (std::size_t fi = 0; fi < frames.size(); fi += 10) {
    const CameraFrame& f = frames[fi];
    const double t = sim.sim_time(f.utime);
    const SplineState T = *sim.target_state(t);
    for (int cam = 0; cam < 2; ++cam) {
      const CameraInG C = camera_in_G(sim, cam, t);
      const CameraModel& model = sim.camera_models()[static_cast<std::size_t>(cam)];
      std::set<int64_t> expected, reported;
      for (const FeatureObservation& o : f.observations) {
        if (o.camera_id == cam) reported.insert(sim.landmark_of_feature(o.feature_id));
      }
      for (const Landmark& lm : sim.landmarks()) {
        const Eigen::Vector3d p_G = point_in_G(sim, lm, t);
        const Eigen::Vector3d p_C = C.R_GtoC * (p_G - C.p_CinG);
        if (p_C.z() <= c.camera.min_depth || p_C.norm() > c.camera.max_range) continue;
        if (!model.in_image(model.distort(p_C.head<2>() / p_C.z()))) continue;
        if (lm.is_target) {
          const Eigen::Vector3d to_cam = C.p_CinG - p_G;
          if ((T.R_BtoG * lm.normal_T).dot(to_cam) <= c.target.min_view_cos * to_cam.norm()) {
            ++back_faces_in_view;
            CHECK(reported.count(lm.id) == 0);
            continue;
          }
        } else {
          const Eigen::Matrix3d R_GtoT = T.R_BtoG.transpose();
          if (segment_crosses_box(R_GtoT * (C.p_CinG - T.p_BinG), R_GtoT * (p_G - T.p_BinG), half)) {
            ++occluded_in_view;
            CHECK(reported.count(lm.id) == 0);
            continue;
          }
        }
        expected.insert(lm.id);
      }
      CHECK(expected == reported);
      ++compared;
    }
  }
  INFO("occluded static points in view: " << occluded_in_view << ", back-face target points in view: "
                                          << back_faces_in_view);
  CHECK(compared == 14);
  // Both mechanisms were exercised.
  CHECK(occluded_in_view > 50);
  CHECK(back_faces_in_view > 100);
}

TEST_CASE("segment_hits_box handles through, short, grazing-free and surface cases") {
  const Eigen::Vector3d half(0.5, 0.5, 0.5);
  CHECK(FeatureSimulator::segment_hits_box({-2, 0, 0}, {2, 0, 0}, half));           // straight through
  CHECK_FALSE(FeatureSimulator::segment_hits_box({-2, 0, 0}, {-1, 0, 0}, half));    // stops before
  CHECK_FALSE(FeatureSimulator::segment_hits_box({-2, 0.6, 0}, {2, 0.6, 0}, half)); // passes beside
  CHECK(FeatureSimulator::segment_hits_box({0, 0, 3}, {0.1, 0.1, -0.5}, half));     // ends on the far face
  CHECK_FALSE(FeatureSimulator::segment_hits_box({0, 0, 3}, {0.1, 0.1, 0.5}, half)); // ends on the near face
  CHECK(FeatureSimulator::segment_hits_box({-3, -3, 0.2}, {3, 3, 0.2}, half));      // diagonal
}

TEST_CASE("Pixel noise has the configured σ and normalized coordinates undistort the noisy pixel") {
  SimConfig clean = clean_paper_config(5.0);
  SimConfig noisy = clean;
  noisy.camera.pixel_noise = 1.0;
  Simulator a(clean), b(noisy);
  const std::vector<CameraFrame> fa = frames_of(a), fb = frames_of(b);
  REQUIRE(fa.size() == fb.size());
  double sum2 = 0.0;
  std::size_t n = 0;
  double max_roundtrip = 0.0;
  for (std::size_t k = 0; k < fa.size(); ++k) {
    // Noise does not change which points are seen, nor their ids.
    REQUIRE(fa[k].observations.size() == fb[k].observations.size());
    for (std::size_t j = 0; j < fa[k].observations.size(); ++j) {
      const FeatureObservation& o0 = fa[k].observations[j];
      const FeatureObservation& o1 = fb[k].observations[j];
      REQUIRE(a.landmark_of_feature(o0.feature_id) == b.landmark_of_feature(o1.feature_id));
      REQUIRE(o0.feature_id == o1.feature_id);
      sum2 += (o1.pixel - o0.pixel).squaredNorm();
      n += 2;
      const Eigen::Vector2d back = b.camera_models()[static_cast<std::size_t>(o1.camera_id)].distort(o1.normalized);
      max_roundtrip = std::max(max_roundtrip, (back - o1.pixel).norm());
    }
  }
  CHECK(n > 10000);
  CHECK(std::sqrt(sum2 / static_cast<double>(n)) == Approx(1.0).epsilon(0.03));
  CHECK(max_roundtrip < 1e-6);
}

TEST_CASE("Track ids: persistent while tracked, fresh after a loss, shared by the stereo pair") {
  SimConfig lossless = clean_paper_config(10.0);
  SimConfig lossy = lossless;
  lossy.camera.track_loss_probability = 0.2;
  Simulator s0(lossless), s1(lossy);
  const std::vector<CameraFrame> f0 = frames_of(s0), f1 = frames_of(s1);
  REQUIRE(f0.size() == f1.size());

  // landmark -> feature id per frame (lossy run).
  std::vector<std::map<int64_t, int64_t>> ids(f1.size());
  for (std::size_t k = 0; k < f1.size(); ++k) {
    std::set<std::pair<int, int64_t>> seen;
    for (const FeatureObservation& o : f1[k].observations) {
      CHECK(seen.insert({o.camera_id, o.feature_id}).second);  // one observation per camera and id
      const int64_t lm = s1.landmark_of_feature(o.feature_id);
      const auto it = ids[k].find(lm);
      if (it != ids[k].end()) CHECK(it->second == o.feature_id);  // stereo: same id in both cameras
      ids[k][lm] = o.feature_id;
    }
  }
  std::size_t continued = 0, broken = 0, fresh_after_gap = 0, dropped = 0, candidates = 0;
  for (std::size_t k = 0; k + 2 < f1.size(); ++k) {
    for (const auto& [lm, id] : ids[k]) {
      const auto next = ids[k + 1].find(lm);
      if (next != ids[k + 1].end()) {
        (next->second == id ? continued : broken)++;
      } else {
        const auto after = ids[k + 2].find(lm);
        if (after != ids[k + 2].end()) fresh_after_gap += (after->second != id);
      }
    }
  }
  CHECK(continued > 1000);
  CHECK(broken == 0);          // seen in consecutive frames: same id
  CHECK(fresh_after_gap > 50); // a gap always gives a new id ...
  for (std::size_t k = 0; k + 2 < f1.size(); ++k) {
    for (const auto& [lm, id] : ids[k]) {
      const auto after = ids[k + 2].find(lm);
      if (ids[k + 1].count(lm) == 0 && after != ids[k + 2].end()) CHECK(after->second != id);  // ... checked here
    }
  }
  // Drop rate: points reported at k (lossy) and visible at k+1 (lossless run,
  // same geometry) go missing at k+1 with probability 0.2.
  for (std::size_t k = 0; k + 1 < f1.size(); ++k) {
    std::set<int64_t> visible_next;
    for (const FeatureObservation& o : f0[k + 1].observations) visible_next.insert(s0.landmark_of_feature(o.feature_id));
    for (const auto& [lm, id] : ids[k]) {
      if (visible_next.count(lm) == 0) continue;
      ++candidates;
      dropped += ids[k + 1].count(lm) == 0;
    }
  }
  const double rate = static_cast<double>(dropped) / static_cast<double>(candidates);
  INFO("drop rate " << rate << " over " << candidates);
  CHECK(rate == Approx(0.2).margin(0.02));
}
