#include "cvslam/slam/agent_setup.h"

#include "cvslam/geometry/euler.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {
namespace {

AgentFilterSetup setupAt(int64_t t_us, const Eigen::Vector3d& p, const Eigen::Vector3d& v_B,
                         const Eigen::Vector3d& euler, const sim::InitialUncertainty& init,
                         const VisualInertialSlamOptions& options) {
  AgentFilterSetup s;
  s.options = options;
  s.t0_us = t_us;
  const bool with_bias = options.ins.estimate_imu_bias;
  const int n = vehicle::size(with_bias);
  s.x0 = Eigen::VectorXd::Zero(n);
  s.x0 << p, v_B, euler, Eigen::VectorXd::Zero(n - 9);
  Eigen::VectorXd sigma = Eigen::VectorXd::Zero(n);
  sigma << init.position_sigma, init.velocity_sigma, init.attitude_sigma,
      Eigen::VectorXd::Zero(n - 9);
  if (with_bias) {
    s.x0.segment<3>(vehicle::kAccelBias) = options.slam.initial_accel_bias;
    s.x0.segment<3>(vehicle::kGyroBias) = options.slam.initial_gyro_bias;
    sigma.segment<3>(vehicle::kAccelBias).setConstant(options.slam.initial_accel_bias_sigma);
    sigma.segment<3>(vehicle::kGyroBias).setConstant(options.slam.initial_gyro_bias_sigma);
  }
  s.P0 = sigma.array().square().matrix().asDiagonal();
  return s;
}

}  // namespace

AgentFilterSetup simulatedAgentSetup(const sim::AgentSimulator& agent,
                                     const VisualInertialSlamOptions& options) {
  VisualInertialSlamOptions agent_options = options;
  const sim::ImuOptions& imu = agent.spec().imu;
  if (imu.noise) {
    agent_options.ins.gyro_noise_density = imu.gyro_noise_density;
    agent_options.ins.accel_noise_density = imu.accel_noise_density;
    agent_options.ins.gyro_random_walk = imu.gyro_random_walk;
    agent_options.ins.accel_random_walk = imu.accel_random_walk;
  }
  const sim::InitialEstimate& init = agent.initialEstimate();
  return setupAt(init.state.t_us, init.state.p_BinN, init.state.v_B, init.state.euler, init.sigma,
                 agent_options);
}

AgentFilterSetup knownPoseSetup(int64_t t_us, const Eigen::Vector3d& p_BinN,
                                const Eigen::Vector3d& v_N, const Eigen::Vector3d& euler,
                                const sim::InitialUncertainty& sigma,
                                const VisualInertialSlamOptions& options) {
  const Eigen::Vector3d v_B = rotationBodyToNav<double>(euler).transpose() * v_N;
  return setupAt(t_us, p_BinN, v_B, euler, sigma, options);
}

}  // namespace cvslam
