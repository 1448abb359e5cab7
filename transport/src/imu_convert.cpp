#include "cvslam/lcm/imu_convert.h"

namespace cvslam::transport {

cvslam::imu_t toMessage(const ImuSample& sample, int32_t agent_id) {
  cvslam::imu_t msg{};
  msg.header.utime = sample.t_us;
  msg.header.agent_id = agent_id;
  for (int i = 0; i < 3; ++i) {
    msg.gyro[i] = sample.gyro_B[i];
    msg.accel[i] = sample.accel_B[i];
  }
  return msg;
}

ImuSample fromMessage(const cvslam::imu_t& msg) {
  ImuSample sample;
  sample.t_us = msg.header.utime;
  for (int i = 0; i < 3; ++i) {
    sample.gyro_B[i] = msg.gyro[i];
    sample.accel_B[i] = msg.accel[i];
  }
  return sample;
}

}  // namespace cvslam::transport
