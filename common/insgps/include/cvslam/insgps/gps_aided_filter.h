#pragma once
// The one interface of the GPS-aided INS filters of thesis chapter 3 (KF §3.3, EKF §3.4,
// UKF and SDRE §3.5, NH∞ §3.6.5), so that a run feeds them the same IMU and GPS data.
//
// State: the thesis's vehicle state in the Euler layout of ins/vehicle_state_layout.h,
// x = [p_N | v_B | φ θ ψ] (9 entries, NED position, body velocity, ZYX Euler angles), propagated
// by the shared strap-down mechanisation of ins/ins_propagator.h (attitude: euler, no bias
// states). Observation (thesis eq. 2.10 extended with the receiver's velocity, §2.4):
//   y = h(x) + v = [p_N ; R_BtoN(φ θ ψ) v_B] + v.

#include <Eigen/Core>
#include <string>

#include "cvslam/core/status.h"
#include "cvslam/ins/gps_fix.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam::insgps {

constexpr int kStateSize = vehicle::kSizeNoBias;  ///< 9
constexpr int kNoiseSize = kStateSize - 3;        ///< accelerometer + gyro white noise
constexpr int kMeasSize = 6;                      ///< GPS position + velocity

using StateVector = Eigen::Matrix<double, kStateSize, 1>;
using StateMatrix = Eigen::Matrix<double, kStateSize, kStateSize>;
using MeasVector = Eigen::Matrix<double, kMeasSize, 1>;
using MeasMatrix = Eigen::Matrix<double, kMeasSize, kMeasSize>;
using MeasJacobian = Eigen::Matrix<double, kMeasSize, kStateSize>;

/// a − b with the Euler-angle entries wrapped to (−π, π] (estimation errors, UKF residuals).
StateVector stateDifference(const StateVector& a, const StateVector& b);
/// x with its yaw wrapped to (−π, π].
StateVector wrapYaw(StateVector x);

class GpsAidedFilter {
 public:
  virtual ~GpsAidedFilter() = default;
  /// Short name for tables and file names ("kf", "ekf", "ukf", "sdre", "nhinf").
  virtual std::string name() const = 0;
  /// Starts at t_us with the estimate x0 and its covariance P0.
  virtual void initialize(const StateVector& x0, const StateMatrix& P0, int64_t t_us) = 0;
  /// Prediction over one IMU interval [s0.t_us, s1.t_us] (s0 at the current time).
  virtual Status propagate(const ImuSample& s0, const ImuSample& s1) = 0;
  /// Correction by a fix taken at the current time.
  virtual Status update(const GpsFix& fix) = 0;
  virtual StateVector state() const = 0;
  virtual StateMatrix covariance() const = 0;
};

}  // namespace cvslam::insgps
