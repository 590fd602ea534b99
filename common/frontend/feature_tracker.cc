#include "common/frontend/feature_tracker.h"

#include <algorithm>
#include <Eigen/SVD>
#include <chrono>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "common/frontend/grid_detector.h"

namespace vimot::frontend {

namespace {

std::string size_text(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

void check_image(const cv::Mat& image, const CameraModel& cam, const std::string& name) {
  if (image.empty()) throw std::invalid_argument("FeatureTracker: " + name + " image is empty");
  if (image.type() != CV_8UC1) {
    throw std::invalid_argument("FeatureTracker: " + name + " image must be 8-bit grey (CV_8UC1), got OpenCV type " +
                                std::to_string(image.type()));
  }
  const CameraCalibration& c = cam.calibration();
  if (image.cols != c.width || image.rows != c.height) {
    throw std::invalid_argument("FeatureTracker: " + name + " image is " + size_text(image) + ", its calibration is " +
                                std::to_string(c.width) + "x" + std::to_string(c.height));
  }
}

void check_box(const std::optional<Box>& box, const std::string& name) {
  if (!box) return;
  const bool finite =
      std::isfinite(box->x_min) && std::isfinite(box->y_min) && std::isfinite(box->width) && std::isfinite(box->height);
  if (!finite || box->width < 0.0 || box->height < 0.0) {
    throw std::invalid_argument("FeatureTracker: " + name + " box [" + std::to_string(box->x_min) + ", " +
                                std::to_string(box->y_min) + ", " + std::to_string(box->width) + ", " +
                                std::to_string(box->height) + "] must be finite with width, height >= 0");
  }
}

void check_mask(const cv::Mat& mask, const cv::Mat& image, const std::string& name) {
  if (mask.empty()) return;
  if (mask.type() != CV_8UC1 || mask.size() != image.size()) {
    throw std::invalid_argument("FeatureTracker: " + name + " mask must be 8-bit (CV_8UC1) of the image's size " +
                                size_text(image) + ", got " + size_text(mask) + " type " +
                                std::to_string(mask.type()));
  }
}

}  // namespace

FeatureTracker::FeatureTracker(const FeatureTrackerOptions& options, const std::vector<CameraCalibration>& cameras)
    : options_(options), ransac_(options.ransac), orb_(options.target), store_(options.target) {
  options_.validate();
  if (cameras.empty() || cameras.size() > 2) {
    throw std::invalid_argument("FeatureTracker: needs 1 (mono) or 2 (stereo) cameras, got " +
                                std::to_string(cameras.size()));
  }
  for (const CameraCalibration& c : cameras) cameras_.emplace_back(c);
  const std::size_t n = cameras_.size();
  prev_pyramid_.resize(n);
  pyramid_.resize(n);
  static_.resize(n);
  target_.resize(n);
  prev_box_.resize(n);
  eroded_mask_.resize(n);
}

void FeatureTracker::check_input(int64_t utime, const cv::Mat& left, const cv::Mat& right,
                                 const std::optional<Box>& box_left, const std::optional<Box>& box_right,
                                 const cv::Mat& mask_left, const cv::Mat& mask_right) const {
  if (frame_index_ > 0 && utime <= last_utime_) {
    throw std::invalid_argument("FeatureTracker: utime " + std::to_string(utime) + " is not after the previous " +
                                std::to_string(last_utime_));
  }
  check_image(left, cameras_[0], "left");
  if (num_cameras() == 2) {
    check_image(right, cameras_[1], "right");
  } else if (!right.empty()) {
    throw std::invalid_argument("FeatureTracker: a right image was given to a mono tracker");
  } else if (box_right) {
    throw std::invalid_argument("FeatureTracker: a right box was given to a mono tracker");
  } else if (!mask_right.empty()) {
    throw std::invalid_argument("FeatureTracker: a right mask was given to a mono tracker");
  }
  check_box(box_left, "left");
  check_box(box_right, "right");
  check_mask(mask_left, left, "left");
  check_mask(mask_right, right, "right");
}

double FeatureTracker::focal(int cam_a, int cam_b) const {
  return 0.5 * (cameras_[static_cast<std::size_t>(cam_a)].mean_focal() +
                cameras_[static_cast<std::size_t>(cam_b)].mean_focal());
}

bool FeatureTracker::normalize(int cam, Point* p) const {
  try {
    p->normalized = cameras_[static_cast<std::size_t>(cam)].undistort(Eigen::Vector2d(p->pixel.x, p->pixel.y));
    return true;
  } catch (const std::runtime_error&) {
    return false;  // beyond where the lens model is invertible: no ray to give
  }
}

bool FeatureTracker::usable(int cam, const cv::Point2f& px, const std::optional<Box>& box) const {
  const double border = options_.static_tracks.border_px;
  if (!cameras_[static_cast<std::size_t>(cam)].in_image(Eigen::Vector2d(px.x, px.y), border)) return false;
  return !(box && box->contains(px.x, px.y, options_.static_tracks.box_margin_px()));
}

std::vector<FeatureTracker::Point> FeatureTracker::klt(const std::vector<cv::Mat>& from_pyr, int to_cam,
                                                       const std::vector<cv::Mat>& to_pyr,
                                                       const std::vector<Point>& points, cv::Point2f shift,
                                                       const PixelTest& keep) const {
  std::vector<Point> out;
  if (points.empty()) return out;
  const StaticTrackOptions& o = options_.static_tracks;
  std::vector<cv::Point2f> from, to;
  from.reserve(points.size());
  for (const Point& p : points) {
    from.push_back(p.pixel);
    to.push_back(p.pixel + shift);
  }
  std::vector<uint8_t> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(
      from_pyr, to_pyr, from, to, status, error, cv::Size(o.klt_window_px, o.klt_window_px), o.klt_pyramid_levels,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, o.klt_max_iterations, o.klt_epsilon),
      cv::OPTFLOW_USE_INITIAL_FLOW);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!status[i] || !keep(to[i])) continue;
    Point p = points[i];
    p.pixel = to[i];
    if (normalize(to_cam, &p)) out.push_back(p);
  }
  return out;
}

