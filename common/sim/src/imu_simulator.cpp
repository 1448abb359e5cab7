#include "cvslam/sim/imu_simulator.h"

#include <Eigen/LU>

#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

ImuSimulator::ImuSimulator(std::shared_ptr<const Trajectory> trajectory, const ImuOptions& options,
                           uint64_t seed, double time_offset)
    : trajectory_(std::move(trajectory)),
      o_(options),
      rng_(seed),
      time_offset_(time_offset),
      gyro_bias_(options.noise ? options.gyro_bias : Eigen::Vector3d::Zero()),
      accel_bias_(options.noise ? options.accel_bias : Eigen::Vector3d::Zero()) {
  // Drawn only when vibration is on, so that scenarios without it keep their noise sequence.
  vibration_phase_.setZero();
  if (o_.noise && o_.vibration_hz > 0.0)
    for (int i = 0; i < 6; ++i) vibration_phase_(i) = 2.0 * M_PI * rng_.uniform();
}

ImuSample ImuSimulator::perfectSample(const TrajectoryState& state, int64_t t_us) {
  ImuSample s;
  s.t_us = t_us;
  s.gyro_B = state.omega_B;
  s.accel_B = state.specificForce_B();
  return s;
}

Eigen::Vector3d ImuSimulator::noiseVector(double sigma) {
  Eigen::Vector3d n;
  for (int i = 0; i < 3; ++i) n(i) = sampleCentredNoise(rng_, o_.kind, o_.shape, sigma);
  return n;
}

void ImuSimulator::useRecording(std::shared_ptr<const ImuRecording> recording,
                                double file_time_at_zero) {
  recording_ = std::move(recording);
  recording_time_at_zero_ = file_time_at_zero;
  gyro_bias_.setZero();
  accel_bias_.setZero();
}

std::vector<ImuSample> ImuSimulator::recordedBeforeStart() const {
  if (!recording_) return {};
  return recording_->samplesBefore(recording_time_at_zero_ + time_offset_);
}

ImuSample ImuSimulator::sample(int64_t t_us) {
  if (recording_) {
    return recording_->sampleAt(
        recording_time_at_zero_ + 1e-6 * static_cast<double>(t_us) + time_offset_, t_us);
  }
  const TrajectoryState truth = trajectory_->state(1e-6 * static_cast<double>(t_us) + time_offset_);
  ImuSample s = perfectSample(truth, t_us);
  if (!o_.noise) return s;
  if (started_ && t_us > last_t_us_) {
    const double sqrt_dt = std::sqrt(1e-6 * static_cast<double>(t_us - last_t_us_));
    for (int i = 0; i < 3; ++i) gyro_bias_(i) += o_.gyro_random_walk * sqrt_dt * rng_.gaussian();
    for (int i = 0; i < 3; ++i) accel_bias_(i) += o_.accel_random_walk * sqrt_dt * rng_.gaussian();
  }
  started_ = true;
  last_t_us_ = t_us;
  const double sqrt_rate = std::sqrt(o_.rate_hz);
  s.gyro_B += gyro_bias_ + noiseVector(o_.gyro_noise_density * sqrt_rate);
  s.accel_B += accel_bias_ + noiseVector(o_.accel_noise_density * sqrt_rate);
  if (o_.vibration_hz > 0.0) {
    const double arg = 2.0 * M_PI * o_.vibration_hz * 1e-6 * static_cast<double>(t_us);
    for (int i = 0; i < 3; ++i) {
      s.gyro_B(i) += o_.vibration_gyro * std::sin(arg + vibration_phase_(i));
      s.accel_B(i) += o_.vibration_accel * std::sin(arg + vibration_phase_(3 + i));
    }
  }
  return s;
}

}  // namespace cvslam::sim
