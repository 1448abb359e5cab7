#pragma once
// True vehicle motion for the simulator: pose and derivatives at any time (docs/conventions.md).
//
// Frames: N is NED, B is FRD (= IMU frame). Everything the IMU synthesis needs is here:
//   specific force  f_B = R_NtoB (a_N − g_N),  g_N = [0 0 9.81]   (level at rest: [0 0 −9.81])
//   body rates      ω_B, related to the Euler rates by thesis eq. 2.4
//   body velocity   v_B = R_NtoB v_N, with v̇_B = f_B + R_NtoB g_N − ω_B × v_B.

#include <Eigen/Core>

namespace cvslam::sim {

/// Gravity in NED [m/s²] (docs/conventions.md).
inline Eigen::Vector3d gravityNed() {
  return {0.0, 0.0, 9.81};
}

/// The true state of a vehicle at one instant.
struct TrajectoryState {
  double t = 0.0;                                         ///< trajectory time [s]
  Eigen::Vector3d p_BinN = Eigen::Vector3d::Zero();       ///< position [m], NED
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();          ///< velocity [m/s], NED
  Eigen::Vector3d a_N = Eigen::Vector3d::Zero();          ///< acceleration [m/s²], NED
  Eigen::Vector3d euler = Eigen::Vector3d::Zero();        ///< [φ θ ψ] ZYX [rad]
  Eigen::Vector3d euler_rates = Eigen::Vector3d::Zero();  ///< [φ̇ θ̇ ψ̇] [rad/s]
  Eigen::Matrix3d R_NtoB = Eigen::Matrix3d::Identity();   ///< C_bn (thesis eq. 2.8, corrected)
  Eigen::Vector3d omega_B = Eigen::Vector3d::Zero();      ///< body rates [p q r] [rad/s]

  /// Body-frame velocity [U V W] (the filter's velocity state, thesis §2.3).
  Eigen::Vector3d v_B() const { return R_NtoB * v_N; }
  /// Specific force the accelerometer measures, f_B = R_NtoB (a_N − g_N).
  Eigen::Vector3d specificForce_B() const { return R_NtoB * (a_N - gravityNed()); }
};

/// Ground-truth motion of one vehicle. Implementations are immutable and thread-compatible.
class Trajectory {
 public:
  virtual ~Trajectory() = default;
  /// The state at trajectory time t [s]. Defined for every t (periodic paths wrap, open paths
  /// extend their end pieces), but meaningful on [0, duration()].
  virtual TrajectoryState state(double t) const = 0;
  /// Length of the described motion [s]; +infinity for periodic paths.
  virtual double duration() const = 0;
};

/// Body rates from Euler angles and their rates (inverse of thesis eq. 2.4).
Eigen::Vector3d bodyRatesFromEulerRates(const Eigen::Vector3d& euler,
                                        const Eigen::Vector3d& euler_rates);

}  // namespace cvslam::sim
