#pragma once
// GPS receiver simulation (thesis §2.4, §3.7: GPS at a few Hz aiding the INS).
//
//   p_meas = p_N + b_p + n_p,   v_meas = v_N + n_v
// at `rate_hz` on the simulation clock (fix k at t = t_start + k / rate_hz), none inside an
// outage window. White errors n are per axis, of standard deviation σ (horizontal axes N, E:
// sigma_horizontal; D: sigma_vertical; velocity: sigma_velocity), of one kind:
//   gaussian   σ N(0, 1)
//   student_t  heavy-tailed, ν degrees of freedom, scaled to standard deviation σ (ν > 2):
//              σ √((ν − 2)/ν) · N(0, 1) / √(χ²_ν / ν)
//   mixture    contaminated Gaussian of noise_model.h (0.9 N(0, σ1²) + 0.1 N(0, (4σ1)²)),
//              standard deviation σ
// b_p is a position bias (multipath / ionosphere drift): a random walk of density
// bias_random_walk [m/√s] from bias_initial, so the errors are not white when it is on.
// Each fix states σ_p and σ_v (the white part only: the receiver does not know its bias).

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/core/random.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/gps_fix.h"
#include "cvslam/sim/trajectory.h"

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

class GpsSimulator {
 public:
  GpsSimulator(std::shared_ptr<const Trajectory> trajectory, const GpsOptions& options,
               uint64_t seed);

  /// Every fix with time in [0, end_s] (outages removed), in time order.
  std::vector<GpsFix> fixes(double end_s);

  /// The fix at simulation time t_us; calls in increasing time (the bias walks).
  GpsFix fixAt(int64_t t_us);

  const Eigen::Vector3d& positionBias() const { return bias_; }
  const GpsOptions& options() const { return o_; }

 private:
  double whiteNoise(double sigma);

  std::shared_ptr<const Trajectory> trajectory_;
  GpsOptions o_;
  Rng rng_;
  Eigen::Vector3d bias_;
  int64_t last_t_us_ = 0;
  bool started_ = false;
};

}  // namespace cvslam::sim
