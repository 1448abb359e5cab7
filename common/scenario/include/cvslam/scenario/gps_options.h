#pragma once
// A scenario's GPS receiver (section `gps:` of an agent; sim/gps_simulator.h draws its fixes;
// thesis §2.4, §3.7): rate, white-noise σ and kind, position bias walk, outage windows.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

enum class GpsNoiseKind : uint8_t { kGaussian, kStudentT, kMixture };

/// A time window [start_s, end_s) without fixes (tunnel, jamming, antenna masked).
struct GpsOutage {
  double start_s = 0.0;
  double end_s = 0.0;
};

struct GpsOptions {
  double rate_hz = 5.0;                         ///< fix rate [Hz]
  double start_s = 0.0;                         ///< time of the first fix [s]
  double sigma_horizontal = 1.5;                ///< position white noise, N and E [m]
  double sigma_vertical = 3.0;                  ///< position white noise, D [m]
  double sigma_velocity = 0.1;                  ///< velocity white noise per axis [m/s]
  GpsNoiseKind kind = GpsNoiseKind::kGaussian;  ///< gaussian | student_t | mixture
  int student_dof = 4;                          ///< ν of student_t (> 2 for a finite variance)
  double bias_random_walk = 0.0;                ///< position bias random walk [m/√s] (0: no bias)
  Eigen::Vector3d bias_initial = Eigen::Vector3d::Zero();  ///< position bias at t = 0 [m]
  std::vector<GpsOutage> outages;                          ///< windows without fixes

  Status load(const ConfigNode& node);
  /// True when t [s] is inside an outage window.
  bool inOutage(double t_s) const;
};

/// Config names: {"gaussian", "student_t", "mixture"}.
const std::vector<std::pair<std::string, GpsNoiseKind>>& gpsNoiseKindNames();

}  // namespace cvslam::sim