bool FeatureTracker::anchor(int cam, Point* p) const {
  std::optional<AnchorPatch> patch = AnchorPatch::take(pyramid_[static_cast<std::size_t>(cam)][0], p->pixel,
                                                       options_.static_tracks.klt_window_px);
  if (!patch) return false;
  p->anchor = std::make_shared<const AnchorPatch>(std::move(*patch));
  p->affine = Eigen::Matrix2f::Identity();
  return true;
}

std::optional<FeatureTracker::Point> FeatureTracker::aligned(int cam, const Point& p) const {
  const StaticTrackOptions& o = options_.static_tracks;
  const std::optional<AnchorPatch::Alignment> a =
      p.anchor->align(pyramid_[static_cast<std::size_t>(cam)][0], p.pixel, p.affine, o.klt_max_iterations,
                      static_cast<float>(o.klt_epsilon));
  if (!a || a->zncc < o.anchor_min_zncc) return std::nullopt;
  const cv::Point2f correction = a->pixel - p.pixel;
  if (correction.dot(correction) > o.anchor_max_correction_px * o.anchor_max_correction_px) return std::nullopt;
  Point q = p;
  q.pixel = a->pixel;
  q.affine = a->affine;
  if (!normalize(cam, &q)) return std::nullopt;
  const Eigen::Vector2f scale = Eigen::JacobiSVD<Eigen::Matrix2f>(q.affine).singularValues();
  const auto limit = static_cast<float>(o.anchor_max_scale);
  // Far from the anchor's scale the affine model no longer describes the
  // patch (perspective, resampling): the current patch, at the aligned
  // position, becomes the anchor. The error made so far is kept, but it
  // grows only at these rare steps, not every frame.
  if (scale(0) > limit || scale(1) < 1.0f / limit) {
    Point fresh = q;
    if (anchor(cam, &fresh)) q = fresh;
  }
  return q;
}

void FeatureTracker::align_to_anchors(int cam, const PixelTest& keep, std::vector<Point>* points) const {
  std::vector<Point> kept;
  kept.reserve(points->size());
  for (const Point& p : *points) {
    std::optional<Point> q = aligned(cam, p);
    if (q && keep(q->pixel)) kept.push_back(std::move(*q));
  }
  points->swap(kept);
}

