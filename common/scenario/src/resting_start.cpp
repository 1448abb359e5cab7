#include "cvslam/scenario/resting_start.h"

#include <utility>

namespace cvslam::sim {

RestingStartTrajectory::RestingStartTrajectory(std::shared_ptr<const Trajectory> base, double rest,
                                               double ramp)
    : base_(std::move(base)), rest_(rest), ramp_(ramp) {}

double RestingStartTrajectory::duration() const {
  return base_->duration() + rest_ + 0.5 * ramp_;
}

void RestingStartTrajectory::warp(double t, double* tau, double* tau_dot, double* tau_ddot) const {
  const double s = t - rest_;
  if (s <= 0.0) {
    *tau = 0.0, *tau_dot = 0.0, *tau_ddot = 0.0;
  } else if (s < ramp_) {
    const double u = s / ramp_;
    *tau = ramp_ * (u * u * u - 0.5 * u * u * u * u);  // ∫ (3u² − 2u³) ds
    *tau_dot = u * u * (3.0 - 2.0 * u);
    *tau_ddot = 6.0 * u * (1.0 - u) / ramp_;
  } else {
    *tau = s - 0.5 * ramp_, *tau_dot = 1.0, *tau_ddot = 0.0;
  }
}

TrajectoryState RestingStartTrajectory::state(double t) const {
  double tau = 0.0, tau_dot = 0.0, tau_ddot = 0.0;
  warp(t, &tau, &tau_dot, &tau_ddot);
  TrajectoryState s = base_->state(tau);
  s.a_N = s.a_N * tau_dot * tau_dot + s.v_N * tau_ddot;
  s.v_N *= tau_dot;
  s.omega_B *= tau_dot;
  s.euler_rates *= tau_dot;
  s.t = t;
  return s;
}

}  // namespace cvslam::sim
