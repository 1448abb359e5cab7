#pragma once
// Trajectory read from a TUM file (`t x y z qx qy qz qw`, seconds; the pose of the body in the
// file's world frame, q rotating body vectors into the world), e.g. the EuRoC ground truth in
// data/euroc/*.tum (body = IMU, world z up).
//
// Smooth, differentiable interpolation so that a synthesised IMU is sensible: the samples are
// averaged over windows of `knot_interval` seconds and interpolated by natural cubic splines —
// positions (C², analytic velocity and acceleration) and the four quaternion components
// (normalised after interpolation; ω_B = 2 vec(q* ⊗ q̇) analytically).
//
// Frames: the file's world W becomes NED by R_WtoN: with `z_up_to_ned: true` (default, for
// EuRoC's z-up world) R_WtoN = diag(1, −1, −1) (a half turn about x: x stays, y and z flip);
// otherwise W is taken as NED already. The file's body T becomes our body B by R_TtoB (default
// identity: B is the IMU frame of the file, which for EuRoC is not FRD — its x axis points up,
// so Euler angles are near θ = −90°; give R_TtoB to fly an FRD body). Time starts at 0 at the
// first sample (`start_time()` keeps the file's stamp); positions may be shifted so that the
// flight starts at `offset`.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>

#include "cvslam/core/status.h"
#include "cvslam/scenario/cubic_spline.h"
#include "cvslam/scenario/trajectory.h"

namespace cvslam::sim {

struct TumTrajectoryOptions {
  std::string file;         ///< TUM file path
  bool z_up_to_ned = true;  ///< world is z-up (EuRoC): convert to NED with diag(1, −1, −1)
  Eigen::Matrix3d R_TtoB = Eigen::Matrix3d::Identity();  ///< file body → simulated body
  bool start_at_offset = false;                      ///< shift positions so that p_BinN(0) = offset
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< NED [m], see start_at_offset
  double knot_interval = 0.1;  ///< spline knot spacing and averaging window [s]
};

class TumTrajectory : public Trajectory {
 public:
  /// Reads and fits the file. Errors name the file (and line for malformed rows).
  static Expected<std::shared_ptr<TumTrajectory>> load(const TumTrajectoryOptions& options);

  TrajectoryState state(double t) const override;
  double duration() const override { return duration_; }
  /// Time stamp in the file of trajectory time 0 [s].
  double startTime() const { return start_time_; }

 private:
  TumTrajectory() = default;
  CubicSpline<3> position_;  // p_BinN(t)
  CubicSpline<4> quat_;      // q_WT as (w, x, y, z), not normalised
  Eigen::Matrix3d R_WtoN_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_TtoB_ = Eigen::Matrix3d::Identity();
  double duration_ = 0.0;
  double start_time_ = 0.0;
};

}  // namespace cvslam::sim
