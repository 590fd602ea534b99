#include "procs/object_tracker/object_tracker_node.h"

#include <string>
#include <utility>

namespace vimot {

namespace {
constexpr std::size_t kMaxPendingBoxes = 64;  // 3 s at 20 Hz
}  // namespace

ObjectTrackerNode::ObjectTrackerNode(const ObjectTrackerOptions& options, PoseCallback on_pose,
                                     EventCallback on_event)
    : tracker_(options), on_pose_(std::move(on_pose)), on_event_(std::move(on_event)) {}

void ObjectTrackerNode::say(NodeEvent::Kind kind, const std::string& message) {
  if (on_event_) on_event_(NodeEvent{kind, message});
}

void ObjectTrackerNode::on_box(int64_t utime, const BoundingBox2d& box) {
  boxes_[utime] = box;
  // Boxes of frames that never come (e.g. a frame dropped upstream).
  while (boxes_.size() > kMaxPendingBoxes) boxes_.erase(boxes_.begin());
}

void ObjectTrackerNode::on_frame(const CameraFrame& frame) {
  std::optional<BoundingBox2d> box;
  const auto it = boxes_.find(frame.utime);
  if (it != boxes_.end()) box = it->second;
  boxes_.erase(boxes_.begin(), boxes_.upper_bound(frame.utime));
  const ObjectTrackerCounters before = tracker_.counters();
  const ObjectPoseEstimate estimate = tracker_.process(frame, box);
  const ObjectTrackerCounters& after = tracker_.counters();
  if (after.rejected_time_backwards > before.rejected_time_backwards) {
    say(NodeEvent::Kind::kDropped, "FEATURES utime went backwards");
    return;
  }
  if (after.rejected_duplicate_time > before.rejected_duplicate_time) {
    say(NodeEvent::Kind::kDropped, "FEATURES utime repeated");
    return;
  }
  if (after.dropped_non_finite_observations > before.dropped_non_finite_observations) {
    say(NodeEvent::Kind::kDropped, "non-finite target observation");
  }
  if (after.track_losses > before.track_losses) {
    say(NodeEvent::Kind::kInfo, "object track lost at utime " + std::to_string(frame.utime));
  }
  if (estimate.valid && estimate.track_id != last_track_id_) {
    last_track_id_ = estimate.track_id;
    say(NodeEvent::Kind::kInfo,
        "object track " + std::to_string(estimate.track_id) + " initialised at utime " + std::to_string(frame.utime));
  }
  if (on_pose_) on_pose_(estimate);
}

}  // namespace vimot
