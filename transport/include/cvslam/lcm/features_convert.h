#pragma once
// Conversions between the core's StereoFrameObservations and stereo_features_t, the
// feature-only simulation stream (one adapter file per message family).
// The message carries index, z = [u_L v_L u_R v_R] and descriptor only: association to
// the map (type, landmark_id) is the receiving agent's job, so fromMessage() returns
// every observation as ObservationType::kNew with landmark_id −1.

#include <cstdint>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/status.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {

/// Fails if the descriptors differ in length (the message has one length for all).
/// Indices are uint32 in the core and travel as the same bit pattern in int32.
Expected<cvslam::stereo_features_t> toMessage(const StereoFrameObservations& frame,
                                              int32_t agent_id);
StereoFrameObservations fromMessage(const cvslam::stereo_features_t& msg);

}  // namespace cvslam::transport
