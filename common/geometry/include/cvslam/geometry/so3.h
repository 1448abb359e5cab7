#pragma once
// Rotations as a Lie group (docs/conventions.md): the exponential and logarithm of SO(3) and
// the right Jacobian, for the rotation error state of the INS (ins_propagator.h) and the
// camera model's rotation-based pose (stereo_camera.h).
//
// Perturbations are on the right, in the body frame: R = R̂ · Exp(δθ). Then
//   Exp(φ + dφ) ≈ Exp(φ) Exp(J_r(φ) dφ)                                   (right Jacobian)
// and a rotation R(t) with body rate ω written in the chart around R̂, R = R̂ Exp(φ(t)), obeys
//   φ̇ = J_r(φ)⁻¹ ω.
// Templated on the scalar so that ceres::Jet can differentiate them. Small angles use the
// Taylor series of the coefficients (|φ|² below kSmallAngle2), so a Jet at φ = 0 stays
// finite: the series is accurate to ~|φ|⁶ / 10⁶ there, below double precision.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace cvslam::so3 {

/// |φ|² below which the coefficients use their series (|φ| < 0.01 rad).
constexpr double kSmallAngle2 = 1e-4;

/// [a]×: the cross-product matrix, [a]× b = a × b.
template <typename T>
Eigen::Matrix<T, 3, 3> skew(const Eigen::Matrix<T, 3, 1>& a) {
  Eigen::Matrix<T, 3, 3> S;
  S << T(0.0), -a.z(), a.y(), a.z(), T(0.0), -a.x(), -a.y(), a.x(), T(0.0);
  return S;
}

/// Exp(φ) = I + sin|φ|/|φ| [φ]× + (1 − cos|φ|)/|φ|² [φ]×²   (Rodrigues).
template <typename T>
Eigen::Matrix<T, 3, 3> exp(const Eigen::Matrix<T, 3, 1>& phi) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T a2 = phi.squaredNorm();
  T c1, c2;  // sin(a)/a, (1 − cos a)/a²
  if (a2 < T(kSmallAngle2)) {
    c1 = T(1.0) - a2 / T(6.0) + a2 * a2 / T(120.0);
    c2 = T(0.5) - a2 / T(24.0) + a2 * a2 / T(720.0);
  } else {
    const T a = sqrt(a2);
    c1 = sin(a) / a;
    c2 = (T(1.0) - cos(a)) / a2;
  }
  const Eigen::Matrix<T, 3, 3> S = skew(phi);
  return Eigen::Matrix<T, 3, 3>::Identity() + c1 * S + c2 * S * S;
}

/// Log(R): the rotation vector of R (|φ| ≤ π), via the quaternion (well-conditioned near π).
inline Eigen::Vector3d log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

/// J_r(φ) = I − (1 − cos a)/a² [φ]× + (a − sin a)/a³ [φ]×²,  a = |φ|.
template <typename T>
Eigen::Matrix<T, 3, 3> rightJacobian(const Eigen::Matrix<T, 3, 1>& phi) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T a2 = phi.squaredNorm();
  T c1, c2;
  if (a2 < T(kSmallAngle2)) {
    c1 = T(0.5) - a2 / T(24.0) + a2 * a2 / T(720.0);
    c2 = T(1.0) / T(6.0) - a2 / T(120.0) + a2 * a2 / T(5040.0);
  } else {
    const T a = sqrt(a2);
    c1 = (T(1.0) - cos(a)) / a2;
    c2 = (a - sin(a)) / (a2 * a);
  }
  const Eigen::Matrix<T, 3, 3> S = skew(phi);
  return Eigen::Matrix<T, 3, 3>::Identity() - c1 * S + c2 * S * S;
}

/// J_r(φ)⁻¹ = I + ½[φ]× + (1/a² − (1 + cos a)/(2a sin a)) [φ]×²  (valid for a < π).
template <typename T>
Eigen::Matrix<T, 3, 3> rightJacobianInverse(const Eigen::Matrix<T, 3, 1>& phi) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T a2 = phi.squaredNorm();
  T c2;
  if (a2 < T(kSmallAngle2)) {
    c2 = T(1.0) / T(12.0) + a2 / T(720.0) + a2 * a2 / T(30240.0);
  } else {
    const T a = sqrt(a2);
    c2 = T(1.0) / a2 - (T(1.0) + cos(a)) / (T(2.0) * a * sin(a));
  }
  const Eigen::Matrix<T, 3, 3> S = skew(phi);
  return Eigen::Matrix<T, 3, 3>::Identity() + T(0.5) * S + c2 * S * S;
}

}  // namespace cvslam::so3
