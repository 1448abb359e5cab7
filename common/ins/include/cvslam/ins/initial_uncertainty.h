#pragma once
// The 1σ uncertainty of a vehicle's initial state as handed to an estimator: thesis §6.3.1
// assumes every UAV's initial pose known in the team's frame up to this uncertainty. Shared
// by the simulator (which may sample the initial estimate from it) and the filter set-up
// (which initialises the covariance with it), so it lives with the vehicle state.

#include <Eigen/Core>
#include <cmath>

#include "cvslam/core/status.h"

namespace cvslam {

class ConfigNode;

/// 1σ uncertainty of the initial vehicle state given to the estimator (thesis §6.3.1 assumes
/// the initial poses known in the shared frame, up to this uncertainty).
struct InitialUncertainty {
  Eigen::Vector3d position_sigma = Eigen::Vector3d::Constant(0.1);           ///< [m], NED
  Eigen::Vector3d velocity_sigma = Eigen::Vector3d::Constant(0.1);           ///< [m/s], body
  Eigen::Vector3d attitude_sigma = Eigen::Vector3d::Constant(M_PI / 180.0);  ///< [rad] φ θ ψ
  bool perturb = true;  ///< true: the initial estimate handed out is sampled from this
  /// With `perturb` and bias states: the initial bias estimates are sampled too, from the
  /// filter's stated bias σ (slam.initial_accel_bias_sigma / initial_gyro_bias_sigma) around
  /// the IMU's true turn-on biases, so that the whole initial error matches the stated P0.
  /// false: the filter starts at slam.initial_*_bias, i.e. it knows a simulated IMU's biases
  /// exactly while claiming their σ (docs/filter.md "Under-confident tilt").
  bool perturb_biases = true;

  Status load(const ConfigNode& node);  ///< reads attitude_sigma_deg in degrees
};

}  // namespace cvslam
