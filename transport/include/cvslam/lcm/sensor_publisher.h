#pragma once
// Publishes a core sensor stream (sensors/sensor_stream.h) on the per-agent channels
// (channels.h): IMU → UAV<id>/IMU (imu_t), ground truth → UAV<id>/GT (pose_t), stereo pair
// → UAV<id>/STEREO (stereo_image_t, mono8 or PNG), features → UAV<id>/FEATURES
// (stereo_features_t). header.utime = the event's dataset time; header.agent_id = the
// replay's sender id; header.seq is stamped per channel by LcmBus.
#include <cstdint>
#include "cvslam/core/status.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/sensor_convert.h"
#include "cvslam/sensors/sensor_stream.h"

namespace cvslam::transport {

struct SensorPublisherOptions {
  bool png = false;                     ///< stereo images as PNG instead of mono8
  bool ground_truth = true;             ///< publish UAV<id>/GT
  int32_t sender_id = kReplaySenderId;  ///< header.agent_id
};

class SensorPublisher {
 public:
  SensorPublisher(LcmBus& bus, SensorPublisherOptions options) : bus_(bus), options_(options) {}
  Status publish(const SensorEvent& event);
  int64_t messages() const { return messages_; }
  int64_t bytes() const { return bytes_; }  ///< encoded payload bytes published

 private:
  template <typename Msg>
  Status send(const std::string& channel, Msg& msg);
  LcmBus& bus_;
  SensorPublisherOptions options_;
  int64_t messages_ = 0;
  int64_t bytes_ = 0;
};

}  // namespace cvslam::transport
