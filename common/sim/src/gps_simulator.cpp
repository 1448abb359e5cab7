#include "cvslam/sim/gps_simulator.h"

#include <cmath>

#include "cvslam/io/config_node.h"
#include "cvslam/scenario/noise_model.h"

namespace cvslam::sim {

GpsSimulator::GpsSimulator(std::shared_ptr<const Trajectory> trajectory, const GpsOptions& options,
                           uint64_t seed)
    : trajectory_(std::move(trajectory)), o_(options), rng_(seed), bias_(options.bias_initial) {}

double GpsSimulator::whiteNoise(double sigma) {
  switch (o_.kind) {
    case GpsNoiseKind::kGaussian:
      return sigma * rng_.gaussian();
    case GpsNoiseKind::kStudentT: {
      // t_ν = N / √(χ²_ν/ν), χ²_ν a sum of ν squared normals; Var t_ν = ν/(ν − 2).
      double chi2 = 0.0;
      for (int i = 0; i < o_.student_dof; ++i) {
        const double g = rng_.gaussian();
        chi2 += g * g;
      }
      const double nu = static_cast<double>(o_.student_dof);
      const double t = rng_.gaussian() / std::sqrt(chi2 / nu);
      return sigma * std::sqrt((nu - 2.0) / nu) * t;
    }
    case GpsNoiseKind::kMixture:
      return sampleCentredNoise(rng_, NoiseKind::kNonGaussianCentred, NonGaussianShape::kMixture,
                                sigma);
  }
  return 0.0;
}

GpsFix GpsSimulator::fixAt(int64_t t_us) {
  const double t_s = 1e-6 * static_cast<double>(t_us);
  if (started_ && t_us > last_t_us_ && o_.bias_random_walk > 0.0) {
    const double sqrt_dt = std::sqrt(1e-6 * static_cast<double>(t_us - last_t_us_));
    for (int i = 0; i < 3; ++i) bias_(i) += o_.bias_random_walk * sqrt_dt * rng_.gaussian();
  }
  started_ = true;
  last_t_us_ = t_us;
  const TrajectoryState truth = trajectory_->state(t_s);
  GpsFix fix;
  fix.t_us = t_us;
  fix.sigma_p = Eigen::Vector3d(o_.sigma_horizontal, o_.sigma_horizontal, o_.sigma_vertical);
  fix.sigma_v = Eigen::Vector3d::Constant(o_.sigma_velocity);
  fix.p_N = truth.p_BinN + bias_;
  fix.v_N = truth.v_N;
  for (int i = 0; i < 3; ++i) fix.p_N(i) += whiteNoise(fix.sigma_p(i));
  for (int i = 0; i < 3; ++i) fix.v_N(i) += whiteNoise(fix.sigma_v(i));
  return fix;
}

std::vector<GpsFix> GpsSimulator::fixes(double end_s) {
  std::vector<GpsFix> out;
  const double period_us = 1e6 / o_.rate_hz;
  for (int64_t k = 0;; ++k) {
    const auto t_us =
        static_cast<int64_t>(std::llround(1e6 * o_.start_s + static_cast<double>(k) * period_us));
    if (1e-6 * static_cast<double>(t_us) > end_s) break;
    // The bias walks through outages too: draw the fix, drop it when masked.
    GpsFix fix = fixAt(t_us);
    if (!o_.inOutage(1e-6 * static_cast<double>(t_us))) out.push_back(fix);
  }
  return out;
}

}  // namespace cvslam::sim
