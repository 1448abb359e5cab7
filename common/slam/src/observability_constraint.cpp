#include "cvslam/slam/observability_constraint.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

Eigen::Vector3d yawDirectionOfPoint(const Eigen::Vector3d& p) {
  return {-p.y(), p.x(), 0.0};  // e3 × p
}

void constrainStereoJacobian(const Eigen::VectorXd& u_v, const Eigen::Vector3d& u_L,
                             double attitude_lever_m, StereoCamera::Matrix4x9d* H_v,
                             StereoCamera::Matrix4x3d* H_L, const TiltDirections* tilt) {
  constexpr int kPose = kObservedPoseEntries, kRows = kObservedEntries;
  using NullSpace = Eigen::Matrix<double, kRows, Eigen::Dynamic, 0, kRows, 6>;
  NullSpace N = NullSpace::Zero(kRows, tilt != nullptr ? 6 : 4);
  if (tilt != nullptr) N.rightCols<2>() = *tilt;
  N.block<3, 3>(vehicle::kPosition, 0).setIdentity();
  N.block<3, 3>(kPose, 0).setIdentity();
  N.block<kPose, 1>(0, 3) = u_v.head<kPose>();
  N.block<3, 1>(kPose, 3) = u_L;
  Eigen::Matrix<double, kRows, 1> w_inv = Eigen::Matrix<double, kRows, 1>::Ones();
  w_inv.segment<3>(vehicle::kAttitude).setConstant(attitude_lever_m * attitude_lever_m);
  const NullSpace WN = w_inv.asDiagonal() * N;
  Eigen::Matrix<double, 4, kRows> H;
  H << *H_v, *H_L;
  // NᵀW⁻¹N is positive definite: N has full column rank (the yaw and tilt columns turn the
  // attitude about three independent axes, which the translation columns do not) and W⁻¹ > 0.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6> NtWN = N.transpose() * WN;
  const Eigen::Matrix<double, 4, kRows> H_oc = H - (H * N) * NtWN.ldlt().solve(WN.transpose());
  *H_v = H_oc.leftCols<kPose>();
  *H_L = H_oc.rightCols<3>();
}

TiltDirections tiltDirections(const EstimatedPose& x, const Eigen::Vector3d& p_ref) {
  TiltDirections n = TiltDirections::Zero();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(i);
    // Exp(α a) R = R Exp(α Rᵀa): the body turns by Rᵀa; body velocity does not change.
    const Eigen::Vector3d turn_B = x.R_BtoN.transpose() * axis;
    n.block<3, 1>(vehicle::kPosition, i) = axis.cross(x.p_BinN);
    n.block<3, 1>(vehicle::kAttitude, i) =
        x.attitude == vehicle::Attitude::kEuler ? eulerRates(x.euler, turn_B) : turn_B;
    n.block<3, 1>(kObservedPoseEntries, i) = axis.cross(p_ref);
  }
  return n;
}

}  // namespace cvslam
