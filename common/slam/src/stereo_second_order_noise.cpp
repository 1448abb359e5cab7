#include "cvslam/slam/stereo_second_order_noise.h"

#include <array>

#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {
namespace {

using Matrix4x12d = Eigen::Matrix<double, 4, 12>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// [∂z/∂pose ∂z/∂p_L] at the pose moved by d (its first 9 entries, in the pose's coordinates)
/// and the landmark moved by the last 3.
Matrix4x12d jacobianAt(const StereoCamera& camera, const EstimatedPose& pose,
                       const Eigen::Vector3d& p_LinN, const Eigen::Matrix<double, 12, 1>& d) {
  EstimatedPose moved = pose;
  moved.p_BinN += d.segment<3>(vehicle::kPosition);
  moved.v_B += d.segment<3>(vehicle::kVelocity);
  const Eigen::Vector3d dth = d.segment<3>(vehicle::kAttitude);
  if (pose.attitude == vehicle::Attitude::kEuler) {
    moved.euler += dth;
    moved.R_BtoN = rotationBodyToNav(moved.euler);
  } else {
    moved.R_BtoN = pose.R_BtoN * so3::exp(dth);
  }
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  camera.project(moved, p_LinN + d.tail<3>(), &dz_dxv, &dz_dpL);
  Matrix4x12d J;
  J << dz_dxv, dz_dpL;
  return J;
}

}  // namespace

StereoSecondOrderTerms stereoSecondOrderTerms(const StereoCamera& camera, const EstimatedPose& pose,
                                              const Eigen::Vector3d& p_LinN, const Matrix12d& P) {
  // Central differences of the Jacobian: column k of ∇²h_i is ∂(row i of J)/∂x_k. The step
  // is small against every state's scale (metres, radians) and large against rounding.
  constexpr double kStep = 1e-5;
  std::array<Matrix12d, 4> hessian;
  for (int k = 0; k < 12; ++k) {
    Eigen::Matrix<double, 12, 1> d = Eigen::Matrix<double, 12, 1>::Zero();
    d(k) = kStep;
    const Matrix4x12d dJ =
        (jacobianAt(camera, pose, p_LinN, d) - jacobianAt(camera, pose, p_LinN, -d)) /
        (2.0 * kStep);
    for (int i = 0; i < 4; ++i) hessian[static_cast<std::size_t>(i)].col(k) = dJ.row(i).transpose();
  }
  // Symmetrised: the error-state attitude's Hessian of the Jacobian carries an antisymmetric
  // part (Exp(d + δ) ≠ Exp(d) Exp(δ)) that a quadratic form does not see.
  StereoSecondOrderTerms terms;
  std::array<Matrix12d, 4> HP;
  for (std::size_t i = 0; i < 4; ++i) {
    const Matrix12d symmetric = 0.5 * (hessian[i] + hessian[i].transpose());
    HP[i] = symmetric * P;
    terms.mean(static_cast<int>(i)) = 0.5 * HP[i].trace();
  }
  Eigen::Matrix4d& delta = terms.noise;
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      // tr(A B) without forming A B.
      const double t = (HP[static_cast<std::size_t>(i)].array() *
                        HP[static_cast<std::size_t>(j)].transpose().array())
                           .sum();
      delta(i, j) = delta(j, i) = 0.5 * t;
    }
  }
  return terms;
}

}  // namespace cvslam
