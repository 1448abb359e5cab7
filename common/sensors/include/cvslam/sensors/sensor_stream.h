#pragma once
// A time-ordered stream of sensor data for a team of agents, whatever produces it: EuRoC
// folders played back (EurocSensorSource) or a scenario simulated live, with or without
// rendered images (SimulatedSensorSource). cvslam_replay publishes it over LCM and
// cvslam_simulate writes it to disk; both stay thin because the merging lives here
// (docs/architecture.md: no LCM in common/).
//
// Ordering: events come by increasing play time; at equal play time IMU comes before ground
// truth, ground truth before the frame (propagate, then update); ties of the same type go to
// the lower agent id. Per-agent streams (AgentSensorStream) are merged by MergedSensorSource.
// Play time is the shared clock of the team: for each agent its dataset time minus the
// agent's time offset (EuRoC: its first timestamp, so recordings made at different times
// play together; simulation: 0). Events carry the agent's own dataset time in t_us.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/sensor_event_type.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"

namespace cvslam {

/// True pose and velocity of the body in the stream's world frame (NED for our simulated
/// datasets; whatever the recording uses for real EuRoC folders).
struct VehiclePose {
  Eigen::Vector3d p_BinN = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Quaterniond q_BtoN = Eigen::Quaterniond::Identity();
  Eigen::Vector3d euler = Eigen::Vector3d::Zero();       ///< ZYX [φ θ ψ] of R_BtoN [rad]
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();         ///< [m/s]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< [rad/s]
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< [m/s²]
};

struct SensorEvent {
  SensorEventType type = SensorEventType::kImu;
  int agent_id = 0;
  int64_t t_us = 0;     ///< the agent's dataset time [µs] (goes into header.utime)
  int64_t play_us = 0;  ///< shared play clock [µs] (t_us − the agent's offset)
  ImuSample imu;
  VehiclePose truth;
  cv::Mat left, right;
  StereoFrameObservations features;
};

/// The events of one agent, in the order above.
class AgentSensorStream {
 public:
  virtual ~AgentSensorStream() = default;
  virtual int agentId() const = 0;
  /// Fills the next event; false when the stream is over. An error (e.g. an image that
  /// does not decode) ends the stream: check status() after false.
  virtual bool next(SensorEvent& event) = 0;
  /// Ok unless the stream stopped on an error.
  virtual const Status& status() const = 0;
  /// Play time of the agent's last event [µs] (for progress).
  virtual int64_t endPlayUs() const = 0;
};

/// Sort key of an event within a merged stream (see the ordering rule above).
inline bool eventBefore(int64_t play_a, SensorEventType type_a, int agent_a, int64_t play_b,
                        SensorEventType type_b, int agent_b) {
  if (play_a != play_b) return play_a < play_b;
  if (type_a != type_b) return type_a < type_b;
  return agent_a < agent_b;
}

}  // namespace cvslam
