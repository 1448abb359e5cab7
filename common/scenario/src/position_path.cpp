#include "cvslam/scenario/position_path.h"

#include <cmath>

namespace cvslam::sim {

double LoopPath::perimeter(double a, double b) {
  const double h = (a - b) * (a - b) / ((a + b) * (a + b));
  return M_PI * (a + b) * (1.0 + 3.0 * h / (10.0 + std::sqrt(4.0 - 3.0 * h)));
}

PathPoint LoopPath::at(double t) const {
  const double w = (p_.clockwise ? 1.0 : -1.0) * 2.0 * M_PI / p_.period;
  const double th = p_.start_angle + w * t;
  const double c = std::cos(th), s = std::sin(th);
  const double cz = std::cos(th - p_.start_angle), sz = std::sin(th - p_.start_angle);
  const double a = p_.semi_axis_x, b = p_.semi_axis_y, dz = p_.altitude_amplitude;
  const double w2 = w * w, w3 = w2 * w;
  PathPoint out;
  out.value << p_.centre.x() + a * c, p_.centre.y() + b * s, -p_.altitude - dz * sz;
  out.d1 << -a * s * w, b * c * w, -dz * cz * w;
  out.d2 << -a * c * w2, -b * s * w2, dz * sz * w2;
  out.d3 << a * s * w3, -b * c * w3, dz * cz * w3;
  return out;
}

PathPoint Figure8Path::at(double t) const {
  const double w = 2.0 * M_PI / p_.period;
  const double th = p_.start_angle + w * t;
  const double a = p_.half_length, b = p_.half_width;
  const double s1 = std::sin(th), c1 = std::cos(th), s2 = std::sin(2 * th), c2 = std::cos(2 * th);
  const double w2 = w * w, w3 = w2 * w;
  PathPoint out;
  out.value << p_.centre.x() + a * s1, p_.centre.y() + 0.5 * b * s2, -p_.altitude;
  out.d1 << a * w * c1, b * w * c2, 0.0;
  out.d2 << -a * w2 * s1, -2.0 * b * w2 * s2, 0.0;
  out.d3 << -a * w3 * c1, -4.0 * b * w3 * c2, 0.0;
  return out;
}

std::vector<double> SplinePath::chordTimes(const std::vector<Eigen::Vector3d>& waypoints,
                                           double speed) {
  std::vector<double> times;
  double t = 0.0;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    if (i > 0) t += (waypoints[i] - waypoints[i - 1]).norm() / speed;
    times.push_back(t);
  }
  return times;
}

double SplinePath::duration() const {
  return spline_.periodic() ? std::numeric_limits<double>::infinity()
                            : spline_.endTime() - spline_.startTime();
}

std::vector<Eigen::Vector3d> lawnmowerWaypoints(const Eigen::Vector3d& start, double heading,
                                                double row_length, double row_spacing, int rows) {
  // Pattern in a local frame (x along the rows, y across), then rotated by the heading.
  std::vector<Eigen::Vector2d> local;
  const int per_row = std::max(2, static_cast<int>(std::ceil(row_length / (0.5 * row_spacing))));
  const double r = 0.5 * row_spacing;
  for (int k = 0; k < rows; ++k) {
    const bool forward = (k % 2) == 0;
    const double y = k * row_spacing;
    for (int i = 0; i <= per_row; ++i) {
      const double s = row_length * i / per_row;
      local.emplace_back(forward ? s : row_length - s, y);
    }
    if (k + 1 == rows) break;
    // Half circle to the next row, centred beyond the row end.
    const double xc = forward ? row_length : 0.0;
    const double dir = forward ? 1.0 : -1.0;
    for (int i = 1; i <= 3; ++i) {
      const double phi = -M_PI / 2 + i * M_PI / 4;  // −45°, 0°, 45° around the turn
      local.emplace_back(xc + dir * r * std::cos(phi), y + r + r * std::sin(phi));
    }
  }
  const double c = std::cos(heading), s = std::sin(heading);
  std::vector<Eigen::Vector3d> out;
  for (const auto& q : local)
    out.push_back(start + Eigen::Vector3d(c * q.x() - s * q.y(), s * q.x() + c * q.y(), 0.0));
  return out;
}

}  // namespace cvslam::sim
