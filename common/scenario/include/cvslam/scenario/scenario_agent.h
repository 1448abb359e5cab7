#pragma once
// One agent of a scenario as an estimator starts it, without simulating any sensor: its
// trajectory, its stereo camera, the initial estimate (the truth, or a draw around it, thesis
// §6.3.1) and, when its IMU plays a recording, that recording and what it measured before the
// flight. The simulator (sim/simulator.h) builds its agents from these, and a scenario-driven
// agent process or ground station starts its filter from them without linking the simulator.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/scenario/imu_recording.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario/trajectory.h"

namespace cvslam::sim {

/// True vehicle state in the filter's terms (thesis §2.3: [X Y Z U V W φ θ ψ]).
struct GroundTruth {
  int64_t t_us = 0;
  Eigen::Vector3d p_BinN = Eigen::Vector3d::Zero();      ///< [m] NED
  Eigen::Vector3d v_B = Eigen::Vector3d::Zero();         ///< body velocity [m/s]
  Eigen::Vector3d euler = Eigen::Vector3d::Zero();       ///< [φ θ ψ] [rad]
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();         ///< [m/s] NED
  Eigen::Vector3d omega_B = Eigen::Vector3d::Zero();     ///< body rates [rad/s]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< IMU gyro bias now [rad/s]
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< IMU accel bias now [m/s²]
  /// false when the IMU plays a recording: its biases are unknown (the two above read zero).
  bool biases_known = true;

  /// The filter's Euler layout [p_BinN, v_B, φ θ ψ] (ins/vehicle_state_layout.h).
  Eigen::Matrix<double, 9, 1> eulerLayout() const {
    Eigen::Matrix<double, 9, 1> x;
    x << p_BinN, v_B, euler;
    return x;
  }
};

/// Initial state for an estimator: the truth, or a sample around it (InitialUncertainty).
struct InitialEstimate {
  GroundTruth state;         ///< p_BinN, v_B, euler filled in (biases: the initial truth)
  InitialUncertainty sigma;  ///< the 1σ to initialise the covariance with
  /// sigma.perturb and sigma.perturb_biases: standard normal draws for the accelerometer (head)
  /// and gyro (tail) bias errors, which the filter set-up scales by its stated bias σ; else 0.
  Eigen::Matrix<double, 6, 1> bias_draw = Eigen::Matrix<double, 6, 1>::Zero();
};

class ScenarioAgent {
 public:
  /// The agent `spec` of `scenario` (one of scenario.agents): builds its trajectory, draws its
  /// initial estimate from its own RNG stream, and loads its IMU recording if it plays one
  /// (error when the recording does not cover the run).
  static Expected<ScenarioAgent> create(const Scenario& scenario, const AgentSpec& spec);

  const AgentSpec& spec() const { return spec_; }
  std::shared_ptr<const Trajectory> trajectory() const { return trajectory_; }
  const StereoCamera& camera() const { return camera_; }
  const InitialEstimate& initialEstimate() const { return initial_; }

  /// The IMU recording played instead of a synthesised IMU (ImuOptions::recording), or null.
  std::shared_ptr<const ImuRecording> imuRecording() const { return recording_; }
  /// File time [s] of the recording at simulation time 0 (before the trajectory's time offset).
  double imuRecordingTimeAtZero() const { return recording_time_at_zero_; }
  /// With a recording: its samples from before simulation time 0 (negative times), what the
  /// IMU measured while the vehicle waited for the flight; empty otherwise.
  std::vector<ImuSample> imuBeforeStart() const;

  /// The true motion at dataset time t_us (trajectory time t_us·1e−6 + the time offset); the
  /// biases are left for the caller (the simulator's IMU knows them as they walk).
  GroundTruth motionAt(int64_t t_us) const;

  /// The agent's own frame in the scenario's world, [t_N t_E t_D ψ] with p_world = R_z(ψ) p_own
  /// + t (merge/frame_relation.h's convention). With `start: unknown` the frame of its true
  /// start pose (origin at its position, x along its heading, gravity-aligned); with a known
  /// start the world itself (zero). The initial estimate and everything an estimator is
  /// compared with (toOwnFrame) are in this frame.
  const Eigen::Vector4d& ownFrameInWorld() const { return own_in_world_; }
  Eigen::Vector3d toOwnFrame(const Eigen::Vector3d& p_world) const;
  /// The truth in the own frame (position, yaw, NED velocity; the body quantities unchanged).
  GroundTruth toOwnFrame(const GroundTruth& world) const;

  /// The IMU's turn-on biases: the configured ones for a noisy synthesised IMU, else zero.
  Eigen::Vector3d turnOnGyroBias() const;
  Eigen::Vector3d turnOnAccelBias() const;

 private:
  ScenarioAgent() = default;
  AgentSpec spec_;
  std::shared_ptr<const Trajectory> trajectory_;
  StereoCamera camera_;
  InitialEstimate initial_;
  std::shared_ptr<const ImuRecording> recording_;
  double recording_time_at_zero_ = 0.0;
  Eigen::Vector4d own_in_world_ = Eigen::Vector4d::Zero();
};

}  // namespace cvslam::sim