void FeatureTracker::track_static_temporal(int cam, const std::optional<Box>& box) {
  const auto c = static_cast<std::size_t>(cam);
  if (prev_pyramid_[c].empty() || static_[c].empty()) return;
  std::unordered_map<int64_t, Eigen::Vector2d> before;
  for (const Point& p : static_[c]) before.emplace(p.id, p.normalized);
  const PixelTest keep = [&](const cv::Point2f& px) { return usable(cam, px, box); };
  std::vector<Point> tracked = klt(prev_pyramid_[c], cam, pyramid_[c], static_[c], {}, keep);
  const int max_age = options_.static_tracks.max_track_frames;
  if (max_age > 0) {
    tracked.erase(std::remove_if(tracked.begin(), tracked.end(),
                                 [&](const Point& p) { return frame_index_ - p.born_frame >= max_age; }),
                  tracked.end());
  }
  if (options_.static_tracks.anchor_align) align_to_anchors(cam, keep, &tracked);
  std::vector<Eigen::Vector2d> a, b;
  for (const Point& p : tracked) {
    a.push_back(before.at(p.id));
    b.push_back(p.normalized);
  }
  const std::vector<bool> in = ransac_.inliers(a, b, focal(cam, cam));
  static_[c].clear();
  for (std::size_t i = 0; i < tracked.size(); ++i) {
    if (in[i]) static_[c].push_back(tracked[i]);
  }
}

void FeatureTracker::detect_static(const std::optional<Box>& box) {
  std::vector<Point>& left = static_[0];
  if (static_cast<int>(left.size()) >= options_.static_tracks.num_features) return;
  std::vector<cv::Point2f> existing;
  existing.reserve(left.size());
  for (const Point& p : left) existing.push_back(p.pixel);
  for (const cv::Point2f& px : detect_grid_fast(pyramid_[0][0], existing, box, options_.static_tracks)) {
    Point p;
    p.pixel = px;
    if (!normalize(0, &p)) continue;
    if (options_.static_tracks.anchor_align && !anchor(0, &p)) continue;
    p.id = next_id_++;
    p.born_frame = frame_index_;
    left.push_back(p);
  }
}

void FeatureTracker::match_static_stereo(const std::optional<Box>& box_right) {
  std::vector<Point>& left = static_[0];
  std::vector<Point>& right = static_[1];
  // Right points whose left partner was lost stay right-only tracks. Only
  // this frame's new left corners are looked for in the right image:
  // retrying every left-only track each frame cost ~2 ms per EuRoC pair for
  // ~8 % more stereo observations (mostly points the right camera cannot
  // see).
  std::vector<Point> fresh;
  for (const Point& p : left) {
    if (p.id >= first_new_id_) fresh.push_back(p);
  }
  std::vector<Point> found =
      klt(pyramid_[0], 1, pyramid_[1], fresh, {}, [&](const cv::Point2f& px) { return usable(1, px, box_right); });
  for (Point& p : found) {
    // A right track is anchored in the right image where it was matched.
    if (!options_.static_tracks.anchor_align || anchor(1, &p)) right.push_back(std::move(p));
  }

  const std::vector<bool> keep = stereo_inliers(left, right);
  std::vector<Point> kept;
  kept.reserve(right.size());
  for (std::size_t j = 0; j < right.size(); ++j) {
    if (keep[j]) kept.push_back(right[j]);
  }
  right.swap(kept);
}

std::vector<bool> FeatureTracker::stereo_inliers(const std::vector<Point>& left, const std::vector<Point>& right) {
  // One RANSAC over every stereo pair, continuing and new.
  std::unordered_map<int64_t, std::size_t> left_of;
  for (std::size_t i = 0; i < left.size(); ++i) left_of.emplace(left[i].id, i);
  std::vector<std::size_t> right_index;
  std::vector<Eigen::Vector2d> a, b;
  for (std::size_t j = 0; j < right.size(); ++j) {
    const auto it = left_of.find(right[j].id);
    if (it == left_of.end()) continue;
    right_index.push_back(j);
    a.push_back(left[it->second].normalized);
    b.push_back(right[j].normalized);
  }
  const std::vector<bool> in = ransac_.inliers(a, b, focal(0, 1));
  std::vector<bool> keep(right.size(), true);
  for (std::size_t k = 0; k < right_index.size(); ++k) {
    if (!in[k]) keep[right_index[k]] = false;
  }
  return keep;
}

