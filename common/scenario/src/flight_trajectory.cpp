#include "cvslam/scenario/flight_trajectory.h"

#include <cmath>
#include <tuple>
#include <utility>

#include "cvslam/geometry/euler.h"

namespace cvslam::sim {

Eigen::Vector3d bodyRatesFromEulerRates(const Eigen::Vector3d& euler,
                                        const Eigen::Vector3d& euler_rates) {
  // Inverse of thesis eq. 2.4: p = φ̇ − ψ̇ sθ, q = θ̇ cφ + ψ̇ sφ cθ, r = −θ̇ sφ + ψ̇ cφ cθ.
  const double sr = std::sin(euler(0)), cr = std::cos(euler(0));
  const double sp = std::sin(euler(1)), cp = std::cos(euler(1));
  const double dr = euler_rates(0), dp = euler_rates(1), dy = euler_rates(2);
  return {dr - dy * sp, dp * cr + dy * sr * cp, -dp * sr + dy * cr * cp};
}

namespace {

/// Bounded tilt angle for a horizontal acceleration component and its rate:
/// angle = ±m tanh(atan(a/g)/m); returns (angle, d angle / dt).
std::pair<double, double> boundedTilt(double a, double a_dot, double max_tilt) {
  const double g = gravityNed().z();
  const double c = a / g, c_dot = a_dot / g;
  const double u = std::atan(c) / max_tilt;
  const double th = std::tanh(u);
  return {max_tilt * th, (1.0 - th * th) * c_dot / (1.0 + c * c)};
}

}  // namespace

TrajectoryState FlightTrajectory::state(double t) const {
  const PathPoint pp = path_->at(t);
  TrajectoryState s;
  s.t = t;
  s.p_BinN = pp.value;
  s.v_N = pp.d1;
  s.a_N = pp.d2;
  const Eigen::Vector3d& v = pp.d1;
  const Eigen::Vector3d& a = pp.d2;
  const Eigen::Vector3d& j = pp.d3;

  double yaw = o_.fixed_yaw, yaw_rate = 0.0;
  if (o_.heading == HeadingMode::kVelocity) {
    // ψ = atan2(v_y, v_x), ψ̇ = (v_x a_y − v_y a_x) / s with s = v_x² + v_y² (> 0: the
    // parametric paths never stop).
    const double sq = v.x() * v.x() + v.y() * v.y();
    yaw = std::atan2(v.y(), v.x());
    yaw_rate = sq > 1e-12 ? (v.x() * a.y() - v.y() * a.x()) / sq : 0.0;
  }
  double roll = 0.0, roll_rate = 0.0, pitch = 0.0, pitch_rate = 0.0;
  if (o_.tilt != TiltMode::kLevel) {
    const double cy = std::cos(yaw), sy = std::sin(yaw);
    const double a_lon = a.x() * cy + a.y() * sy;
    const double a_lat = -a.x() * sy + a.y() * cy;
    // d/dt of the projections onto the rotating heading axes.
    const double a_lon_dot = j.x() * cy + j.y() * sy + yaw_rate * a_lat;
    const double a_lat_dot = -j.x() * sy + j.y() * cy - yaw_rate * a_lon;
    std::tie(roll, roll_rate) = boundedTilt(a_lat, a_lat_dot, o_.max_tilt);
    if (o_.tilt == TiltMode::kQuadrotor) {
      std::tie(pitch, pitch_rate) = boundedTilt(a_lon, a_lon_dot, o_.max_tilt);
      pitch = -pitch;
      pitch_rate = -pitch_rate;
    }
  }
  s.euler = {roll, pitch, yaw};
  s.euler_rates = {roll_rate, pitch_rate, yaw_rate};
  s.R_NtoB = rotationNavToBody(s.euler);
  s.omega_B = bodyRatesFromEulerRates(s.euler, s.euler_rates);
  return s;
}

}  // namespace cvslam::sim
