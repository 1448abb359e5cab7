#include "cvslam/slam/observability_constraint.h"

#include <Eigen/Cholesky>

#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

Eigen::Vector3d yawDirectionOfPoint(const Eigen::Vector3d& p) {
  return {-p.y(), p.x(), 0.0};  // e3 × p
}

void constrainStereoJacobian(const Eigen::VectorXd& u_v, const Eigen::Vector3d& u_L,
                             StereoCamera::Matrix4x9d* H_v, StereoCamera::Matrix4x3d* H_L) {
  constexpr int kPose = 9, kRows = kPose + 3;
  Eigen::Matrix<double, kRows, 4> N = Eigen::Matrix<double, kRows, 4>::Zero();
  N.block<3, 3>(vehicle::kPosition, 0).setIdentity();
  N.block<3, 3>(kPose, 0).setIdentity();
  N.block<kPose, 1>(0, 3) = u_v.head<kPose>();
  N.block<3, 1>(kPose, 3) = u_L;
  Eigen::Matrix<double, 4, kRows> H;
  H << *H_v, *H_L;
  // N has full column rank: the yaw column has a unit ψ entry the translation columns lack.
  const Eigen::Matrix4d NtN = N.transpose() * N;
  const Eigen::Matrix<double, 4, kRows> H_oc = H - (H * N) * NtN.ldlt().solve(N.transpose());
  *H_v = H_oc.leftCols<kPose>();
  *H_L = H_oc.rightCols<3>();
}

void constrainStereoJacobianAttitude(const Eigen::VectorXd& u_v, const Eigen::Vector3d& u_L,
                                     StereoCamera::Matrix4x9d* H_v, StereoCamera::Matrix4x3d* H_L) {
  const Eigen::Matrix<double, 4, 3> translation = H_v->middleCols<3>(vehicle::kPosition) + *H_L;
  H_v->middleCols<3>(vehicle::kPosition) -= 0.5 * translation;
  *H_L -= 0.5 * translation;
  const Eigen::Vector4d yaw = *H_v * u_v.head<vehicle::kSizeNoBias>() + *H_L * u_L;
  const Eigen::Vector3d u_att = u_v.segment<3>(vehicle::kAttitude);
  H_v->middleCols<3>(vehicle::kAttitude) -= yaw * u_att.transpose() / u_att.squaredNorm();
}

Eigen::Vector3d moveYawDirection(const Eigen::Vector3d& u_position, const LoopAlignment& fit) {
  // u = e3 × p = (−p_y, p_x, 0): recover p's horizontal part, move it, rebuild u.
  const Eigen::Vector3d p(u_position.y(), -u_position.x(), fit.pivot.z());
  return yawDirectionOfPoint(fit.apply(p));
}

}  // namespace cvslam
