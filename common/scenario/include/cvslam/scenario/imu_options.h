#pragma once
// A scenario's IMU (section `imu:` of an agent): rate, white-noise densities and kind, bias
// random walks and turn-on biases, rotor vibration, or a EuRoC recording to play instead
// (sim/imu_simulator.h synthesises from these; thesis §2.2, §5.9). Defaults: EuRoC's
// ADIS16448 (data/euroc_micro/mav0/imu0/sensor.yaml).

#include <Eigen/Core>
#include <limits>
#include <string>

#include "cvslam/core/status.h"
#include "cvslam/scenario/noise_model.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

struct ImuOptions {
  double rate_hz = 200.0;                 ///< sample rate [Hz]
  bool noise = true;                      ///< false: perfect IMU (no white noise, no bias at all)
  NoiseKind kind = NoiseKind::kGaussian;  ///< white-noise kind: gaussian | non_gaussian_centred
  NonGaussianShape shape = NonGaussianShape::kUniform;   ///< for non_gaussian_centred
  double gyro_noise_density = 1.6968e-4;                 ///< [rad/s/√Hz]
  double accel_noise_density = 2.0e-3;                   ///< [m/s²/√Hz]
  double gyro_random_walk = 1.9393e-5;                   ///< bias random walk [rad/s²/√Hz]
  double accel_random_walk = 3.0e-3;                     ///< bias random walk [m/s³/√Hz]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< initial gyro bias [rad/s]
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  ///< initial accel bias [m/s²]
  /// Rotor vibration (beyond white noise): on each axis a sinusoid of this amplitude at
  /// vibration_hz with a random phase, sampled at rate_hz (so aliased as a real IMU's is).
  double vibration_accel = 0.0;  ///< amplitude [m/s²]
  double vibration_gyro = 0.0;   ///< amplitude [rad/s]
  double vibration_hz = 0.0;     ///< rotor frequency [Hz]
  /// EuRoC imu0/data.csv to play instead of synthesising (imu_recording.h); "" = synthesise.
  /// Relative to the scenario file. Noise and bias settings are then ignored.
  std::string recording;
  Eigen::Matrix3d recording_R_StoB = Eigen::Matrix3d::Identity();  ///< recorded → body
  /// File time [s] of simulation time 0; NaN: the TUM trajectory's start, else the file's.
  double recording_start = std::numeric_limits<double>::quiet_NaN();

  Status load(const ConfigNode& node);
};

}  // namespace cvslam::sim
