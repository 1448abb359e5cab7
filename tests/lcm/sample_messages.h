#pragma once
// Deterministic, fully populated sample of every cvslam message type for the LCM tests,
// plus per-type facts the fault-injection tests need (where the first count field sits,
// how to make a valid encoding semantically invalid).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/message_types.h"

namespace cvslam::transport::testing {

using AllMessageTypes =
    ::testing::Types<cvslam::imu_t, cvslam::stereo_image_t, cvslam::stereo_features_t,
                     cvslam::pose_t, cvslam::agent_state_t, cvslam::agent_summary_t,
                     cvslam::feature_index_t, cvslam::shared_request_t, cvslam::shared_landmarks2_t,
                     cvslam::observation_batch_t, cvslam::gs_state_t, cvslam::map_t,
                     cvslam::agent_map_t, cvslam::status_t>;

/// Names typed tests after the message type (CodecTest/imu_t.…) instead of an index.
struct TypeNames {
  template <typename Msg>
  static std::string GetName(int) {
    return Msg::getTypeName();
  }
};

inline void setHeader(cvslam::header_t& h, int64_t utime) {
  h.utime = utime;
  h.seq = 7;
  h.agent_id = 2;
}

inline std::vector<uint8_t> bytes(std::size_t n, uint8_t start) {
  std::vector<uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<uint8_t>(start + 13 * i);
  return v;
}

inline void fill(cvslam::imu_t& m) {
  setHeader(m.header, 1000);
  for (int i = 0; i < 3; ++i) {
    m.gyro[i] = 0.01 * (i + 1);
    m.accel[i] = i == 2 ? -9.81 : 0.1 * i;
  }
}
inline void fill(cvslam::stereo_image_t& m) {
  setHeader(m.header, 2000);
  m.encoding = cvslam::stereo_image_t::ENCODING_MONO8;
  m.width = 20;
  m.height = 10;
  m.stride = 24;
  m.left_data = bytes(24 * 10, 1);
  m.right_data = bytes(24 * 10, 2);
}
inline void fill(cvslam::stereo_features_t& m) {
  setHeader(m.header, 3000);
  for (int i = 0; i < 5; ++i) {
    m.index.push_back(100 + i);
    m.u_left.push_back(10.5 + i);
    m.v_left.push_back(20.25 + i);
    m.u_right.push_back(5.5 + i);
    m.v_right.push_back(20.25 + i);
    m.descriptors.push_back(bytes(32, static_cast<uint8_t>(i)));
  }
}
inline void fill(cvslam::pose_t& m) {
  setHeader(m.header, 4000);
  const double values[13] = {1, 2, -3, 1, 0, 0, 0, 0, 0, 0.5, 0.1, 0.2, 0.3};
  for (int i = 0; i < 3; ++i) m.position[i] = values[i];
  for (int i = 0; i < 4; ++i) m.quaternion[i] = values[3 + i];
  for (int i = 0; i < 3; ++i) m.euler[i] = values[7 + i];
  for (int i = 0; i < 3; ++i) m.velocity[i] = values[10 + i];
}
inline void fill(cvslam::agent_state_t& m) {
  setHeader(m.header, 5000);
  m.filter = "ekf";
  m.state.assign(9, 0.5);
  m.covariance.assign(81, 0.0);
  for (int i = 0; i < 9; ++i) m.covariance[i * 9 + i] = 0.01 * (i + 1);
  m.num_landmarks = 20;
  m.num_archived = 3;
}
inline void fill(cvslam::agent_summary_t& m) {
  setHeader(m.header, 6000);
  m.mode = "dc";
  m.boot_id = 0x1234567890LL;
  for (int i = 0; i < 3; ++i) {
    m.ellipsoid_mean[i] = 10.0 * i;
    m.ellipsoid_std[i] = 1.0 + i;
  }
  m.num_features = 42;
  m.vehicle_cov_trace = 0.3;
  m.own_frame = true;
  m.channel = {"UAV2/IMU", "UAV2/STEREO"};
  m.received = {2000, 100};
  m.dropped = {0, 1};
  m.invalid = {0, 2};
}
inline void fill(cvslam::feature_index_t& m) {
  setHeader(m.header, 7000);
  m.true_ids = true;
  m.index = {3, 5, 8, 13, 21, 34};
}
inline void fill(cvslam::shared_request_t& m) {
  setHeader(m.header, 8000);
  m.index = {5, 13};
}
inline void fill(cvslam::shared_landmarks2_t& m) {
  setHeader(m.header, 9000);
  m.vehicle_cov_trace = 0.7;
  m.informed_by = {1, 2};
  for (int i = 0; i < 4; ++i) {
    m.index.push_back(i * 3);
    m.position.push_back({1.0 * i, 2.0, -3.0});
    m.covariance.push_back({0.1, 0.01, 0.0, 0.2, 0.02, 0.3});
    m.descriptors.push_back(bytes(16, static_cast<uint8_t>(i)));
  }
  for (int k = 0; k < 4 * 3 / 2; ++k)  // (0,1) (0,2) (0,3) (1,2) (1,3) (2,3)
    m.cross_covariance.push_back({0.01 * k, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01});
}
inline void fill(cvslam::observation_batch_t& m) {
  setHeader(m.header, 10000);
  for (int i = 0; i < 10; ++i) {
    m.imu_age_us.push_back(1000 - 100 * i);
    m.gyro.push_back({0.01f, 0.02f, 0.03f * static_cast<float>(i)});
    m.accel.push_back({0.1f, 0.0f, -9.81f});
  }
  for (int i = 0; i < 3; ++i) {
    m.index.push_back(50 + i);
    m.type.push_back(i == 0 ? cvslam::observation_batch_t::TYPE_NEW
                            : cvslam::observation_batch_t::TYPE_REOBSERVED);
    m.landmark_id.push_back(i == 0 ? -1 : 7 + i);
    m.u_left.push_back(100.0f + static_cast<float>(i));
    m.v_left.push_back(200.0f + static_cast<float>(i));
    m.u_right.push_back(90.0f + static_cast<float>(i));
    m.v_right.push_back(200.0f + static_cast<float>(i));
    m.descriptors.push_back(bytes(8, static_cast<uint8_t>(i)));
  }
}
inline void fill(cvslam::gs_state_t& m) {
  setHeader(m.header, 11000);
  m.filter = "ekf";
  m.map_version = 4;
  m.state.assign(15, -0.25);
  m.covariance.assign(225, 0.001);
}
inline void fill(cvslam::map_t& m) {
  setHeader(m.header, 12000);
  m.map_version = 9;
  for (int i = 0; i < 6; ++i) {
    m.index.push_back(i);
    m.position.push_back({1.0 * i, -1.0 * i, 5.0});
    m.covariance.push_back({0.5, 0.0, 0.0, 0.5, 0.0, 0.5});
  }
}
inline void fill(cvslam::agent_map_t& m) {
  setHeader(m.header, 12500);
  for (int i = 0; i < 5; ++i) {
    m.id.push_back(100 + i);
    m.position.push_back({1.0f * i, 2.0f, -3.0f});
    m.position_std.push_back(0.1f * (i + 1));
    m.active.push_back(i % 2 == 0);
  }
}
inline void fill(cvslam::status_t& m) {
  setHeader(m.header, 13000);
  m.processed_utime = 12950;
  m.health = cvslam::status_t::HEALTH_DEGRADED;
  m.message = "dropping images";
}

/// A finalized, valid sample of Msg.
template <typename Msg>
Msg sample() {
  Msg m{};
  fill(m);
  EXPECT_TRUE(finalize(m).ok());
  return m;
}

template <typename Msg>
std::vector<uint8_t> encodedSample() {
  Msg m = sample<Msg>();
  Expected<std::vector<uint8_t>> b = encodeMessage(m);
  EXPECT_TRUE(b.ok()) << b.status().message();
  return b.ok() ? *b : std::vector<uint8_t>{};
}

/// Byte offset of the first count field in encodedSample<Msg>() (after the fingerprint,
/// header and any fixed fields), and the count stored there; offset -1 if the type has
/// no variable-length field.
struct CountField {
  int offset;
  int32_t value;
};
inline CountField firstCount(const cvslam::imu_t*) {
  return {-1, 0};
}
inline CountField firstCount(const cvslam::pose_t*) {
  return {-1, 0};
}
inline CountField firstCount(const cvslam::stereo_image_t*) {
  return {41, 240};
}
inline CountField firstCount(const cvslam::stereo_features_t*) {
  return {28, 5};
}
inline CountField firstCount(const cvslam::agent_state_t*) {
  return {36, 9};
}
inline CountField firstCount(const cvslam::agent_summary_t*) {
  return {104, 2};
}
inline CountField firstCount(const cvslam::feature_index_t*) {
  return {29, 6};
}
inline CountField firstCount(const cvslam::shared_request_t*) {
  return {28, 2};
}
inline CountField firstCount(const cvslam::shared_landmarks2_t*) {
  return {36, 2};  // num_informed_by
}
inline CountField firstCount(const cvslam::observation_batch_t*) {
  return {28, 10};
}
inline CountField firstCount(const cvslam::gs_state_t*) {
  return {44, 15};
}
inline CountField firstCount(const cvslam::map_t*) {
  return {36, 6};
}
inline CountField firstCount(const cvslam::agent_map_t*) {
  return {28, 5};
}
inline CountField firstCount(const cvslam::status_t*) {
  return {37, 16};
}  // string length

inline int32_t readInt32(const std::vector<uint8_t>& b, int offset) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | b[static_cast<std::size_t>(offset + i)];
  return static_cast<int32_t>(v);
}
inline void writeInt32(std::vector<uint8_t>& b, int offset, int32_t value) {
  const auto v = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) {
    b[static_cast<std::size_t>(offset + i)] = static_cast<uint8_t>(v >> (24 - 8 * i));
  }
}

