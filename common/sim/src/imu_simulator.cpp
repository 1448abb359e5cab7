#include "cvslam/sim/imu_simulator.h"

#include <Eigen/LU>

#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

Status ImuOptions::load(const ConfigNode& node) {
  node.get("rate_hz", rate_hz);
  node.get("noise", noise);
  node.getEnum("kind", kind,
               {{"gaussian", NoiseKind::kGaussian},
                {"non_gaussian_centred", NoiseKind::kNonGaussianCentred}});
  node.getEnum("shape", shape, nonGaussianShapeNames());
  node.get("gyro_noise_density", gyro_noise_density);
  node.get("accel_noise_density", accel_noise_density);
  node.get("gyro_random_walk", gyro_random_walk);
  node.get("accel_random_walk", accel_random_walk);
  node.get("gyro_bias", gyro_bias);
  node.get("accel_bias", accel_bias);
  node.get("vibration_accel", vibration_accel);
  node.get("vibration_gyro", vibration_gyro);
  node.get("vibration_hz", vibration_hz);
  node.check(vibration_accel >= 0.0, "vibration_accel", "must be >= 0");
  node.check(vibration_gyro >= 0.0, "vibration_gyro", "must be >= 0");
  node.check(vibration_hz >= 0.0, "vibration_hz", "must be >= 0");
  node.get("recording", recording);
  node.get("recording_R_StoB", recording_R_StoB);
  node.get("recording_start", recording_start);
  node.check((recording_R_StoB * recording_R_StoB.transpose()).isIdentity(1e-6) &&
                 recording_R_StoB.determinant() > 0,
             "recording_R_StoB", "must be a rotation matrix");
  node.check(rate_hz > 0.0 && rate_hz <= 1e5, "rate_hz", "must be in (0, 100000]");
  node.check(gyro_noise_density >= 0.0, "gyro_noise_density", "must be >= 0");
  node.check(accel_noise_density >= 0.0, "accel_noise_density", "must be >= 0");
  node.check(gyro_random_walk >= 0.0, "gyro_random_walk", "must be >= 0");
  node.check(accel_random_walk >= 0.0, "accel_random_walk", "must be >= 0");
  return node.status();
}

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
