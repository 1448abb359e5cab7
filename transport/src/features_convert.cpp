#include "cvslam/lcm/features_convert.h"

#include "cvslam/lcm/message_finalize.h"

namespace cvslam::transport {

Expected<cvslam::stereo_features_t> toMessage(const StereoFrameObservations& frame,
                                              int32_t agent_id) {
  cvslam::stereo_features_t msg{};
  msg.header.utime = frame.t_us;
  msg.header.agent_id = agent_id;
  for (const StereoObservation& o : frame.observations) {
    msg.index.push_back(static_cast<int32_t>(o.index));
    msg.u_left.push_back(o.z[0]);
    msg.v_left.push_back(o.z[1]);
    msg.u_right.push_back(o.z[2]);
    msg.v_right.push_back(o.z[3]);
    msg.descriptors.push_back(o.descriptor);
  }
  Status status = finalize(msg);
  if (!status.ok()) return status;
  return msg;
}

StereoFrameObservations fromMessage(const cvslam::stereo_features_t& msg) {
  StereoFrameObservations frame;
  frame.t_us = msg.header.utime;
  // Sizes are trusted here: messages reach this point only through decodeMessage().
  frame.observations.resize(msg.index.size());
  for (std::size_t i = 0; i < msg.index.size(); ++i) {
    StereoObservation& o = frame.observations[i];
    o.index = static_cast<uint32_t>(msg.index[i]);
    o.z = Eigen::Vector4d(msg.u_left[i], msg.v_left[i], msg.u_right[i], msg.v_right[i]);
    o.type = ObservationType::kNew;
    o.landmark_id = -1;
    if (i < msg.descriptors.size()) o.descriptor = msg.descriptors[i];
  }
  return frame;
}

}  // namespace cvslam::transport
