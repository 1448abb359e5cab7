#include "cvslam/lcm/sensor_publisher.h"

#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/features_convert.h"
#include "cvslam/lcm/imu_convert.h"

namespace cvslam::transport {

template <typename Msg>
Status SensorPublisher::send(const std::string& channel, Msg& msg) {
  Status s = bus_.publish(channel, msg);
  if (!s.ok()) return s;
  ++messages_;
  bytes_ += msg.getEncodedSize();  // publish() finalized the counts, so this is exact
  return Status::Ok();
}

Status SensorPublisher::publish(const SensorEvent& e) {
  const std::string channel = channelName(channelStream(e.type), e.agent_id);
  switch (e.type) {
    case SensorEventType::kImu: {
      ImuSample sample = e.imu;
      sample.t_us = e.t_us;
      cvslam::imu_t msg = toMessage(sample, options_.sender_id);
      return send(channel, msg);
    }
    case SensorEventType::kGroundTruth: {
      if (!options_.ground_truth) return Status::Ok();
      cvslam::pose_t msg = toPoseMessage(e.truth, e.t_us, options_.sender_id);
      return send(channel, msg);
    }
    case SensorEventType::kStereoImage: {
      auto msg = toStereoMessage(e.left, e.right, e.t_us, options_.sender_id, options_.png);
      if (!msg.ok()) return msg.status();
      return send(channel, *msg);
    }
    case SensorEventType::kFeatures: {
      StereoFrameObservations frame = e.features;
      frame.t_us = e.t_us;
      auto msg = toMessage(frame, options_.sender_id);
      if (!msg.ok()) return msg.status();
      return send(channel, *msg);
    }
  }
  return Status::Error("unknown sensor event type");
}

}  // namespace cvslam::transport
