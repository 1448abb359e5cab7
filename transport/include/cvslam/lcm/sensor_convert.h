#pragma once
// Conversions from the core's sensor stream (sensors/sensor_stream.h) to LCM messages:
// ground truth → pose_t, stereo pair → stereo_image_t (mono8 or PNG). IMU and features
// have their own adapters (imu_convert.h, features_convert.h).
#include <cstdint>
#include <opencv2/core.hpp>
#include "cvslam/core/status.h"
#include "cvslam/io/run_record.h"
#include "cvslam/lcm/message_types.h"
#include "cvslam/sensors/sensor_stream.h"

namespace cvslam::transport {

/// header.agent_id of everything the replay or simulator publishes (header_t.lcm).
constexpr int32_t kReplaySenderId = -1;

cvslam::pose_t toPoseMessage(const VehiclePose& pose, int64_t t_us, int32_t sender_id);

/// The pose back (gyro and accel biases are not carried: zero).
VehiclePose fromPoseMessage(const cvslam::pose_t& msg);

/// The true vehicle state [p_BinN, v_B, euler] of a pose, in the layout of the run record's
/// truth.csv (the agents' and the ground station's).
Vector9d truthState(const VehiclePose& pose);

/// Both images must be CV_8UC1 of the same size. `png`: each image as a PNG file (lossless,
/// fastest compression level, since the replay must keep up with real time).
Expected<cvslam::stereo_image_t> toStereoMessage(const cv::Mat& left, const cv::Mat& right,
                                                 int64_t t_us, int32_t sender_id, bool png);

/// Decodes a stereo_image_t (either encoding) into two CV_8UC1 images.
Status fromStereoMessage(const cvslam::stereo_image_t& msg, cv::Mat& left, cv::Mat& right);

/// The sensor event a received message carries for UAV `agent_id` (t_us = header.utime,
/// play_us 0): what the agent's subscriptions and a logged run (lcm_log_sensor_stream.h) feed
/// on. False only for a stereo pair whose images do not decode.
bool toSensorEvent(const cvslam::imu_t& msg, int agent_id, SensorEvent* event);
bool toSensorEvent(const cvslam::pose_t& msg, int agent_id, SensorEvent* event);
bool toSensorEvent(const cvslam::stereo_features_t& msg, int agent_id, SensorEvent* event);
bool toSensorEvent(const cvslam::stereo_image_t& msg, int agent_id, SensorEvent* event);

/// Ground truth within this of a frame is the frame's truth (cvslam_eval's default
/// association tolerance) [µs].
constexpr int64_t kTruthToleranceUs = 10000;

}  // namespace cvslam::transport
