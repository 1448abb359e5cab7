#pragma once
// A flight: a PositionPath plus an attitude law, giving a full Trajectory (thesis §5.9).
//
// Heading follows the horizontal velocity (the UAV flies forward), ψ = atan2(v_E, v_N), or is
// fixed. Roll and pitch (bounded) tilt the thrust towards the horizontal acceleration, like a
// multirotor in a coordinated turn: with a_lon, a_lat the horizontal acceleration along and
// across the heading,
//   φ = φ_max tanh(atan(a_lat / g) / φ_max)                 (bank into turns)
//   θ = −φ_max tanh(atan(a_lon / g) / φ_max)                (nose down to speed up; quadrotor)
// Every rate is analytic (it uses the path's jerk); ω_B follows from the Euler rates by the
// inverse of thesis eq. 2.4.

#include <memory>

#include "cvslam/scenario/position_path.h"
#include "cvslam/scenario/trajectory.h"

namespace cvslam::sim {

enum class HeadingMode : uint8_t { kVelocity, kFixed };
enum class TiltMode : uint8_t { kLevel, kBank, kQuadrotor };

struct AttitudeOptions {
  HeadingMode heading = HeadingMode::kVelocity;  ///< velocity: nose along the velocity
  double fixed_yaw = 0.0;                        ///< ψ when heading is fixed [rad]
  TiltMode tilt = TiltMode::kBank;               ///< level | bank (roll) | quadrotor (roll+pitch)
  double max_tilt = 25.0 * M_PI / 180.0;         ///< bound on |φ| and |θ| [rad]
};

class FlightTrajectory : public Trajectory {
 public:
  FlightTrajectory(std::shared_ptr<const PositionPath> path, const AttitudeOptions& attitude)
      : path_(std::move(path)), o_(attitude) {}
  TrajectoryState state(double t) const override;
  double duration() const override { return path_->duration(); }
  const PositionPath& path() const { return *path_; }

 private:
  std::shared_ptr<const PositionPath> path_;
  AttitudeOptions o_;
};

}  // namespace cvslam::sim
