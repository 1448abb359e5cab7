#include "cvslam/insgps/gps_measurement.h"

#include <ceres/jet.h>

#include "cvslam/geometry/euler.h"

namespace cvslam::insgps {

StateVector stateDifference(const StateVector& a, const StateVector& b) {
  StateVector d = a - b;
  for (int i = 0; i < 3; ++i) d(vehicle::kAttitude + i) = wrapAngle(d(vehicle::kAttitude + i));
  return d;
}

StateVector wrapYaw(StateVector x) {
  x(vehicle::kAttitude + 2) = wrapAngle(x(vehicle::kAttitude + 2));
  return x;
}

MeasVector gpsPredicted(const StateVector& x) {
  const Eigen::Vector3d euler = x.segment<3>(vehicle::kAttitude);
  MeasVector y;
  y.head<3>() = x.segment<3>(vehicle::kPosition);
  y.tail<3>() = rotationBodyToNav(euler) * x.segment<3>(vehicle::kVelocity);
  return y;
}

MeasJacobian gpsJacobian(const StateVector& x) {
  using Jet = ceres::Jet<double, 3>;
  Eigen::Matrix<Jet, 3, 1> a;
  for (int i = 0; i < 3; ++i) a(i) = Jet(x(vehicle::kAttitude + i), i);
  const Eigen::Matrix<Jet, 3, 3> R = rotationBodyToNav(a);
  const Eigen::Matrix<Jet, 3, 1> v_N = R * x.segment<3>(vehicle::kVelocity).cast<Jet>();
  MeasJacobian H = MeasJacobian::Zero();
  H.block<3, 3>(0, vehicle::kPosition).setIdentity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H(3 + r, vehicle::kVelocity + c) = R(r, c).a;
    H.block<1, 3>(3 + r, vehicle::kAttitude) = v_N(r).v.transpose();
  }
  return H;
}

MeasVector gpsMeasurement(const GpsFix& fix) {
  MeasVector y;
  y << fix.p_N, fix.v_N;
  return y;
}

MeasMatrix gpsCovariance(const GpsFix& fix) {
  MeasVector d;
  d << fix.sigma_p.cwiseAbs2(), fix.sigma_v.cwiseAbs2();
  return d.asDiagonal();
}

}  // namespace cvslam::insgps
