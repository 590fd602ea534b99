#pragma once
// The `object_tracker` process's logic without LCM: feeds each FEATURES
// frame to the up-to-scale object tracker (common/object/object_tracker.h),
// says what to publish (OBJECT_POSE_UPTOSCALE for every accepted frame,
// valid or not) and reports dropped input and track changes as node events.
// main.cc only moves messages; the offline scale evaluator
// (procs/eval/scale_run.h) drives this same class.

#include <cstdint>
#include <functional>

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
  void on_frame(const CameraFrame& frame);

  const ObjectTracker& tracker() const { return tracker_; }

 private:
  void say(NodeEvent::Kind kind, const std::string& message);

  ObjectTracker tracker_;
  PoseCallback on_pose_;
  EventCallback on_event_;
  int64_t last_track_id_{0};
};

}  // namespace vimot
