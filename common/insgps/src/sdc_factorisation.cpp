#include "cvslam/insgps/sdc_factorisation.h"

#include <cmath>

#include "cvslam/geometry/euler.h"
#include "cvslam/ins/ins_propagator.h"

namespace cvslam::insgps {

Eigen::Matrix3d staircaseSdc(const AttitudeFunction& c, const Eigen::Vector3d& e,
                             const std::array<int, 3>& order, const SdcOptions& o) {
  Eigen::Matrix3d C;
  Eigen::Vector3d partial = Eigen::Vector3d::Zero();
  Eigen::Vector3d c_prev = c(partial);
  for (int j : order) {
    const double ej = e(j);
    if (std::abs(ej) < o.small_coordinate) {
      Eigen::Vector3d plus = partial, minus = partial;
      plus(j) += o.derivative_step;
      minus(j) -= o.derivative_step;
      C.col(j) = (c(plus) - c(minus)) / (2.0 * o.derivative_step);
      partial(j) = ej;
      // The telescoping continues from c on the true path (error O(e_j²) for this column).
      c_prev = c(partial);
      continue;
    }
    partial(j) = ej;
    const Eigen::Vector3d c_next = c(partial);
    C.col(j) = (c_next - c_prev) / ej;
    c_prev = c_next;
  }
  return C;
}

StateVector insDynamics(const StateVector& x, const ImuSample& s, double gravity) {
  const Eigen::Matrix<double, kNoiseSize, 1> w = Eigen::Matrix<double, kNoiseSize, 1>::Zero();
  return InsPropagator::dynamics<double, kStateSize>(x, s.gyro_B, s.accel_B, w, gravity);
}

InsSdc insSdc(const StateVector& x, const ImuSample& s, double gravity, double alpha,
              const SdcOptions& o) {
  using vehicle::kAttitude;
  using vehicle::kPosition;
  using vehicle::kVelocity;
  const Eigen::Vector3d e = x.segment<3>(kAttitude);
  const Eigen::Vector3d g_N(0.0, 0.0, gravity);
  const Eigen::Vector3d omega = s.gyro_B;
  const AttitudeFunction c_g = [&](const Eigen::Vector3d& a) {
    return Eigen::Vector3d(rotationNavToBody(a) * g_N - g_N);
  };
  const AttitudeFunction c_E = [&](const Eigen::Vector3d& a) {
    return Eigen::Vector3d(eulerRates(a, omega) - omega);
  };
  auto mixed = [&](const AttitudeFunction& c) {
    return Eigen::Matrix3d(alpha * staircaseSdc(c, e, kForwardOrder, o) +
                           (1.0 - alpha) * staircaseSdc(c, e, kReverseOrder, o));
  };
  InsSdc out;
  const Eigen::Matrix3d R_BtoN = rotationBodyToNav(e);
  out.A.setZero();
  out.A.block<3, 3>(kPosition, kVelocity) = R_BtoN;
  out.A.block<3, 3>(kVelocity, kVelocity) << 0.0, omega.z(), -omega.y(), -omega.z(), 0.0, omega.x(),
      omega.y(), -omega.x(), 0.0;
  out.A.block<3, 3>(kVelocity, kAttitude) = mixed(c_g);
  out.A.block<3, 3>(kAttitude, kAttitude) = mixed(c_E);
  out.b.setZero();
  out.b.segment<3>(kVelocity) = s.accel_B + g_N;
  out.b.segment<3>(kAttitude) = omega;
  out.H.setZero();
  out.H.block<3, 3>(0, kPosition).setIdentity();
  out.H.block<3, 3>(3, kVelocity) = R_BtoN;
  return out;
}

}  // namespace cvslam::insgps
