#pragma once
// ZYX Euler angles and direction cosine matrices (thesis §2.3.2, docs/conventions.md).
//
// Frames: navigation N is NED, body B is FRD. Euler angles e = [φ θ ψ] (roll, pitch, yaw).
// R_NtoB = C_bn = R_x(φ) R_y(θ) R_z(ψ) with the *frame* rotations
//   R_x(φ) = [1 0 0; 0 cφ sφ; 0 −sφ cφ] (and alike for y, z),
// so v_B = R_NtoB v_N. The thesis's eq. 2.8 prints this matrix with misprints in rows 2–3;
// its first row [cθcψ, cθsψ, −sθ] agrees with ours. R_BtoN = R_NtoBᵀ (eq. 2.7).
// Everything is templated on the scalar so that ceres::Jet can differentiate it.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace cvslam {

/// R_NtoB (C_bn): rotates a vector expressed in NED into the body frame.
template <typename T>
Eigen::Matrix<T, 3, 3> rotationNavToBody(const Eigen::Matrix<T, 3, 1>& euler) {
  using std::cos;
  using std::sin;
  const T cr = cos(euler(0)), sr = sin(euler(0));
  const T cp = cos(euler(1)), sp = sin(euler(1));
  const T cy = cos(euler(2)), sy = sin(euler(2));
  Eigen::Matrix<T, 3, 3> R;
  R(0, 0) = cp * cy;
  R(0, 1) = cp * sy;
  R(0, 2) = -sp;
  R(1, 0) = sr * sp * cy - cr * sy;
  R(1, 1) = sr * sp * sy + cr * cy;
  R(1, 2) = sr * cp;
  R(2, 0) = cr * sp * cy + sr * sy;
  R(2, 1) = cr * sp * sy - sr * cy;
  R(2, 2) = cr * cp;
  return R;
}

/// R_BtoN = C_bnᵀ: rotates a body-frame vector into NED.
template <typename T>
Eigen::Matrix<T, 3, 3> rotationBodyToNav(const Eigen::Matrix<T, 3, 1>& euler) {
  return rotationNavToBody(euler).transpose();
}

/// Euler-angle rates from body rates ω = [p q r] (thesis eq. 2.4). Singular at θ = ±90°.
template <typename T>
Eigen::Matrix<T, 3, 1> eulerRates(const Eigen::Matrix<T, 3, 1>& euler,
                                  const Eigen::Matrix<T, 3, 1>& omega_B) {
  using std::cos;
  using std::sin;
  using std::tan;
  const T cr = cos(euler(0)), sr = sin(euler(0));
  const T cp = cos(euler(1)), tp = tan(euler(1));
  Eigen::Matrix<T, 3, 1> rates;
  rates(0) = omega_B(0) + (sr * omega_B(1) + cr * omega_B(2)) * tp;
  rates(1) = cr * omega_B(1) - sr * omega_B(2);
  rates(2) = (sr * omega_B(1) + cr * omega_B(2)) / cp;
  return rates;
}

/// Euler angles [φ θ ψ] of a rotation R_NtoB (inverse of rotationNavToBody).
inline Eigen::Vector3d eulerFromRotationNavToBody(const Eigen::Matrix3d& R_NtoB) {
  const double pitch = std::asin(std::clamp(-R_NtoB(0, 2), -1.0, 1.0));
  const double roll = std::atan2(R_NtoB(1, 2), R_NtoB(2, 2));
  const double yaw = std::atan2(R_NtoB(0, 1), R_NtoB(0, 0));
  return {roll, pitch, yaw};
}

/// Wraps an angle to (−π, π].
inline double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

}  // namespace cvslam
