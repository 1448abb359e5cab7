#pragma once
// A recorded IMU stream (EuRoC imu0/data.csv: t [ns], ω_S [rad/s], a_S [m/s²]) used instead
// of synthesised IMU data, so that a simulated flight along a recorded trajectory (e.g. the
// EuRoC MH ground truth) carries the real sensor's noise, biases and vibration.
//
// Samples are rotated into the simulated body: ω_B = R_StoB ω_S, f_B = R_StoB f_S (for a
// TUM trajectory use its R_TtoB, since the EuRoC ground-truth body is the IMU). Values
// between recorded samples are interpolated linearly. Timestamps are read as doubles
// (≤ 0.2 µs rounding at EuRoC's 1.4·10¹⁸ ns), far below the 5 ms sample spacing.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"

namespace cvslam::sim {

class ImuRecording {
 public:
  /// Reads the file; errors name the file and line. Needs ≥ 2 rows, increasing times.
  static Expected<std::shared_ptr<const ImuRecording>> load(const std::string& path,
                                                            const Eigen::Matrix3d& R_StoB);
  double startTime() const { return t_.front(); }  ///< [s], file clock
  double endTime() const { return t_.back(); }     ///< [s], file clock
  const std::string& source() const { return source_; }
  /// The body-frame sample at file time t_s (clamped to the recording), stamped t_us.
  ImuSample sampleAt(double t_s, int64_t t_us) const;
  /// The recorded body-frame samples before file time `zero_s`, stamped with their (negative)
  /// time since it.
  std::vector<ImuSample> samplesBefore(double zero_s) const;

 private:
  ImuRecording() = default;
  std::string source_;
  std::vector<double> t_;  // [s]
  std::vector<Eigen::Vector3d> gyro_B_, accel_B_;
};

}  // namespace cvslam::sim
