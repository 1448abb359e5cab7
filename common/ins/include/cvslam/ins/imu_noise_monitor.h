#pragma once
// The white-noise density of an IMU measured in flight from its own samples.
//
// A datasheet gives the noise of an IMU at rest. On a multirotor the rotors shake it: the real
// EuRoC IMUs (ADIS16448 on a hexacopter) are 22–26× noisier in flight than their datasheet
// (docs/results/euroc_recorded.md "In-flight noise"), and a filter that believes the datasheet
// is over-confident in velocity and tilt. This monitor measures the noise the filter should
// assume without knowing the motion, from a third difference of block means (a Hadamard-type
// variance; IEEE Std 952 uses these for drift-free noise identification): means m_k of the
// samples over blocks of τ, d = m_{k+3} − 3 m_{k+2} + 3 m_{k+1} − m_k, which cancels any motion
// that is quadratic over 4τ (a second difference leaves a manoeuvre's changing curvature, 2×
// the gyro's noise on a 1 rad/s swing at 0.5 Hz), and for white noise of density σ,
// var(d) = 20 σ²/τ, so σ² = var(d) τ / 20, with var(d) taken robustly from the median of d²:
// the spline trajectories of the simulated recordings have kinks in their acceleration at every
// knot, which a variance read as 2–4× the noise and the median does not. Averaging over τ
// also damps vibration above 1/τ, which integrates to nothing between two frames; how much
// depends on where the line aliases (the simulated recordings' 117 Hz line, read per sample as
// 19× the accelerometer's noise, is gone over 25 ms blocks and leaks at 10× over 20 ms).
// One density per sensor (gyro, accelerometer): the mean of the three axes' variances, as the
// INS model's noise is isotropic. Over a sliding window, so it follows take-off and landing.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"

namespace cvslam {

class ConfigNode;

struct ImuNoiseMonitorOptions {
  /// Measure in flight and let the INS assume the larger of this and its configured density
  /// (`ins.measure_noise_density`). Off where the densities are the truth (a simulated IMU).
  bool enabled = true;
  double tau_s = 0.025;   ///< τ, block length [s]: half a 20 Hz frame interval
  double window_s = 4.0;  ///< sliding window of the estimate [s]
  int min_terms = 20;     ///< differences needed before the estimate is used

  Status load(const ConfigNode& node);
};

class ImuNoiseMonitor {
 public:
  explicit ImuNoiseMonitor(const ImuNoiseMonitorOptions& options = {}) : o_(options) {}

  /// Adds the next sample (samples not later than the previous one are ignored, and every
  /// sample when the options disable the measurement: it is then never ready).
  void add(const ImuSample& sample);
  /// Enough differences in the window for an estimate.
  bool ready() const { return static_cast<int>(terms_.size()) >= o_.min_terms; }
  /// Measured white-noise densities over the window, [rad/s/√Hz] and [m/s²/√Hz] (0 when not
  /// ready).
  double gyroDensity() const { return density(0); }
  double accelDensity() const { return density(3); }

 private:
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  struct Term {
    int64_t t_us = 0;
    Vector6d d = Vector6d::Zero();  ///< third difference of block means, gyro then accel
    double tau_s = 0.0;             ///< mean block length of the four blocks
  };
  struct Block {
    Vector6d mean = Vector6d::Zero();
    double length_s = 0.0;
  };
  double density(int first_row) const;

  ImuNoiseMonitorOptions o_;
  // The block being filled.
  Vector6d sum_ = Vector6d::Zero();
  int count_ = 0;
  int64_t block_start_us_ = 0;
  int64_t last_us_ = 0;
  bool started_ = false;
  // The last four closed blocks, oldest first.
  std::deque<Block> blocks_;
  std::deque<Term> terms_;
  mutable std::vector<double> scratch_;  // the median's workspace
};

}  // namespace cvslam
