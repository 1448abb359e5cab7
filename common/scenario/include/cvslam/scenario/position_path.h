#pragma once
// Translational part of a simulated flight: position and its first three derivatives at any
// time, analytic so that the IMU synthesised from it is exact (thesis §5.9 flies a UAV loop).
// Attitude is added by FlightTrajectory (heading along the velocity, bank into turns).
// All positions are NED [m]; "altitude" parameters are heights above the origin (z = −alt).

#include <Eigen/Core>
#include <limits>

#include "cvslam/scenario/cubic_spline.h"
#include "cvslam/scenario/quintic_spline.h"

namespace cvslam::sim {

/// Position p_BinN and its time derivatives (velocity, acceleration, jerk) in NED.
using PathPoint = SplineSample<3>;

class PositionPath {
 public:
  virtual ~PositionPath() = default;
  virtual PathPoint at(double t) const = 0;
  /// Length of the path in time [s]; +infinity when periodic.
  virtual double duration() const = 0;
};

/// Closed ellipse (circle when a = b) flown at constant angular rate, with an optional vertical
/// undulation: θ = θ0 ± 2π t / T,
///   p = centre + [a cos θ, b sin θ, −altitude − dz sin(θ − θ0)].
/// Returns exactly to its start after one period T.
class LoopPath : public PositionPath {
 public:
  struct Params {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< [x y] NED [m]
    double semi_axis_x = 20.0;                         ///< a, along north [m]
    double semi_axis_y = 20.0;                         ///< b, along east [m]
    double altitude = 10.0;                            ///< height above z = 0 [m]
    double altitude_amplitude = 0.0;                   ///< dz [m]
    double period = 60.0;                              ///< T, time of one lap [s]
    double start_angle = 0.0;                          ///< θ0 [rad] (0: start at centre + [a, 0])
    bool clockwise = true;  ///< seen from above (NED: +θ turns north → east, i.e. clockwise)
  };
  explicit LoopPath(const Params& p) : p_(p) {}
  PathPoint at(double t) const override;
  double duration() const override { return std::numeric_limits<double>::infinity(); }
  /// Ramanujan's approximation of the ellipse perimeter [m].
  static double perimeter(double a, double b);

 private:
  Params p_;
};

/// Figure of eight (lemniscate of Gerono), θ = θ0 + 2π t / T:
///   p = centre + [a sin θ, (b/2) sin 2θ, −altitude].  Crosses itself at the centre.
class Figure8Path : public PositionPath {
 public:
  struct Params {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double half_length = 30.0;  ///< a [m], along north
    double half_width = 15.0;   ///< b [m] (the lobes are b/2 wide on each side)
    double altitude = 10.0;     ///< [m]
    double period = 60.0;       ///< [s]
    double start_angle = 0.0;   ///< θ0 [rad]
  };
  explicit Figure8Path(const Params& p) : p_(p) {}
  PathPoint at(double t) const override;
  double duration() const override { return std::numeric_limits<double>::infinity(); }

 private:
  Params p_;
};

/// A vehicle hovering at a fixed point.
class HoverPath : public PositionPath {
 public:
  explicit HoverPath(const Eigen::Vector3d& p_BinN) { point_.value = p_BinN; }
  PathPoint at(double) const override { return point_; }
  double duration() const override { return std::numeric_limits<double>::infinity(); }

 private:
  PathPoint point_;
};

/// C⁴ quintic spline through waypoints (NED), natural ends or closed (periodic), so that the
/// body rates of a flight along it are continuous. Knot times are given, or follow from the
/// chord lengths at a nominal speed.
class SplinePath : public PositionPath {
 public:
  SplinePath(std::vector<double> times, std::vector<Eigen::Vector3d> waypoints, bool closed)
      : spline_(std::move(times), std::move(waypoints), closed) {}
  /// Knot times from chord lengths at `speed` [m/s], starting at 0. A closed path must repeat
  /// its first point at the end.
  static std::vector<double> chordTimes(const std::vector<Eigen::Vector3d>& waypoints,
                                        double speed);
  PathPoint at(double t) const override { return spline_.sample(t); }
  double duration() const override;

 private:
  QuinticSpline<3> spline_;
};

/// Waypoints of a lawnmower (boustrophedon) survey: `rows` parallel rows of `row_length`,
/// `row_spacing` apart, joined by half circles; rows run along `heading` from `start`.
/// Points are dense enough (≤ row_spacing / 2 apart) for a spline to follow the pattern.
std::vector<Eigen::Vector3d> lawnmowerWaypoints(const Eigen::Vector3d& start, double heading,
                                                double row_length, double row_spacing, int rows);

}  // namespace cvslam::sim