std::vector<FeatureTracker::TargetPoint> FeatureTracker::klt_target(int cam, const Box& box) {
  const auto c = static_cast<std::size_t>(cam);
  const std::vector<TargetPoint>& prev = target_[c];
  if (prev.empty() || prev_pyramid_[c].empty()) return {};
  cv::Point2f shift(0.f, 0.f);
  if (prev_box_[c]) {
    shift = cv::Point2f(static_cast<float>(box.center_u() - prev_box_[c]->center_u()),
                        static_cast<float>(box.center_v() - prev_box_[c]->center_v()));
  }
  std::vector<Point> from;
  std::unordered_map<int64_t, const TargetPoint*> prev_of;
  for (const TargetPoint& t : prev) {
    from.push_back(t.point);
    prev_of.emplace(t.point.id, &t);
  }
  const PixelTest keep = [&](const cv::Point2f& px) { return on_target(cam, px, box); };
  std::vector<Point> tracked = klt(prev_pyramid_[c], cam, pyramid_[c], from, shift, keep);
  if (options_.target.anchor_align) align_to_anchors(cam, keep, &tracked);
  std::vector<Eigen::Vector2d> a, b;
  for (const Point& p : tracked) {
    a.push_back(prev_of.at(p.id)->point.normalized);
    b.push_back(p.normalized);
  }
  const std::vector<bool> in = ransac_.inliers(a, b, focal(cam, cam));
  std::vector<TargetPoint> kept;
  for (std::size_t i = 0; i < tracked.size(); ++i) {
    if (!in[i]) continue;
    TargetPoint t = *prev_of.at(tracked[i].id);
    t.point = tracked[i];
    kept.push_back(t);
  }
  return kept;
}

bool FeatureTracker::on_target(int cam, const cv::Point2f& px, const Box& box) const {
  const auto c = static_cast<std::size_t>(cam);
  if (!box.contains(px.x, px.y) || !cameras_[c].in_image(Eigen::Vector2d(px.x, px.y), 0.0)) return false;
  const cv::Mat& mask = eroded_mask_[c];
  if (mask.empty()) return true;
  const cv::Point at(cvRound(px.x), cvRound(px.y));
  return at.inside(cv::Rect(0, 0, mask.cols, mask.rows)) && mask.at<uint8_t>(at) != 0;
}

void FeatureTracker::match_target_stereo_klt(const Box& box_right, std::vector<std::vector<TargetPoint>>* cur) {
  std::vector<TargetPoint>& left = (*cur)[0];
  std::vector<TargetPoint>& right = (*cur)[1];
  std::set<int64_t> paired;
  for (const TargetPoint& t : right) paired.insert(t.point.id);
  std::vector<Point> lone;
  std::unordered_map<int64_t, const Descriptor*> descriptor_of;
  for (const TargetPoint& t : left) {
    if (paired.count(t.point.id) != 0) continue;
    lone.push_back(t.point);
    descriptor_of.emplace(t.point.id, &t.descriptor);
  }
  // Every left-only point is looked for, not only new ones: a box holds few
  // points (<= num_features), and a target point lost on the right by the
  // target's own occlusion comes back when it turns.
  const std::vector<Point> found = klt(pyramid_[0], 1, pyramid_[1], lone, {},
                                       [&](const cv::Point2f& px) { return on_target(1, px, box_right); });
  for (const Point& p : found) {
    TargetPoint t;
    t.point = p;
    t.descriptor = *descriptor_of.at(p.id);
    if (options_.target.anchor_align && !anchor(1, &t.point)) continue;
    right.push_back(t);
  }
  std::vector<Point> l, r;
  for (const TargetPoint& t : left) l.push_back(t.point);
  for (const TargetPoint& t : right) r.push_back(t.point);
  const std::vector<bool> keep = stereo_inliers(l, r);
  std::vector<TargetPoint> kept;
  for (std::size_t j = 0; j < right.size(); ++j) {
    if (keep[j]) kept.push_back(right[j]);
  }
  right.swap(kept);
}

