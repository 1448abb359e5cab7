#include "cvslam/scenario/trajectory_spec.h"

#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

namespace {

constexpr double kDeg = M_PI / 180.0;

void loadAttitude(const ConfigNode& node, AttitudeOptions& a) {
  node.getEnum("heading", a.heading,
               {{"velocity", HeadingMode::kVelocity}, {"fixed", HeadingMode::kFixed}});
  double yaw_deg = a.fixed_yaw / kDeg, max_tilt_deg = a.max_tilt / kDeg;
  node.get("yaw_deg", yaw_deg);
  node.getEnum("tilt", a.tilt,
               {{"level", TiltMode::kLevel},
                {"bank", TiltMode::kBank},
                {"quadrotor", TiltMode::kQuadrotor}});
  node.get("max_tilt_deg", max_tilt_deg);
  node.check(max_tilt_deg > 0.0 && max_tilt_deg < 80.0, "max_tilt_deg", "must be in (0, 80)");
  a.fixed_yaw = yaw_deg * kDeg;
  a.max_tilt = max_tilt_deg * kDeg;
}

void loadPeriodOrSpeed(const ConfigNode& node, double& period, double& speed) {
  node.get("period", period);
  node.get("speed", speed);
  node.check(!(node.has("period") && node.has("speed")), "speed", "give period or speed, not both");
  node.check(period > 0.0, "period", "must be > 0");
  node.check(speed >= 0.0, "speed", "must be >= 0");
}

// Any kind: the resting start (resting_start.h).
void loadRestingStart(const ConfigNode& node, double& rest, double& ramp) {
  node.get("rest", rest);
  node.get("rest_ramp", ramp);
  node.check(rest >= 0.0, "rest", "must be >= 0");
  node.check(ramp >= 0.0, "rest_ramp", "must be >= 0");
}

}  // namespace

Status TrajectorySpec::load(const ConfigNode& node, const std::string& base_dir) {
  node.getEnum("kind", kind,
               {{"loop", TrajectoryKind::kLoop},
                {"circle", TrajectoryKind::kCircle},
                {"figure8", TrajectoryKind::kFigure8},
                {"lawnmower", TrajectoryKind::kLawnmower},
                {"waypoints", TrajectoryKind::kWaypoints},
                {"tum", TrajectoryKind::kTum},
                {"hover", TrajectoryKind::kHover}});
  node.get("time_offset", time_offset);
  loadRestingStart(node, rest, rest_ramp);
  if (kind != TrajectoryKind::kTum) loadAttitude(node, attitude);
  switch (kind) {
    case TrajectoryKind::kLoop:
    case TrajectoryKind::kCircle: {
      node.get("centre", loop.centre);
      if (kind == TrajectoryKind::kCircle) {
        double radius = loop.semi_axis_x;
        node.get("radius", radius);
        node.check(radius > 0.0, "radius", "must be > 0");
        loop.semi_axis_x = loop.semi_axis_y = radius;
      } else {
        Eigen::Vector2d axes(loop.semi_axis_x, loop.semi_axis_y);
        node.get("semi_axes", axes);
        node.check(axes.minCoeff() > 0.0, "semi_axes", "must be > 0");
        loop.semi_axis_x = axes.x();
        loop.semi_axis_y = axes.y();
      }
      node.get("altitude", loop.altitude);
      node.get("altitude_amplitude", loop.altitude_amplitude);
      loadPeriodOrSpeed(node, loop.period, speed);
      double start_deg = loop.start_angle / kDeg;
      node.get("start_angle_deg", start_deg);
      loop.start_angle = start_deg * kDeg;
      node.get("clockwise", loop.clockwise);
      if (speed > 0.0)
        loop.period = LoopPath::perimeter(loop.semi_axis_x, loop.semi_axis_y) / speed;
      break;
    }
    case TrajectoryKind::kFigure8: {
      node.get("centre", figure8.centre);
      node.get("half_length", figure8.half_length);
      node.get("half_width", figure8.half_width);
      node.get("altitude", figure8.altitude);
      node.get("period", figure8.period);
      double start_deg = figure8.start_angle / kDeg;
      node.get("start_angle_deg", start_deg);
      figure8.start_angle = start_deg * kDeg;
      node.check(figure8.half_length > 0 && figure8.half_width > 0, "half_length",
                 "half_length and half_width must be > 0");
      node.check(figure8.period > 0.0, "period", "must be > 0");
      break;
    }
    case TrajectoryKind::kLawnmower: {
      double heading_deg = lawn_heading / kDeg;
      node.get("start", lawn_start);
      node.get("altitude", lawn_altitude);
      node.get("heading_deg", heading_deg);
      node.get("row_length", lawn_row_length);
      node.get("row_spacing", lawn_row_spacing);
      node.get("rows", lawn_rows);
      speed = 3.0;
      node.get("speed", speed);
      lawn_heading = heading_deg * kDeg;
      node.check(lawn_row_length > 0.0, "row_length", "must be > 0");
      node.check(lawn_row_spacing > 0.0, "row_spacing", "must be > 0");
      node.check(lawn_rows >= 1, "rows", "must be >= 1");
      node.check(speed > 0.0, "speed", "must be > 0");
      break;
    }
    case TrajectoryKind::kWaypoints: {
      points.clear();
      times.clear();
      const auto items = node.sequence("points");
      for (const ConfigNode& item : items) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        item.require("p", p);
        points.push_back(p);
        if (item.has("t")) {
          double t = 0.0;
          item.get("t", t);
          times.push_back(t);
        }
      }
      node.get("closed", closed);
      node.get("speed", speed);
      node.check(points.size() >= (closed ? 4u : 2u), "points",
                 closed ? "a closed path needs at least 3 points plus the first repeated"
                        : "need at least 2 waypoints");
      node.check(times.empty() || times.size() == points.size(), "points",
                 "give a time t for every waypoint or for none");
      bool increasing = true;
      for (std::size_t i = 1; i < times.size(); ++i) increasing &= times[i] > times[i - 1];
      node.check(increasing, "points", "waypoint times must increase");
      node.check(times.empty() || times.front() == 0.0, "points", "the first time t must be 0");
      node.check(!times.empty() || speed > 0.0, "speed", "must be > 0 when no times are given");
      node.check(!closed || points.empty() || (points.front() - points.back()).norm() < 1e-9,
                 "closed", "a closed path must end at its first point");
      break;
    }
    case TrajectoryKind::kTum: {
      node.require("file", tum.file);
      if (!tum.file.empty() && tum.file.front() != '/' && !base_dir.empty())
        tum.file = base_dir + "/" + tum.file;
      node.get("z_up_to_ned", tum.z_up_to_ned);
      node.get("R_TtoB", tum.R_TtoB);
      node.get("start_at_offset", tum.start_at_offset);
      node.get("offset", tum.offset);
      node.get("knot_interval", tum.knot_interval);
      node.check(tum.knot_interval > 0.0, "knot_interval", "must be > 0");
      node.check(
          (tum.R_TtoB * tum.R_TtoB.transpose()).isIdentity(1e-6) && tum.R_TtoB.determinant() > 0,
          "R_TtoB", "must be a rotation matrix");
      break;
    }
    case TrajectoryKind::kHover:
      node.get("position", hover_position);
      break;
  }
  return node.status();
}