/// Makes a valid message semantically invalid in a way only content validation can see:
/// a NaN where the type has floating-point fields, else an out-of-range value.
inline void poison(cvslam::imu_t& m) {
  m.accel[1] = std::nan("");
}
inline void poison(cvslam::stereo_image_t& m) {
  m.stride = 5;
}  // < width
inline void poison(cvslam::stereo_features_t& m) {
  m.v_right[2] = std::nan("");
}
inline void poison(cvslam::pose_t& m) {
  m.quaternion[0] = std::numeric_limits<double>::infinity();
}
inline void poison(cvslam::agent_state_t& m) {
  m.covariance[40] = std::nan("");
}
inline void poison(cvslam::agent_summary_t& m) {
  m.ellipsoid_mean[2] = std::nan("");
}
inline void poison(cvslam::feature_index_t& m) {
  m.header.seq = -1;
}
inline void poison(cvslam::shared_request_t& m) {
  m.header.seq = -5;
}
inline void poison(cvslam::shared_landmarks2_t& m) {
  m.position[1][2] = std::nan("");
}
inline void poison(cvslam::observation_batch_t& m) {
  m.accel[4][0] = std::nanf("");
}
inline void poison(cvslam::gs_state_t& m) {
  m.state[3] = -std::nan("");
}
inline void poison(cvslam::map_t& m) {
  m.covariance[5][5] = std::nan("");
}
inline void poison(cvslam::agent_map_t& m) {
  m.position_std[2] = -1.0f;
}
inline void poison(cvslam::status_t& m) {
  m.health = 17;
}

/// Encodes `m` with the generated encoder only (no finalize/validate), as a faulty or
/// hostile sender would. Count fields must match the vectors (else encode() overreads).
template <typename Msg>
std::vector<uint8_t> rawEncode(const Msg& m) {
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

}  // namespace cvslam::transport::testing
