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
#include "cvslam/scenario/gps_options.h"
#include "cvslam/scenario/trajectory.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

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
