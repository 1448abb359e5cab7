#pragma once
// One GPS receiver output (thesis §2.4): NED position and velocity of the antenna, taken at
// the vehicle's origin (no lever arm), with the receiver's stated 1σ accuracies. A sensor
// sample type like ImuSample, shared by the simulator (sim/gps_simulator.h) and the GPS-aided
// INS filters (insgps/).

#include <Eigen/Core>
#include <cstdint>

namespace cvslam {

struct GpsFix {
  int64_t t_us = 0;                                   ///< receiver time [µs]
  Eigen::Vector3d p_N = Eigen::Vector3d::Zero();      ///< position, NED [m]
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();      ///< velocity, NED [m/s]
  Eigen::Vector3d sigma_p = Eigen::Vector3d::Ones();  ///< stated position 1σ per axis [m]
  Eigen::Vector3d sigma_v = Eigen::Vector3d::Ones();  ///< stated velocity 1σ per axis [m/s]
};

}  // namespace cvslam
