#include "cvslam/lcm/cc_convert.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "covariance_triangle.h"
#include "cvslam/lcm/message_finalize.h"

namespace cvslam::transport {
namespace {

/// Bounds of a plausible IMU sample: ten times what the fastest MEMS IMUs measure (±2000°/s ≈
/// 35 rad/s, ±16 g ≈ 160 m/s²); beyond them a sample is corrupt, not a manoeuvre.
constexpr double kMaxGyroRadS = 350.0;
constexpr double kMaxAccelMS2 = 1600.0;

std::vector<float> toFloat(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

Eigen::Vector3d fromFloat(const std::vector<float>& v) {
  return Eigen::Vector3f(v[0], v[1], v[2]).cast<double>();
}

/// The state vector and row-major covariance of agent_state_t / gs_state_t (validated sizes).
template <typename Msg>
VehicleEstimate vehicleEstimate(const Msg& msg) {
  VehicleEstimate e;
  e.t_us = msg.header.utime;
  const int n = msg.state_dim;
  e.x_v = Eigen::Map<const Eigen::VectorXd>(msg.state.data(), n);
  e.P_v = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      msg.covariance.data(), n, n);
  return e;
}

}  // namespace

cvslam::agent_state_t agentStateMessage(int agent_id, const std::string& filter, int64_t t_us,
                                        const Eigen::VectorXd& x_v, const Eigen::MatrixXd& P_v) {
  cvslam::agent_state_t m{};
  m.header.utime = t_us;
  m.header.agent_id = agent_id;
  m.filter = filter;
  setVehicleEstimate(m, x_v, P_v);
  return m;
}

Expected<cvslam::observation_batch_t> toMessage(const coop::CcObservationBatch& batch) {
  cvslam::observation_batch_t m{};
  m.header.utime = batch.t_us;
  m.header.agent_id = batch.agent_id;
  for (const ImuSample& s : batch.imu) {
    const int64_t age = batch.t_us - s.t_us;
    if (age < 0 || age > std::numeric_limits<int32_t>::max())
      return Status::Error("IMU sample at t=" + std::to_string(s.t_us) +
                           " µs is after the frame or more than 35 min before it");
    m.imu_age_us.push_back(static_cast<int32_t>(age));
    m.gyro.push_back(toFloat(s.gyro_B));
    m.accel.push_back(toFloat(s.accel_B));
  }
  for (const StereoObservation& o : batch.frame.observations) {
    m.index.push_back(static_cast<int32_t>(o.index));
    m.type.push_back(static_cast<int8_t>(o.type));
    m.landmark_id.push_back(o.landmark_id);
    m.u_left.push_back(static_cast<float>(o.z[0]));
    m.v_left.push_back(static_cast<float>(o.z[1]));
    m.u_right.push_back(static_cast<float>(o.z[2]));
    m.v_right.push_back(static_cast<float>(o.z[3]));
    m.descriptors.push_back(o.descriptor);
  }
  return finalized(std::move(m));
}

Expected<coop::CcObservationBatch> fromMessage(const cvslam::observation_batch_t& m) {
  coop::CcObservationBatch b;
  b.agent_id = m.header.agent_id;
  b.t_us = m.header.utime;
  b.frame.t_us = m.header.utime;
  // Sizes are trusted here: messages reach this point only through decodeMessage().
  b.imu.resize(m.imu_age_us.size());
  for (std::size_t i = 0; i < m.imu_age_us.size(); ++i) {
    ImuSample& s = b.imu[i];
    s.t_us = m.header.utime - m.imu_age_us[i];
    s.gyro_B = fromFloat(m.gyro[i]);
    s.accel_B = fromFloat(m.accel[i]);
  }
  b.frame.observations.resize(m.index.size());
  for (std::size_t i = 0; i < m.index.size(); ++i) {
    StereoObservation& o = b.frame.observations[i];
    o.index = static_cast<uint32_t>(m.index[i]);
    o.type = static_cast<ObservationType>(m.type[i]);
    o.landmark_id = m.landmark_id[i];
    o.z = Eigen::Vector4f(m.u_left[i], m.v_left[i], m.u_right[i], m.v_right[i]).cast<double>();
    if (i < m.descriptors.size()) o.descriptor = m.descriptors[i];
  }
  if (b.agent_id < 1) return Status::Error("batch from agent id " + std::to_string(b.agent_id));
  for (const ImuSample& s : b.imu) {
    if (s.gyro_B.cwiseAbs().maxCoeff() > kMaxGyroRadS ||
        s.accel_B.cwiseAbs().maxCoeff() > kMaxAccelMS2)
      return Status::Error("IMU sample at t=" + std::to_string(s.t_us) + " µs is absurd");
  }
  if (Status s = coop::validateBatch(b); !s.ok()) return s;
  return b;
}

Expected<cvslam::gs_state_t> toMessage(const VehicleEstimate& e, const std::string& filter,
                                       int64_t map_version) {
  cvslam::gs_state_t m{};
  m.header.utime = e.t_us;
  m.header.agent_id = 0;
  m.filter = filter;
  m.map_version = map_version;
  setVehicleEstimate(m, e.x_v, e.P_v);
  return finalized(std::move(m));
}

VehicleEstimate fromMessage(const cvslam::gs_state_t& m) {
  return vehicleEstimate(m);
}

VehicleEstimate estimateOf(const cvslam::agent_state_t& m) {
  return vehicleEstimate(m);
}

Expected<cvslam::agent_map_t> agentMapMessage(int agent_id, int64_t t_us,
                                              const std::vector<MapLandmark>& map) {
  cvslam::agent_map_t m{};
  m.header.utime = t_us;
  m.header.agent_id = agent_id;
  m.id.reserve(map.size());
  for (const MapLandmark& l : map) {
    m.id.push_back(l.id);
    m.position.push_back({static_cast<float>(l.p_LinN.x()), static_cast<float>(l.p_LinN.y()),
                          static_cast<float>(l.p_LinN.z())});
    m.position_std.push_back(
        static_cast<float>(std::sqrt(std::max(0.0, l.covariance.trace() / 3.0))));
    m.active.push_back(l.in_state);
  }
  return finalized(std::move(m));
}

Expected<cvslam::map_t> toMessage(const std::vector<MapLandmark>& map, int64_t t_us,
                                  int64_t map_version) {
  cvslam::map_t m{};
  m.header.utime = t_us;
  m.header.agent_id = 0;
  m.map_version = map_version;
  m.index.reserve(map.size());
  for (const MapLandmark& l : map) {
    m.index.push_back(static_cast<int32_t>(l.index));
    m.position.push_back({l.p_LinN.x(), l.p_LinN.y(), l.p_LinN.z()});
    m.covariance.push_back(upperTriangle(l.covariance));
  }
  return finalized(std::move(m));
}

}  // namespace cvslam::transport
