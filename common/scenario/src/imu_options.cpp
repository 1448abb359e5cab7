#include "cvslam/scenario/imu_options.h"

#include <Eigen/LU>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

Status ImuOptions::load(const ConfigNode& node) {
  node.get("rate_hz", rate_hz);
  node.get("noise", noise);
  node.getEnum("kind", kind,
               {{"gaussian", NoiseKind::kGaussian},
                {"non_gaussian_centred", NoiseKind::kNonGaussianCentred}});
  node.getEnum("shape", shape, nonGaussianShapeNames());
  node.get("gyro_noise_density", gyro_noise_density);
  node.get("accel_noise_density", accel_noise_density);
  node.get("gyro_random_walk", gyro_random_walk);
  node.get("accel_random_walk", accel_random_walk);
  node.get("gyro_bias", gyro_bias);
  node.get("accel_bias", accel_bias);
  node.get("vibration_accel", vibration_accel);
  node.get("vibration_gyro", vibration_gyro);
  node.get("vibration_hz", vibration_hz);
  node.check(vibration_accel >= 0.0, "vibration_accel", "must be >= 0");
  node.check(vibration_gyro >= 0.0, "vibration_gyro", "must be >= 0");
  node.check(vibration_hz >= 0.0, "vibration_hz", "must be >= 0");
  node.get("recording", recording);
  node.get("recording_R_StoB", recording_R_StoB);
  node.get("recording_start", recording_start);
  node.check((recording_R_StoB * recording_R_StoB.transpose()).isIdentity(1e-6) &&
                 recording_R_StoB.determinant() > 0,
             "recording_R_StoB", "must be a rotation matrix");
  node.check(rate_hz > 0.0 && rate_hz <= 1e5, "rate_hz", "must be in (0, 100000]");
  node.check(gyro_noise_density >= 0.0, "gyro_noise_density", "must be >= 0");
  node.check(accel_noise_density >= 0.0, "accel_noise_density", "must be >= 0");
  node.check(gyro_random_walk >= 0.0, "gyro_random_walk", "must be >= 0");
  node.check(accel_random_walk >= 0.0, "accel_random_walk", "must be >= 0");
  return node.status();
}

}  // namespace cvslam::sim
