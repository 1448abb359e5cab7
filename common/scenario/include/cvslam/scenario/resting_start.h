#pragma once
// A trajectory that begins at rest: the vehicle stands still at the base trajectory's first
// pose for `rest` seconds, then sets off along the base trajectory through a smooth ramp —
// the way a real recording begins (and what a static initialisation needs, ins/
// static_initializer.h).
//
// Time warp: t < rest → base(0) with zero velocity, acceleration and rates; after that the
// base trajectory is played at time τ(t) whose rate τ̇ rises from 0 to 1 over `ramp`
// seconds as the smoothstep 3u² − 2u³ (u = (t − rest)/ramp), so position, velocity and
// acceleration stay continuous: v = v_base(τ) τ̇, a = a_base(τ) τ̇² + v_base(τ) τ̈,
// ω = ω_base(τ) τ̇. After the ramp τ = t − rest − ramp/2. ramp = 0 holds the first pose and
// then plays the base trajectory as it is (a real IMU recording must keep its own timing).

#include <memory>

#include "cvslam/scenario/trajectory.h"

namespace cvslam::sim {

class RestingStartTrajectory : public Trajectory {
 public:
  RestingStartTrajectory(std::shared_ptr<const Trajectory> base, double rest, double ramp);

  TrajectoryState state(double t) const override;
  double duration() const override;

  const Trajectory& base() const { return *base_; }
  double rest() const { return rest_; }
  double ramp() const { return ramp_; }
  /// Base-trajectory time τ at time t, with τ̇ and τ̈.
  void warp(double t, double* tau, double* tau_dot, double* tau_ddot) const;

 private:
  std::shared_ptr<const Trajectory> base_;
  double rest_;
  double ramp_;
};

}  // namespace cvslam::sim
