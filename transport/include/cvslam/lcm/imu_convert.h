#pragma once
// Conversions between the core's ImuSample and imu_t (one adapter file per
// message family; the core never sees LCM types).

#include <cstdint>

#include "cvslam/ins/imu_sample.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport {

/// header.utime = t_us, header.agent_id = agent_id; header.seq is stamped by LcmBus.
cvslam::imu_t toMessage(const ImuSample& sample, int32_t agent_id);
ImuSample fromMessage(const cvslam::imu_t& msg);

}  // namespace cvslam::transport
