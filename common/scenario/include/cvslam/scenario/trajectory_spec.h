#pragma once
// Trajectory description as read from a scenario file, and the factory that builds it.
//
// `kind` selects the shape; each kind reads only its own keys (other keys are reported as
// unknown by ConfigNode::finish):
//   loop / circle  centre [x y], semi_axes [a b] (loop) or radius (circle), altitude,
//                  altitude_amplitude, period [s] or speed [m/s], start_angle_deg, clockwise
//   figure8        centre, half_length, half_width, altitude, period [s], start_angle_deg
//   lawnmower      start [x y], altitude, heading_deg, row_length, row_spacing, rows, speed
//   waypoints      points: list of {p: [x y z] NED, t: time [s] (all or none)}, closed,
//                  speed (when no times: chord-length timing)
//   tum            file (relative to the scenario file), z_up_to_ned, R_TtoB,
//                  start_at_offset, offset, knot_interval (see tum_trajectory.h)
//   hover          position [x y z] NED
// Attitude (all kinds but tum): heading velocity|fixed, yaw_deg, tilt level|bank|quadrotor,
// max_tilt_deg. time_offset [s]: trajectory time at simulation time 0. Any kind: rest [s] and
// rest_ramp [s] begin the flight standing still at its first pose (resting_start.h).

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/scenario/flight_trajectory.h"
#include "cvslam/scenario/position_path.h"
#include "cvslam/scenario/resting_start.h"
#include "cvslam/scenario/trajectory.h"
#include "cvslam/scenario/tum_trajectory.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

enum class TrajectoryKind : uint8_t {
  kLoop,
  kCircle,
  kFigure8,
  kLawnmower,
  kWaypoints,
  kTum,
  kHover
};

struct TrajectorySpec {
  TrajectoryKind kind = TrajectoryKind::kCircle;
  LoopPath::Params loop;        ///< loop, circle (circle: semi axes = radius)
  double speed = 0.0;           ///< loop/circle: if > 0 sets the period; lawnmower, waypoints
  Figure8Path::Params figure8;  ///< figure8
  Eigen::Vector2d lawn_start = Eigen::Vector2d::Zero();  ///< lawnmower first row start [m]
  double lawn_altitude = 10.0;                           ///< [m]
  double lawn_heading = 0.0;                             ///< row direction [rad]
  double lawn_row_length = 60.0;                         ///< [m]
  double lawn_row_spacing = 10.0;                        ///< [m]
  int lawn_rows = 4;
  std::vector<Eigen::Vector3d> points;  ///< waypoints, NED [m]
  std::vector<double> times;            ///< waypoint times [s] (empty: chord-length timing)
  bool closed = false;                  ///< waypoints: closed periodic path
  TumTrajectoryOptions tum;             ///< tum
  Eigen::Vector3d hover_position = Eigen::Vector3d(0.0, 0.0, -10.0);  ///< hover [m]
  AttitudeOptions attitude;
  double time_offset = 0.0;  ///< trajectory time at simulation time 0 [s]
  double rest = 0.0;         ///< standing still at the first pose before setting off [s]
  double rest_ramp = 2.0;    ///< smooth start after the rest [s] (0 with an IMU recording)

  /// `base_dir` resolves relative TUM file names (the scenario file's folder).
  Status load(const ConfigNode& node, const std::string& base_dir = "");
  /// Builds the trajectory (reads the TUM file for kind tum).
  Expected<std::shared_ptr<const Trajectory>> build() const;

 private:
  /// The trajectory of `kind`, without the resting start.
  Expected<std::shared_ptr<const Trajectory>> buildBase() const;
};

}  // namespace cvslam::sim
