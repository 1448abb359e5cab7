#include "cvslam/ins/gps_observation.h"

#include <ceres/jet.h>

#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"

namespace cvslam {

namespace {
/// ∂(R(e) v)/∂e for ZYX Euler angles e, by forward-mode automatic differentiation of the
/// rotation the INS uses (geometry/euler.h).
Eigen::Matrix3d eulerVelocityJacobian(const Eigen::Vector3d& euler, const Eigen::Vector3d& v_B) {
  using Jet = ceres::Jet<double, 3>;
  Eigen::Matrix<Jet, 3, 1> e;
  for (int i = 0; i < 3; ++i) e(i) = Jet(euler(i), i);
  const Eigen::Matrix<Jet, 3, 1> v_N = rotationBodyToNav(e) * v_B.cast<Jet>();
  Eigen::Matrix3d J;
  for (int r = 0; r < 3; ++r) J.row(r) = v_N(r).v.transpose();
  return J;
}
}  // namespace

GpsVector gpsPrediction(const EstimatedPose& pose) {
  GpsVector h;
  h << pose.p_BinN, pose.R_BtoN * pose.v_B;
  return h;
}

GpsJacobian gpsJacobian(const EstimatedPose& pose) {
  GpsJacobian J = GpsJacobian::Zero();
  J.block<3, 3>(0, vehicle::kPosition).setIdentity();
  J.block<3, 3>(3, vehicle::kVelocity) = pose.R_BtoN;
  J.block<3, 3>(3, vehicle::kAttitude) =
      pose.attitude == vehicle::Attitude::kEuler
          ? eulerVelocityJacobian(pose.euler, pose.v_B)
          : Eigen::Matrix3d(-pose.R_BtoN * so3::skew(Eigen::Vector3d(pose.v_B)));
  return J;
}

GpsVector gpsMeasurement(const GpsFix& fix) {
  GpsVector z;
  z << fix.p_N, fix.v_N;
  return z;
}

Eigen::Matrix<double, kGpsObservationSize, kGpsObservationSize> gpsCovariance(const GpsFix& fix) {
  GpsVector d;
  d << fix.sigma_p.cwiseAbs2(), fix.sigma_v.cwiseAbs2();
  return d.asDiagonal();
}

}  // namespace cvslam
