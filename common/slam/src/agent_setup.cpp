#include "cvslam/slam/agent_setup.h"

#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {
AgentFilterSetup initialEstimateSetup(int64_t t_us, const Eigen::Vector3d& p,
                                      const Eigen::Vector3d& v_B, const Eigen::Vector3d& euler,
                                      const InitialUncertainty& init,
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

AgentFilterSetup knownPoseSetup(int64_t t_us, const Eigen::Vector3d& p_BinN,
                                const Eigen::Vector3d& v_N, const Eigen::Vector3d& euler,
                                const InitialUncertainty& sigma,
                                const VisualInertialSlamOptions& options) {
  const Eigen::Vector3d v_B = rotationBodyToNav<double>(euler).transpose() * v_N;
  return initialEstimateSetup(t_us, p_BinN, v_B, euler, sigma, options);
}

AgentFilterSetup restSetup(const StaticInitialization& rest, const InitialUncertainty& sigma,
                           const VisualInertialSlamOptions& options) {
  InitialUncertainty at_rest = sigma;
  at_rest.attitude_sigma.head<2>().setConstant(rest.tilt_sigma);
  AgentFilterSetup s = initialEstimateSetup(rest.t_us, Eigen::Vector3d::Zero(),
                                            Eigen::Vector3d::Zero(), rest.euler, at_rest, options);
  if (options.ins.attitude == vehicle::Attitude::kErrorState) {
    // The rotation itself (no Euler angles at any mounting), σ about N's axes.
    s.q0_BtoN = rest.q_BtoN;
    const Eigen::Vector3d sigma_N = at_rest.attitude_sigma;
    s.P0.block<3, 3>(vehicle::kAttitude, vehicle::kAttitude) =
        vehicle_model::errorCovarianceFromNav(rest.q_BtoN,
                                              sigma_N.array().square().matrix().asDiagonal());
  }
  setGyroBiasFromRest(rest, &s);
  return s;
}

void setGyroBiasFromRest(const StaticInitialization& rest, AgentFilterSetup* setup) {
  if (!setup->options.ins.estimate_imu_bias) return;
  setup->x0.segment<3>(vehicle::kGyroBias) = rest.gyro_bias;
  const Eigen::Vector3d gyro_sigma =
      rest.gyro_bias_sigma.cwiseMax(setup->options.slam.initial_gyro_bias_sigma);
  setup->P0.diagonal().segment<3>(vehicle::kGyroBias) = gyro_sigma.array().square().matrix();
}

AgentFilterSetup dynamicSetup(const DynamicInitialization& d, const InitialUncertainty& sigma,
                              const VisualInertialSlamOptions& options) {
  InitialUncertainty in_motion = sigma;
  in_motion.attitude_sigma.head<2>().setConstant(d.tilt_sigma);
  in_motion.velocity_sigma.setConstant(d.velocity_sigma);
  const Eigen::Matrix3d R_BtoN = d.q_BtoN.toRotationMatrix();
  AgentFilterSetup s =
      initialEstimateSetup(d.t_us, Eigen::Vector3d::Zero(), R_BtoN.transpose() * d.v_N,
                           eulerFromRotationNavToBody(R_BtoN.transpose()), in_motion, options);
  if (options.ins.attitude == vehicle::Attitude::kErrorState) {
    // The rotation itself (an IMU mounted x-up has no usable Euler angles), σ about N's axes.
    s.q0_BtoN = d.q_BtoN;
    const Eigen::Vector3d sigma_N = in_motion.attitude_sigma;
    s.P0.block<3, 3>(vehicle::kAttitude, vehicle::kAttitude) =
        vehicle_model::errorCovarianceFromNav(d.q_BtoN,
                                              sigma_N.array().square().matrix().asDiagonal());
  }
  if (options.ins.estimate_imu_bias) {
    s.x0.segment<3>(vehicle::kGyroBias) = d.gyro_bias;
    const Eigen::Vector3d sigma_bg =
        d.gyro_bias_sigma.cwiseMax(options.slam.initial_gyro_bias_sigma);
    s.P0.diagonal().segment<3>(vehicle::kGyroBias) = sigma_bg.array().square().matrix();
  }
  return s;
}

}  // namespace cvslam
