#pragma once
// How one agent's filter is set up from its calibration (docs/conventions.md, docs/run_format.md),
// shared by cvslam_run (SimulatedTeamRun) and cvslam_agent, so that both start every filter alike:
//  - options: the agent configuration with the IMU's datasheet noise (as from a sensor.yaml);
//  - initial state and covariance: the scenario's initial estimate (simulation), the first
//    ground-truth pose (thesis §6.3.1: initial poses known in the team's frame) with the
//    configured initial 1σ (real or recorded data), or the rest state found by the static
//    initialiser (ins/static_initializer.h: no ground truth needed).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "cvslam/core/status.h"
#include "cvslam/ins/initial_uncertainty.h"
#include "cvslam/ins/static_initializer.h"
#include "cvslam/slam/dynamic_initializer.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

/// Everything VisualInertialSlam::initialize needs plus the options to construct it with.
struct AgentFilterSetup {
  VisualInertialSlamOptions options;
  int64_t t0_us = 0;
  Eigen::VectorXd x0;  ///< 9 or 15 entries (options.ins.estimate_imu_bias), Euler layout
  Eigen::MatrixXd P0;
  /// Set (error-state attitude only): the initial rotation R_BtoN; x0's attitude entries are
  /// then ignored and P0's attitude block is in the error coordinates δθ (any attitude,
  /// e.g. an IMU mounted x-up, where Euler angles are singular).
  std::optional<Eigen::Quaterniond> q0_BtoN;
};

/// An agent started at the estimate x0 = [p_BinN, v_B, euler] with P0 = diag(sigma²); the
/// IMU bias states (options.ins.estimate_imu_bias) start at options.slam's priors.
AgentFilterSetup initialEstimateSetup(int64_t t_us, const Eigen::Vector3d& p_BinN,
                                      const Eigen::Vector3d& v_B, const Eigen::Vector3d& euler,
                                      const InitialUncertainty& sigma,
                                      const VisualInertialSlamOptions& options);

/// An agent started at a known pose (first ground truth): x0 = [p_BinN, R_NtoB v_N, euler]
/// with zero biases, P0 = diag(sigma²) (bias states from options.slam).
AgentFilterSetup knownPoseSetup(int64_t t_us, const Eigen::Vector3d& p_BinN,
                                const Eigen::Vector3d& v_N, const Eigen::Vector3d& euler,
                                const InitialUncertainty& sigma,
                                const VisualInertialSlamOptions& options);

/// An agent started at rest (`agent.start: rest`) in its own gravity-aligned frame: position
/// zero and yaw zero (the frame's definition, held to sigma's position and yaw 1σ), velocity
/// zero (sigma's velocity 1σ), roll and pitch from gravity (1σ: rest.tilt_sigma), the gyro
/// bias measured at rest (1σ: its averaging error, at least slam.initial_gyro_bias_sigma),
/// the accelerometer bias at slam's prior. The tilt and accelerometer-bias errors are in truth
/// correlated (a horizontal bias looks like a tilt at rest); leaving that out is conservative.
AgentFilterSetup restSetup(const StaticInitialization& rest, const InitialUncertainty& sigma,
                           const VisualInertialSlamOptions& options);

/// The gyro bias measured at rest replaces `setup`'s prior (no-op without bias states): mean
/// rate at rest, 1σ its averaging error but at least slam.initial_gyro_bias_sigma. A known-pose
/// start whose IMU was recording at rest before the flight uses it as restSetup does.
void setGyroBiasFromRest(const StaticInitialization& rest, AgentFilterSetup* setup);

/// An agent started in motion (dynamic_initializer.h) in its own gravity-aligned frame:
/// position zero and yaw zero (held to sigma's position and yaw 1σ), the velocity and tilt
/// found (1σ: d.velocity_sigma, d.tilt_sigma), the gyro bias found (1σ: its fit's, at least
/// slam.initial_gyro_bias_sigma), the accelerometer bias at slam's prior.
AgentFilterSetup dynamicSetup(const DynamicInitialization& d, const InitialUncertainty& sigma,
                              const VisualInertialSlamOptions& options);

}  // namespace cvslam
