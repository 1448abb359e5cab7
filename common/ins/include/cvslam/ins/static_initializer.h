#pragma once
// Static initialisation from the IMU's first rest period — a start without ground truth.
//
// At rest the accelerometer measures the reaction to gravity, f_B = −R_BN g_N (+ bias), and
// the gyro its own bias (the earth rate, 7.3e-5 rad/s, lies below a MEMS gyro's turn-on bias
// and is ignored). The mean specific force over the rest window therefore gives roll and
// pitch (the ZYX angles of thesis §2.3.2, g_N = [0 0 g] in NED), the mean rate the gyro
// bias. Yaw and position are not observable from an IMU at rest: they define the
// estimator's own gravity-aligned frame (yaw 0, origin where the vehicle stands), as the
// static initialisers of OpenVINS and Basalt do. The accelerometer bias cannot be told from
// a tilt at rest; it keeps its datasheet prior, which bounds the tilt error:
// σ_tilt ≈ σ_ba / g.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"

namespace cvslam {

class ConfigNode;

/// Options of the static initialisation (cvslam_agent: `agent.static_init` of agent.yaml,
/// used with `agent.start: rest`).
struct StaticInitializerOptions {
  double window_s = 1.0;  ///< rest period averaged, from the first IMU sample [s]
  /// Rest is told from motion by the stability of the mean, not by the spread of the
  /// samples: rotors shake a standing MAV's IMU by more than a slow motion does (EuRoC
  /// V1_01 at rest, rotors on: specific-force std up to 1.1 m/s², rate std 0.08 rad/s).
  /// The window is cut into this many segments; at rest their means agree.
  int segments = 4;
  /// Largest deviation of a segment's mean specific force from the window's [m/s²]
  /// (V1_01: ≤ 0.09 at rest, 0.2–1.2 in motion).
  double max_accel_mean_change = 0.2;
  /// The same for the angular rate [rad/s] (V1_01: ≤ 0.013 at rest, ≥ 0.088 in motion).
  double max_gyro_mean_change = 0.03;
  /// |mean specific force| may differ from gravity by at most this [m/s²]: more means the
  /// vehicle accelerates, or the IMU's units or scale are wrong.
  double max_gravity_error = 0.5;
  Status load(const ConfigNode& node);
};

/// The vehicle state found at rest, in the estimator's gravity-aligned NED frame.
struct StaticInitialization {
  int64_t t_us = 0;                                 ///< last sample of the window
  Eigen::Vector3d euler = Eigen::Vector3d::Zero();  ///< φ θ ψ [rad], ψ = 0
  /// R_BtoN at rest for any IMU mounting (the error-state attitude, docs/filter.md): gravity
  /// along N's z, and N's x the horizontal projection of body x (so that this is the
  /// rotation of `euler`), or, when body x is within ~26° of the vertical (the EuRoC
  /// VI-sensor's x-up IMU, whose Euler angles are singular), of the body axis farthest
  /// from the vertical.
  Eigen::Quaterniond q_BtoN = Eigen::Quaterniond::Identity();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();  ///< mean rate at rest [rad/s]
  /// 1σ of the gyro-bias estimate: the rate noise averaged over the window [rad/s].
  Eigen::Vector3d gyro_bias_sigma = Eigen::Vector3d::Zero();
  double tilt_sigma = 0.0;  ///< 1σ of roll and pitch [rad] (accel-bias prior)
  Eigen::Vector3d accel_std = Eigen::Vector3d::Zero();  ///< per-axis std in the window [m/s²]
  Eigen::Vector3d gyro_std = Eigen::Vector3d::Zero();   ///< [rad/s]
  int samples = 0;                                      ///< IMU samples averaged
};

/// Finds the rest state from the IMU samples (sorted by time) of the first window_s seconds.
/// `accel_bias_sigma` is the accelerometer turn-on bias prior (1σ, m/s²; the filter's
/// slam.initial_accel_bias_sigma), which sets tilt_sigma. Fails with one line saying why:
/// no samples, a window shorter than window_s, a vehicle moving (segment means apart) or a
/// specific force far from `gravity`.
Expected<StaticInitialization> initializeAtRest(const std::vector<ImuSample>& samples,
                                                const StaticInitializerOptions& options,
                                                double gravity, double accel_bias_sigma);

}  // namespace cvslam
