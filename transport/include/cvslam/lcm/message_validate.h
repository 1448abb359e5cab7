#pragma once
// Content checks applied to every message before it is published and after it is
// decoded (docs/architecture.md): count fields equal their vectors' sizes, every floating-point
// number is finite, enumerations and dimensions take allowed values, image sizes match
// their encoding. The agent id is not checked here (that is the receiver's policy, see
// BusOptions::accept_agent).

#include "cvslam/core/status.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {

Status validate(const cvslam::imu_t& msg);
Status validate(const cvslam::stereo_image_t& msg);
Status validate(const cvslam::stereo_features_t& msg);
Status validate(const cvslam::pose_t& msg);
Status validate(const cvslam::agent_map_t& msg);
Status validate(const cvslam::agent_state_t& msg);
Status validate(const cvslam::agent_summary_t& msg);
Status validate(const cvslam::feature_index_t& msg);
Status validate(const cvslam::shared_request_t& msg);
Status validate(const cvslam::shared_landmarks2_t& msg);
Status validate(const cvslam::observation_batch_t& msg);
Status validate(const cvslam::gs_state_t& msg);
Status validate(const cvslam::map_t& msg);
Status validate(const cvslam::status_t& msg);

}  // namespace cvslam::transport
