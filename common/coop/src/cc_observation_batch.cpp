#include "cvslam/coop/cc_observation_batch.h"

#include <cctype>
#include <cmath>
#include <string>

#include "cvslam/coop/cc_batch_builder.h"

namespace cvslam::coop {

Status validateBatch(const CcObservationBatch& batch, double max_pixel, std::string* defect) {
  auto fail = [defect](const char* kind, const std::string& why) {
    if (defect != nullptr) *defect = kind;
    return Status::Error(why);
  };
  if (batch.frame.t_us != batch.t_us) {
    return fail("frame_time", "frame time " + std::to_string(batch.frame.t_us) +
                                  " µs differs from the batch time");
  }
  for (std::size_t i = 0; i < batch.imu.size(); ++i) {
    const ImuSample& s = batch.imu[i];
    if (!s.gyro_B.allFinite() || !s.accel_B.allFinite()) {
      return fail("imu_not_finite", "IMU sample " + std::to_string(i) + " is not finite");
    }
    if (s.t_us > batch.t_us) return fail("imu_after_frame", "IMU sample after the frame time");
    if (i > 0 && s.t_us <= batch.imu[i - 1].t_us) {
      return fail("imu_order", "IMU samples not strictly ascending");
    }
  }
  const std::size_t descriptor_bytes =
      batch.frame.observations.empty() ? 0 : batch.frame.observations.front().descriptor.size();
  for (const StereoObservation& obs : batch.frame.observations) {
    // A negative disparity is no defect: the pixel noise of a distant landmark's pair (σ√2 on
    // the disparity) makes some, and the agent's own filter updates with them as it does with
    // any other observation (only initialisation needs a disparity, min_init_disparity_px).
    if (!obs.z.allFinite() || obs.z.cwiseAbs().maxCoeff() > max_pixel) {
      return fail("pixels", "observation with non-finite or absurd pixels");
    }
    if (obs.descriptor.size() != descriptor_bytes) {
      return fail("descriptors", "descriptors of different lengths");
    }
  }
  return Status::Ok();
}

std::string refusalsOf(const std::string& text, int agent_id) {
  const std::string key = "UAV" + std::to_string(agent_id) + " ";
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + 1)) {
    // A whole name: "UAV1 " must not match inside "UAV11 ".
    if (at > 0 && std::isalnum(static_cast<unsigned char>(text[at - 1])) != 0) continue;
    const std::size_t from = at + key.size();
    const std::size_t end = text.find(';', from);
    return text.substr(from, end == std::string::npos ? std::string::npos : end - from);
  }
  return {};
}

int64_t batchPayloadBytes(const CcObservationBatch& batch) {
  // observation_batch_t: header (utime, sequence, agent id: 8 + 8 + 4), IMU (count + time and
  // two 3-vectors per sample), features (count + index, type, landmark id, 4 pixels each,
  // descriptor length + bytes).
  constexpr int64_t kHeader = 20, kCount = 4, kImuSample = 8 + 6 * 8;
  constexpr int64_t kFeature = 4 + 1 + 8 + 4 * 8;
  const auto n_imu = static_cast<int64_t>(batch.imu.size());
  const auto n_obs = static_cast<int64_t>(batch.frame.observations.size());
  const int64_t descriptor_bytes =
      n_obs == 0 ? 0 : static_cast<int64_t>(batch.frame.observations.front().descriptor.size());
  return kHeader + kCount + n_imu * kImuSample + kCount + n_obs * kFeature + kCount +
         n_obs * descriptor_bytes;
}

CcObservationBatch CcBatchBuilder::takeBatch(const AgentFrame& frame) {
  if (frame.observations != nullptr) return takeBatch(*frame.observations);
  StereoFrameObservations none;
  none.t_us = frame.t_us;
  return takeBatch(none);
}

CcObservationBatch CcBatchBuilder::takeBatch(const StereoFrameObservations& frame) {
  CcObservationBatch b;
  b.agent_id = agent_id_;
  b.t_us = frame.t_us;
  b.frame = frame;
  std::size_t n = 0;
  while (n < imu_.size() && imu_[n].t_us <= frame.t_us) ++n;
  b.imu.assign(imu_.begin(), imu_.begin() + static_cast<std::ptrdiff_t>(n));
  imu_.erase(imu_.begin(), imu_.begin() + static_cast<std::ptrdiff_t>(n));
  return b;
}

}  // namespace cvslam::coop
