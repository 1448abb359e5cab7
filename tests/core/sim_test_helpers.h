#pragma once
// Helpers shared by the simulator tests (tests/core/test_sim_*.cpp).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <memory>

#include "cvslam/scenario/flight_trajectory.h"
#include "cvslam/scenario/position_path.h"
#include "cvslam/scenario/trajectory.h"
#include "cvslam/sim/imu_simulator.h"

namespace cvslam::sim::simtest {

inline Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

/// Navigation state integrated from IMU samples.
struct NavState {
  Eigen::Matrix3d R_BtoN = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v_N = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_N = Eigen::Vector3d::Zero();
};

/// Strapdown integration with classical RK4 of Ṙ = R [ω]×, v̇ = R f + g, ṗ = v, using IMU
/// samples at t, t + h/2 and t + h (a "simple high-rate integrator").
/// `sampler` gives the sample at a true state (default: the simulator's noise-free sample).
using ImuSampler = std::function<ImuSample(const TrajectoryState&)>;
inline NavState integrateImu(const Trajectory& traj, double t0, double t1, double h,
                             const ImuSampler& sampler = {}) {
  const TrajectoryState s0 = traj.state(t0);
  NavState x{s0.R_NtoB.transpose(), s0.v_N, s0.p_BinN};
  const Eigen::Vector3d g = gravityNed();
  struct Deriv {
    Eigen::Matrix3d dR;
    Eigen::Vector3d dv, dp;
  };
  const auto f = [&](const NavState& s, double t) {
    const ImuSample m =
        sampler ? sampler(traj.state(t)) : ImuSimulator::perfectSample(traj.state(t), 0);
    return Deriv{s.R_BtoN * skew(m.gyro_B), s.R_BtoN * m.accel_B + g, s.v_N};
  };
  const auto add = [](const NavState& s, const Deriv& d, double k) {
    return NavState{s.R_BtoN + k * d.dR, s.v_N + k * d.dv, s.p_N + k * d.dp};
  };
  const int steps = static_cast<int>(std::lround((t1 - t0) / h));
  for (int i = 0; i < steps; ++i) {
    const double t = t0 + i * h;
    const Deriv k1 = f(x, t);
    const Deriv k2 = f(add(x, k1, h / 2), t + h / 2);
    const Deriv k3 = f(add(x, k2, h / 2), t + h / 2);
    const Deriv k4 = f(add(x, k3, h), t + h);
    x.R_BtoN += h / 6 * (k1.dR + 2 * k2.dR + 2 * k3.dR + k4.dR);
    x.v_N += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
    x.p_N += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(x.R_BtoN,
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    x.R_BtoN = svd.matrixU() * svd.matrixV().transpose();  // re-orthonormalise
  }
  return x;
}

inline std::shared_ptr<FlightTrajectory> makeFlight(std::shared_ptr<const PositionPath> path,
                                                    TiltMode tilt = TiltMode::kQuadrotor) {
  AttitudeOptions a;
  a.tilt = tilt;
  return std::make_shared<FlightTrajectory>(std::move(path), a);
}

}  // namespace cvslam::sim::simtest
