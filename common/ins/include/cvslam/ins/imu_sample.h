#pragma once
// One IMU measurement (docs/conventions.md): body-frame (FRD) angular rate and specific force.

#include <Eigen/Core>
#include <cstdint>

namespace cvslam {

struct ImuSample {
  int64_t t_us = 0;                                   ///< dataset time [µs]
  Eigen::Vector3d gyro_B = Eigen::Vector3d::Zero();   ///< ω = [p q r] [rad/s], body frame
  Eigen::Vector3d accel_B = Eigen::Vector3d::Zero();  ///< specific force f_b [m/s²], body frame;
                                                      ///< level and at rest: [0 0 −9.81]
};

}  // namespace cvslam
