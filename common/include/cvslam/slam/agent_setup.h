#pragma once
// How one agent's filter is set up from its calibration (DESIGN.md §3, §6), shared by
// cvslam_run (SimulatedTeamRun) and cvslam_agent, so that both start every filter alike:
//  - options: the agent configuration with the IMU's datasheet noise (as from a sensor.yaml);
//  - initial state and covariance: the scenario's initial estimate (simulation), or the first
//    ground-truth pose (thesis §6.3.1: initial poses known in the team's frame) with the
//    configured initial 1σ (real or recorded data).

#include <Eigen/Core>
#include <cstdint>

#include "cvslam/core/status.h"
#include "cvslam/sim/scenario.h"
#include "cvslam/sim/simulator.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

/// Everything VisualInertialSlam::initialize needs plus the options to construct it with.
struct AgentFilterSetup {
  VisualInertialSlamOptions options;
  int64_t t0_us = 0;
  Eigen::VectorXd x0;  ///< 9 or 15 entries (options.ins.estimate_imu_bias)
  Eigen::MatrixXd P0;
};

/// A simulated agent: the IMU's datasheet noise replaces the configured densities when the
/// simulated IMU is noisy; the state starts at the scenario's initial estimate.
AgentFilterSetup simulatedAgentSetup(const sim::AgentSimulator& agent,
                                     const VisualInertialSlamOptions& options);

/// An agent started at a known pose (first ground truth): x0 = [p_BinN, R_NtoB v_N, euler]
/// with zero biases, P0 = diag(sigma²) (bias states from options.slam).
AgentFilterSetup knownPoseSetup(int64_t t_us, const Eigen::Vector3d& p_BinN,
                                const Eigen::Vector3d& v_N, const Eigen::Vector3d& euler,
                                const sim::InitialUncertainty& sigma,
                                const VisualInertialSlamOptions& options);

}  // namespace cvslam