Expected<std::shared_ptr<const Trajectory>> TrajectorySpec::build() const {
  auto base = buildBase();
  if (!base.ok() || rest <= 0.0) return base;
  return std::shared_ptr<const Trajectory>(
      std::make_shared<RestingStartTrajectory>(*base, rest, rest_ramp));
}

Expected<std::shared_ptr<const Trajectory>> TrajectorySpec::buildBase() const {
  std::shared_ptr<const PositionPath> path;
  switch (kind) {
    case TrajectoryKind::kLoop:
    case TrajectoryKind::kCircle:
      path = std::make_shared<LoopPath>(loop);
      break;
    case TrajectoryKind::kFigure8:
      path = std::make_shared<Figure8Path>(figure8);
      break;
    case TrajectoryKind::kLawnmower: {
      const auto wps =
          lawnmowerWaypoints(Eigen::Vector3d(lawn_start.x(), lawn_start.y(), -lawn_altitude),
                             lawn_heading, lawn_row_length, lawn_row_spacing, lawn_rows);
      path = std::make_shared<SplinePath>(SplinePath::chordTimes(wps, speed), wps, false);
      break;
    }
    case TrajectoryKind::kWaypoints: {
      std::vector<double> t = times.empty() ? SplinePath::chordTimes(points, speed) : times;
      path = std::make_shared<SplinePath>(t, points, closed);
      break;
    }
    case TrajectoryKind::kTum: {
      auto tum_traj = TumTrajectory::load(tum);
      if (!tum_traj.ok()) return tum_traj.status();
      return std::shared_ptr<const Trajectory>(*tum_traj);
    }
    case TrajectoryKind::kHover:
      path = std::make_shared<HoverPath>(hover_position);
      break;
  }
  return std::shared_ptr<const Trajectory>(std::make_shared<FlightTrajectory>(path, attitude));
}

}  // namespace cvslam::sim
