#pragma once
// IMU synthesis from a true trajectory (docs/conventions.md; thesis §2.2 sensor errors, §5.9).
//
//   ω_meas = ω_B + b_g + n_g,   f_meas = R_NtoB (a_N − g_N) + b_a + n_a
// White noise n has the continuous-time density σ_c (per √Hz): per sample σ = σ_c √rate.
// Biases random-walk between samples: b(t + Δt) = b(t) + σ_rw √Δt N(0, I), from the
// configured initial biases (the thesis's "constant offset", §2.2). White noise may be
// centred non-Gaussian (thesis §5.9), see noise_model.h. Defaults: EuRoC's ADIS16448
// (data/euroc_micro/mav0/imu0/sensor.yaml).

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/core/random.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/scenario/imu_options.h"
#include "cvslam/scenario/imu_recording.h"
#include "cvslam/scenario/noise_model.h"
#include "cvslam/scenario/trajectory.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

class ImuSimulator {
 public:
  ImuSimulator(std::shared_ptr<const Trajectory> trajectory, const ImuOptions& options,
               uint64_t seed, double time_offset = 0.0);

  /// The measurement at dataset time t_us (trajectory time t_us·1e−6 + time_offset). Calls
  /// must come in increasing time: the biases walk from the previous call.
  ImuSample sample(int64_t t_us);

  /// Noise-free measurement of a true state.
  static ImuSample perfectSample(const TrajectoryState& state, int64_t t_us);

  const Eigen::Vector3d& gyroBias() const { return gyro_bias_; }
  const Eigen::Vector3d& accelBias() const { return accel_bias_; }
  const ImuOptions& options() const { return o_; }
  /// A recording is played (useRecording): the biases are unknown.
  bool playsRecording() const { return recording_ != nullptr; }
  /// From now on samples come from `recording` at file time file_time_at_zero + t (+ the
  /// trajectory time offset); biases read zero (the recording's are unknown).
  void useRecording(std::shared_ptr<const ImuRecording> recording, double file_time_at_zero);
  /// With a recording: its samples from before simulation time 0 (negative times), what the
  /// IMU measured while the vehicle waited for the flight; empty otherwise.
  std::vector<ImuSample> recordedBeforeStart() const;

 private:
  Eigen::Vector3d noiseVector(double sigma);

  std::shared_ptr<const Trajectory> trajectory_;
  ImuOptions o_;
  Rng rng_;
  double time_offset_ = 0.0;
  Eigen::Vector3d gyro_bias_;
  Eigen::Vector3d accel_bias_;
  Eigen::Matrix<double, 6, 1> vibration_phase_;  // gyro xyz, accel xyz [rad]
  int64_t last_t_us_ = 0;
  bool started_ = false;
  std::shared_ptr<const ImuRecording> recording_;
  double recording_time_at_zero_ = 0.0;
};

}  // namespace cvslam::sim