void FeatureTracker::track_target(const std::vector<cv::Mat>& images, const std::vector<std::optional<Box>>& boxes) {
  const std::size_t n = cameras_.size();
  const TargetTrackOptions& o = options_.target;
  std::vector<std::vector<TargetPoint>> cur(n);
  std::vector<std::vector<Descriptor>> cur_desc(n);
  for (std::size_t c = 0; c < n; ++c) {
    if (!boxes[c]) continue;
    const int cam = static_cast<int>(c);
    if (o.klt()) cur[c] = klt_target(cam, *boxes[c]);
    if (c == 1 && o.stereo_klt()) continue;  // right points come from the left ones (match_target_stereo_klt)
    const std::size_t tracked = cur[c].size();
    const double min_d2 = o.min_distance_px * o.min_distance_px;
    const Box& box = *boxes[c];
    const auto cell_of = [&](const cv::Point2f& px) {
      const auto index = [&](double x, double lo, double size) {
        return std::clamp(static_cast<int>((x - lo) / std::max(size, 1e-9) * o.grid), 0, o.grid - 1);
      };
      return index(px.y, box.y_min, box.height) * o.grid + index(px.x, box.x_min, box.width);
    };
    const int cell_capacity = (o.num_features + o.grid * o.grid - 1) / (o.grid * o.grid);
    std::vector<int> in_cell(static_cast<std::size_t>(o.grid * o.grid), 0);
    for (const TargetPoint& t : cur[c]) ++in_cell[static_cast<std::size_t>(cell_of(t.point.pixel))];
    for (const OrbFeature& f : orb_.detect(images[c], box, eroded_mask_[c])) {
      if (cur[c].size() >= static_cast<std::size_t>(o.num_features)) break;
      int& cell_count = in_cell[static_cast<std::size_t>(cell_of(f.pixel))];
      if (cell_count >= cell_capacity || !on_target(cam, f.pixel, box)) continue;
      const bool near_tracked = std::any_of(cur[c].begin(), cur[c].begin() + static_cast<std::ptrdiff_t>(tracked),
                                            [&](const TargetPoint& t) {
                                              const cv::Point2f d = t.point.pixel - f.pixel;
                                              return d.dot(d) < min_d2;
                                            });
      if (near_tracked) continue;
      TargetPoint t;
      t.point.pixel = f.pixel;
      t.descriptor = f.descriptor;
      if (!normalize(cam, &t.point)) continue;
      if (o.anchor_align && !anchor(cam, &t.point)) continue;
      cur[c].push_back(t);
      ++cell_count;
    }
    for (const TargetPoint& t : cur[c]) cur_desc[c].push_back(t.descriptor);
  }

  // Frame to frame by descriptor in each camera, gated by the motion left
  // after the box's ("klt" has followed them already).
  for (std::size_t c = 0; c < n && !o.klt(); ++c) {
    const std::vector<TargetPoint>& prev = target_[c];
    if (prev.empty() || cur[c].empty()) continue;
    cv::Point2f shift(0.f, 0.f);
    if (boxes[c] && prev_box_[c]) {
      shift = cv::Point2f(static_cast<float>(boxes[c]->center_u() - prev_box_[c]->center_u()),
                          static_cast<float>(boxes[c]->center_v() - prev_box_[c]->center_v()));
    }
    std::vector<Descriptor> prev_desc;
    for (const TargetPoint& t : prev) prev_desc.push_back(t.descriptor);
    const double max_motion2 = o.max_motion_px * o.max_motion_px;
    const auto matches = match_descriptors(cur_desc[c], prev_desc, o.max_hamming, o.match_ratio, [&](int i, int j) {
      const cv::Point2f d =
          cur[c][static_cast<std::size_t>(i)].point.pixel - (prev[static_cast<std::size_t>(j)].point.pixel + shift);
      return d.dot(d) <= max_motion2;
    });
    std::vector<Eigen::Vector2d> a, b;
    for (const auto& [i, j] : matches) {
      a.push_back(prev[static_cast<std::size_t>(j)].point.normalized);
      b.push_back(cur[c][static_cast<std::size_t>(i)].point.normalized);
    }
    const int cam = static_cast<int>(c);
    const std::vector<bool> in = ransac_.inliers(a, b, focal(cam, cam));
    for (std::size_t k = 0; k < matches.size(); ++k) {
      if (in[k])
        cur[c][static_cast<std::size_t>(matches[k].first)].point.id =
            prev[static_cast<std::size_t>(matches[k].second)].point.id;
    }
  }

  // Left to right: a pair shares one id.
  std::vector<std::pair<int, int>> new_pairs;  // stereo pairs with no id yet
  if (n == 2 && !o.stereo_klt() && !cur[0].empty() && !cur[1].empty()) {
    const auto matches = match_descriptors(cur_desc[0], cur_desc[1], o.max_hamming, o.match_ratio, {});
    std::vector<Eigen::Vector2d> a, b;
    for (const auto& [i, j] : matches) {
      a.push_back(cur[0][static_cast<std::size_t>(i)].point.normalized);
      b.push_back(cur[1][static_cast<std::size_t>(j)].point.normalized);
    }
    const std::vector<bool> in = ransac_.inliers(a, b, focal(0, 1));
    std::set<int64_t> left_ids, right_ids;
    for (const TargetPoint& t : cur[0]) left_ids.insert(t.point.id);
    for (const TargetPoint& t : cur[1]) right_ids.insert(t.point.id);
    for (std::size_t k = 0; k < matches.size(); ++k) {
      if (!in[k]) continue;
      Point& l = cur[0][static_cast<std::size_t>(matches[k].first)].point;
      Point& r = cur[1][static_cast<std::size_t>(matches[k].second)].point;
      if (l.id >= 0 && r.id < 0 && right_ids.insert(l.id).second) {
        r.id = l.id;
      } else if (r.id >= 0 && l.id < 0 && left_ids.insert(r.id).second) {
        l.id = r.id;
      } else if (l.id < 0 && r.id < 0) {
        new_pairs.push_back(matches[k]);
      }
      // Both tracked under different ids: two tracks that disagree; neither
      // is renamed, the estimator's gating judges them.
    }
  }

  // Loop closure: features without an id against the stored target points
  // out of view in this frame.
  std::set<int64_t> in_view;
  for (std::size_t c = 0; c < n; ++c) {
    for (const TargetPoint& t : cur[c]) {
      if (t.point.id >= 0) in_view.insert(t.point.id);
    }
  }
  std::map<int, int> right_partner;  // left index -> right index of a new pair
  std::set<int> right_in_pair;
  for (const auto& [i, j] : new_pairs) {
    right_partner[i] = j;
    right_in_pair.insert(j);
  }
  struct Query {
    std::size_t cam;
    int index;
  };
  std::vector<Query> queries;
  std::vector<Descriptor> query_desc;
  for (std::size_t c = 0; c < n; ++c) {
    for (std::size_t i = 0; i < cur[c].size(); ++i) {
      if (cur[c][i].point.id >= 0) continue;
      if (c == 1 && right_in_pair.count(static_cast<int>(i)) != 0) continue;  // asked through its left partner
      queries.push_back({c, static_cast<int>(i)});
      query_desc.push_back(cur[c][i].descriptor);
    }
  }
  const std::vector<int64_t> found = store_.match(query_desc, in_view);
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const std::size_t c = queries[q].cam;
    const int i = queries[q].index;
    int64_t id = found[q];
    if (id >= 0) {
      ++loop_closures_;
    } else {
      id = next_id_++;
    }
    cur[c][static_cast<std::size_t>(i)].point.id = id;
    if (c == 0) {
      const auto it = right_partner.find(i);
      if (it != right_partner.end()) cur[1][static_cast<std::size_t>(it->second)].point.id = id;
    }
  }

  if (n == 2 && o.stereo_klt() && boxes[0] && boxes[1]) match_target_stereo_klt(*boxes[1], &cur);

  for (std::size_t c = 0; c < n; ++c) {
    for (const TargetPoint& t : cur[c]) store_.update(t.point.id, t.descriptor, frame_index_);
  }
  target_.swap(cur);
}

