#pragma once
// The `object_tracker` process's logic without LCM: feeds each FEATURES
// frame to the up-to-scale object tracker (common/object/object_tracker.h),
// says what to publish (OBJECT_POSE_UPTOSCALE for every accepted frame,
// valid or not) and reports dropped input and track changes as node events.
// main.cc only moves messages; the offline scale evaluator
// (procs/eval/scale_run.h) drives this same class.

#include <cstdint>
#include <functional>
#include <map>

#include "common/object/object_tracker.h"
#include "common/process/node_event.h"
#include "common/types/object_pose.h"
#include "common/types/sensor_data.h"

namespace vimot {

class ObjectTrackerNode {
 public:
  using PoseCallback = std::function<void(const ObjectPoseEstimate&)>;
  using EventCallback = std::function<void(const NodeEvent&)>;

  ObjectTrackerNode(const ObjectTrackerOptions& options, PoseCallback on_pose, EventCallback on_event);

  /// A frame whose utime repeats or goes back is dropped (an event, no pose).
  /// The box of its utime (on_box), if one came, goes with it.
  void on_frame(const CameraFrame& frame);

  /// The target's box in cam0 at `utime` (TARGET_BOX; TARGET_BOX_TRUTH in
  /// simulation): the object's centre ray at initialisation. It must come
  /// before the frame of its utime (the box source publishes it with the
  /// image, the feature tracker its FEATURES after it); a frame without one
  /// uses the bounding box of its target features.
  void on_box(int64_t utime, const BoundingBox2d& box);

  const ObjectTracker& tracker() const { return tracker_; }

 private:
  void say(NodeEvent::Kind kind, const std::string& message);

  ObjectTracker tracker_;
  PoseCallback on_pose_;
  EventCallback on_event_;
  int64_t last_track_id_{0};
  std::map<int64_t, BoundingBox2d> boxes_;  // by utime, not yet used by a frame
};

}  // namespace vimot
