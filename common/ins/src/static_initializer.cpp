#include "cvslam/ins/static_initializer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "cvslam/io/config_node.h"

namespace cvslam {

Status StaticInitializerOptions::load(const ConfigNode& node) {
  node.get("window_s", window_s);
  node.get("segments", segments);
  node.get("max_accel_mean_change", max_accel_mean_change);
  node.get("max_gyro_mean_change", max_gyro_mean_change);
  node.get("max_gravity_error", max_gravity_error);
  node.check(window_s > 0.0, "window_s", "must be > 0");
  node.check(segments >= 2, "segments", "must be >= 2");
  node.check(max_accel_mean_change > 0.0, "max_accel_mean_change", "must be > 0");
  node.check(max_gyro_mean_change > 0.0, "max_gyro_mean_change", "must be > 0");
  node.check(max_gravity_error > 0.0, "max_gravity_error", "must be > 0");
  return node.status();
}

namespace {

std::string format(const char* fmt, double a, double b) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), fmt, a, b);
  return buf;
}

}  // namespace

namespace {

/// |cos| between body x and the vertical above which the heading is taken from another axis
/// (x within ~26° of the vertical has too short a horizontal part).
constexpr double kMaxHeadingAxisVerticality = 0.9;

/// R_BtoN with N's z along gravity (−f_B at rest) and N's x along the horizontal part of body
/// x, or, when x is near the vertical, of the body axis least aligned with it
/// (StaticInitialization::q_BtoN).
Eigen::Quaterniond gravityAlignedRotation(const Eigen::Vector3d& f_B) {
  const Eigen::Vector3d down_B = -f_B.normalized();  // N's z in B
  Eigen::Index axis = 0;
  if (std::abs(down_B.x()) > kMaxHeadingAxisVerticality) down_B.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d a = Eigen::Vector3d::Unit(axis);
  const Eigen::Vector3d north_B = (a - a.dot(down_B) * down_B).normalized();  // N's x in B
  Eigen::Matrix3d R_NtoB;  // columns: N's axes in B
  R_NtoB.col(0) = north_B;
  R_NtoB.col(2) = down_B;
  R_NtoB.col(1) = down_B.cross(north_B);
  return Eigen::Quaterniond(R_NtoB.transpose()).normalized();
}

}  // namespace

Expected<StaticInitialization> initializeAtRest(const std::vector<ImuSample>& samples,
                                                const StaticInitializerOptions& options,
                                                double gravity, double accel_bias_sigma) {
  if (samples.size() < 2) return Status::Error("static initialisation: fewer than 2 IMU samples");
  const int64_t t0 = samples.front().t_us;
  const int64_t t_end = t0 + static_cast<int64_t>(std::llround(options.window_s * 1e6));
  if (samples.back().t_us < t_end)
    return Status::Error(
        format("static initialisation: rest period too short: %.3f s of IMU, "
               "need %.3f s (static_init.window_s)",
               static_cast<double>(samples.back().t_us - t0) * 1e-6, options.window_s));
  std::size_t end = 0;
  while (end < samples.size() && samples[end].t_us <= t_end) ++end;
  const int n = static_cast<int>(end);
  if (n < 2 * options.segments)
    return Status::Error("static initialisation: " + std::to_string(n) +
                         " IMU samples in the rest window, need at least " +
                         std::to_string(2 * options.segments));
  StaticInitialization init;
  init.samples = n;
  init.t_us = samples[end - 1].t_us;
  Eigen::Vector3d f = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
  Eigen::Vector3d f2 = Eigen::Vector3d::Zero(), w2 = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < end; ++k) {
    const ImuSample& s = samples[k];
    if (!s.accel_B.allFinite() || !s.gyro_B.allFinite())
      return Status::Error(
          "static initialisation: non-finite IMU sample at t = " + std::to_string(s.t_us) + " µs");
    f += s.accel_B;
    w += s.gyro_B;
    f2 += s.accel_B.cwiseAbs2();
    w2 += s.gyro_B.cwiseAbs2();
  }
  const double count = n;
  f /= count;
  w /= count;
  init.accel_std = (f2 / count - f.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  init.gyro_std = (w2 / count - w.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  double accel_change = 0.0, gyro_change = 0.0;
  for (int seg = 0; seg < options.segments; ++seg) {
    const std::size_t a = end * static_cast<std::size_t>(seg) / options.segments;
    const std::size_t b = end * static_cast<std::size_t>(seg + 1) / options.segments;
    Eigen::Vector3d fs = Eigen::Vector3d::Zero(), ws = Eigen::Vector3d::Zero();
    for (std::size_t k = a; k < b; ++k) fs += samples[k].accel_B, ws += samples[k].gyro_B;
    const double m = static_cast<double>(b - a);
    accel_change = std::max(accel_change, (fs / m - f).cwiseAbs().maxCoeff());
    gyro_change = std::max(gyro_change, (ws / m - w).cwiseAbs().maxCoeff());
  }
  const auto not_at_rest = [&](const char* what, double change, int digits, const char* unit,
                               const char* key) {
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "static initialisation: the vehicle is not at rest in the first %.3f s (mean "
                  "%s changes by %.*f %s, limit static_init.%s)",
                  options.window_s, what, digits, change, unit, key);
    return Status::Error(buf);
  };
  if (accel_change > options.max_accel_mean_change)
    return not_at_rest("specific force", accel_change, 3, "m/s²", "max_accel_mean_change");
  if (gyro_change > options.max_gyro_mean_change)
    return not_at_rest("angular rate", gyro_change, 4, "rad/s", "max_gyro_mean_change");
  if (std::abs(f.norm() - gravity) > options.max_gravity_error)
    return Status::Error(
        format("static initialisation: mean specific force %.3f m/s² at rest, "
               "gravity is %.3f m/s² (wrong units or an accelerating vehicle)",
               f.norm(), gravity));
  // f_B = −R_NtoB [0 0 g]ᵀ = −g · (third column of R_NtoB) = −g [−sinθ, sinφ cosθ, cosφ cosθ].
  const double roll = std::atan2(-f.y(), -f.z());
  const double pitch = std::atan2(f.x(), std::hypot(f.y(), f.z()));
  init.euler = Eigen::Vector3d(roll, pitch, 0.0);
  init.q_BtoN = gravityAlignedRotation(f);
  init.gyro_bias = w;
  init.gyro_bias_sigma = init.gyro_std / std::sqrt(count);
  init.tilt_sigma = accel_bias_sigma / gravity;
  return init;
}

}  // namespace cvslam