CameraFrame FeatureTracker::track(int64_t utime, const cv::Mat& left, const cv::Mat& right, std::optional<Box> box_left,
                                  std::optional<Box> box_right, const cv::Mat& mask_left, const cv::Mat& mask_right) {
  check_input(utime, left, right, box_left, box_right, mask_left, mask_right);
  using Clock = std::chrono::steady_clock;
  Clock::time_point t = Clock::now();
  const Clock::time_point start = t;
  auto lap = [&t](double* ms) {
    const Clock::time_point now = Clock::now();
    *ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
  };
  const std::size_t n = cameras_.size();
  std::vector<cv::Mat> images = n == 2 ? std::vector<cv::Mat>{left, right} : std::vector<cv::Mat>{left};
  if (options_.static_tracks.equalize) {
    // KLT compares raw intensities: two cameras (or one camera across an
    // exposure change) with different gain would otherwise disagree on
    // every patch. Equalised, half the EuRoC stereo matches stop failing.
    for (cv::Mat& image : images) {
      cv::Mat equalized;
      cv::equalizeHist(image, equalized);
      image = equalized;
    }
  }
  const std::vector<std::optional<Box>> boxes =
      n == 2 ? std::vector<std::optional<Box>>{box_left, box_right} : std::vector<std::optional<Box>>{box_left};
  const StaticTrackOptions& o = options_.static_tracks;
  const std::vector<cv::Mat> masks =
      n == 2 ? std::vector<cv::Mat>{mask_left, mask_right} : std::vector<cv::Mat>{mask_left};
  for (std::size_t c = 0; c < n; ++c) {
    eroded_mask_[c] = cv::Mat();
    if (options_.target.use_mask && !masks[c].empty()) {
      // Outside the image counts as off the target (border value 0).
      const int r = o.target_mask_erode_px();
      const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * r + 1, 2 * r + 1));
      cv::erode(masks[c] != 0, eroded_mask_[c], square, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    }
    pyramid_[c].clear();
    cv::buildOpticalFlowPyramid(images[c], pyramid_[c], cv::Size(o.klt_window_px, o.klt_window_px),
                                o.klt_pyramid_levels);
  }

  lap(&timing_.preprocess_ms);
  for (std::size_t c = 0; c < n; ++c) track_static_temporal(static_cast<int>(c), boxes[c]);
  lap(&timing_.static_temporal_ms);
  first_new_id_ = next_id_;
  detect_static(boxes[0]);
  lap(&timing_.detect_ms);
  if (n == 2) match_static_stereo(boxes[1]);
  lap(&timing_.static_stereo_ms);
  track_target(images, boxes);
  lap(&timing_.target_ms);

  CameraFrame frame;
  frame.utime = utime;
  for (std::size_t c = 0; c < n; ++c) {
    std::vector<FeatureObservation> obs;
    auto add = [&](const Point& p, bool is_target) {
      FeatureObservation f;
      f.feature_id = p.id;
      f.camera_id = static_cast<int>(c);
      f.pixel = Eigen::Vector2d(p.pixel.x, p.pixel.y);
      f.normalized = p.normalized;
      f.is_target = is_target;
      obs.push_back(f);
    };
    for (const Point& p : static_[c]) add(p, false);
    for (const TargetPoint& t : target_[c]) add(t.point, true);
    std::sort(obs.begin(), obs.end(),
              [](const FeatureObservation& a, const FeatureObservation& b) { return a.feature_id < b.feature_id; });
    frame.observations.insert(frame.observations.end(), obs.begin(), obs.end());
  }

  prev_pyramid_.swap(pyramid_);
  prev_box_ = boxes;
  timing_.total_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  last_utime_ = utime;
  ++frame_index_;
  return frame;
}

}  // namespace vimot::frontend
