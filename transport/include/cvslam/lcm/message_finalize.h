#pragma once
// Count fields of the generated messages must equal their vectors' sizes: the generated
// encode() trusts them and reads out of bounds otherwise (docs/architecture.md). finalize() is the
// one place that sets them. It derives every count from the vectors and fails (leaving the
// message unusable) when parallel arrays disagree or a row has the wrong width, so that a
// malformed message is an error at the sender instead of garbage on the wire.

#include "cvslam/core/status.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {

Status finalize(cvslam::imu_t& msg);
Status finalize(cvslam::stereo_image_t& msg);
Status finalize(cvslam::stereo_features_t& msg);
Status finalize(cvslam::pose_t& msg);
Status finalize(cvslam::agent_map_t& msg);
Status finalize(cvslam::agent_state_t& msg);
Status finalize(cvslam::agent_summary_t& msg);
Status finalize(cvslam::feature_index_t& msg);
Status finalize(cvslam::shared_request_t& msg);
Status finalize(cvslam::shared_landmarks2_t& msg);
Status finalize(cvslam::observation_batch_t& msg);
Status finalize(cvslam::gs_state_t& msg);
Status finalize(cvslam::map_t& msg);
Status finalize(cvslam::status_t& msg);

/// The message, finalized, or finalize()'s error.
template <typename Msg>
Expected<Msg> finalized(Msg msg) {
  if (Status s = finalize(msg); !s.ok()) return s;
  return msg;
}

}  // namespace cvslam::transport
