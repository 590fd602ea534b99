#include "common/target/target_output.h"

#include <cmath>

#include "common/target/target_conversion.h"

namespace vimot {
namespace target {

TargetStateEstimate target_state_estimate(int64_t utime, TargetRepresentation representation, const TargetValue& x,
                                          const Matrix12d& P, const PoseValue& imu_pose, int num_target_points,
                                          int start_count) {
  TargetStateEstimate s;
  s.utime = utime;
  s.covariance = P;
  s.num_target_points = num_target_points;
  s.start_count = start_count;
  TargetValue local, global;
  if (representation == TargetRepresentation::kLocal) {
    s.representation = TargetFrame::kLocal;
    local = x;
    global = local_to_global(imu_pose, x);
  } else {
    s.representation = TargetFrame::kGlobal;
    global = x;
    local = global_to_local(imu_pose, x);
  }
  s.q_ItoT = local.q_RtoT;
  s.p_TinI = local.p_TinR;
  s.q_GtoT = global.q_RtoT;
  s.p_TinG = global.p_TinR;
  s.v_TinT = x.v_TinT;
  s.w_TinT = x.w_TinT;
  return s;
}

TargetPosePrediction target_pose_prediction(int64_t utime, double horizon_s, const TargetPrediction& prediction,
                                            const PoseValue& imu_pose) {
  TargetPosePrediction p;
  p.utime = utime;
  p.prediction_utime = utime + static_cast<int64_t>(std::llround(horizon_s * 1e6));
  p.q_GtoT = prediction.x.q_RtoT;
  p.p_TinG = prediction.x.p_TinR;
  const TargetValue rel = global_to_local(imu_pose, prediction.x);
  p.q_ItoT = rel.q_RtoT;
  p.p_TinI = rel.p_TinR;
  p.covariance = prediction.P.topLeftCorner<6, 6>();
  return p;
}

}  // namespace target
}  // namespace vimot
