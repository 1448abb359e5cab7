#pragma once
// One simulated flight for GPS-aided INS (thesis §3.7.2): a trajectory, the IMU and GPS
// measurements taken along it, and the true vehicle state at every IMU sample in the filters'
// Euler layout [p_N | v_B | φ θ ψ] (ins/vehicle_state_layout.h). Used by cvslam_ins_gps and
// the insgps tests; config sections `trajectory` (trajectory_spec.h), `imu`
// (imu_simulator.h), `gps` (gps_simulator.h), plus `duration_s` and `seed`.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/ins/gps_fix.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/scenario/trajectory_spec.h"
#include "cvslam/sim/gps_simulator.h"
#include "cvslam/sim/imu_simulator.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

struct GpsFlightOptions {
  TrajectorySpec trajectory;
  ImuOptions imu;
  GpsOptions gps;
  double duration_s = 60.0;  ///< simulated time [s]
  uint64_t seed = 1;         ///< IMU and GPS streams derive from it (core/random.h)

  /// Reads trajectory, imu, gps, duration_s and seed of `node` (other keys are the caller's).
  Status load(const ConfigNode& node, const std::string& base_dir = "");
};

struct GpsFlight {
  std::vector<ImuSample> imu;
  std::vector<GpsFix> gps;
  std::vector<Eigen::Matrix<double, 9, 1>> truth;  ///< at each IMU sample
};

/// Simulates the flight (IMU at imu.rate_hz from t = 0 to duration_s, GPS fixes on the same
/// clock; a fix whose time is not an IMU sample time is moved to the next IMU sample).
Expected<GpsFlight> simulateGpsFlight(const GpsFlightOptions& options);

}  // namespace cvslam::sim
