#include "cvslam/slam/stereo_second_order_noise.h"

#include <array>

#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {
namespace {

using Matrix4x12d = Eigen::Matrix<double, 4, 12>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;
using AttitudeOffsetMatrix = Eigen::Matrix<double, 6, 6>;  // (attitude, landmark − vehicle)

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

/// The mean term over the right-invariant error (slam_state.h). With R = Exp(ξθ) R̂,
/// p = Exp(ξθ) p̂ + J_l(ξθ) ξp and l = Exp(ξθ) l̂ + J_l(ξθ) ξl, the landmark in the body frame is
/// R̂ᵀ(l̂ − p̂) + R̂ᵀ J_r(ξθ) Δ with Δ = ξl − ξp: ξθ alone (a turn of the whole, the global heading
/// included) does not move it. To second order, with J_r ≈ I − ½[ξθ]× and ∇²_l h the Hessian in
/// the landmark's position (h depends on l − p only),
///   E[h] − h(x̂) = ½ tr(∇²_l h C_ΔΔ) − ½ ∂h/∂l E[ξθ × Δ].
/// In additive coordinates the same heading uncertainty lies along straight lines
/// p̂ + α e3 × p̂, whose curvature in h reads as a mean that grows with the heading's σ².
Eigen::Vector4d invariantMean(const StereoCamera& camera, const EstimatedPose& pose,
                              const Eigen::Vector3d& p_LinN, const AttitudeOffsetMatrix& C,
                              const std::array<AttitudeOffsetMatrix, 4>& hessian) {
  // C is the covariance of the additive (δa, δl − δp); the invariant (ξθ, Δ) is B times them:
  // ξθ = M δa, Δ = δl − δp + (l̂ − p̂) × ξθ (slam_state.h's ξ in the additive errors δ).
  const Eigen::Matrix3d M = vehicle_model::navRotationPerAttitude(pose);
  AttitudeOffsetMatrix B = AttitudeOffsetMatrix::Identity();
  B.topLeftCorner<3, 3>() = M;
  B.bottomLeftCorner<3, 3>() = so3::skew<double>(p_LinN - pose.p_BinN) * M;
  const AttitudeOffsetMatrix C_xi = B * C * B.transpose();
  const Eigen::Matrix3d C_dd = C_xi.bottomRightCorner<3, 3>();
  const Eigen::Matrix3d C_td = C_xi.topRightCorner<3, 3>();
  // E[ξθ × Δ]_i = ε_ijk C_θΔ(j, k).
  const Eigen::Vector3d e_cross(C_td(1, 2) - C_td(2, 1), C_td(2, 0) - C_td(0, 2),
                                C_td(0, 1) - C_td(1, 0));
  StereoCamera::Matrix4x9d dz_dxv;
  StereoCamera::Matrix4x3d dz_dpL;
  camera.project(pose, p_LinN, &dz_dxv, &dz_dpL);
  Eigen::Vector4d mean;
  for (int i = 0; i < 4; ++i) {
    // ∇²_l h is the Δ block (h depends on l − p only).
    const Eigen::Matrix3d H_ll = hessian[static_cast<std::size_t>(i)].bottomRightCorner<3, 3>();
    mean(i) = 0.5 * H_ll.cwiseProduct(C_dd).sum() - 0.5 * dz_dpL.row(i).dot(e_cross);
  }
  return mean;
}

}  // namespace

StereoSecondOrderTerms stereoSecondOrderTerms(const StereoCamera& camera, const EstimatedPose& pose,
                                              const Eigen::Vector3d& p_LinN, const Matrix12d& P,
                                              ErrorChart chart) {
  // h depends on the attitude and on Δ = l − p only (not on the velocity): with y = T δ =
  // (δa, δl − δp), ∇²h_i = Tᵀ G_i T for the 6×6 Hessian G_i in y, so ½ tr(∇²h_i P) = ½ tr(G_i C)
  // and ½ tr(∇²h_i P ∇²h_j P) = ½ tr(G_i C G_j C) with C = T P Tᵀ. G_i's columns are central
  // differences of the Jacobian's (attitude, landmark) columns along the attitude and the
  // landmark; the step is small against every state's scale (metres, radians) and large
  // against rounding.
  constexpr double kStep = 1e-5;
  constexpr int kLandmark = 9;
  std::array<AttitudeOffsetMatrix, 4> hessian;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 12, 1> d = Eigen::Matrix<double, 12, 1>::Zero();
    d(k < 3 ? vehicle::kAttitude + k : kLandmark + k - 3) = kStep;
    const Matrix4x12d dJ =
        (jacobianAt(camera, pose, p_LinN, d) - jacobianAt(camera, pose, p_LinN, -d)) /
        (2.0 * kStep);
    for (std::size_t i = 0; i < 4; ++i) {
      const int row = static_cast<int>(i);
      hessian[i].col(k) << dJ.block<1, 3>(row, vehicle::kAttitude).transpose(),
          dJ.block<1, 3>(row, kLandmark).transpose();
    }
  }
  Eigen::Matrix<double, 6, 12> T = Eigen::Matrix<double, 6, 12>::Zero();
  T.block<3, 3>(0, vehicle::kAttitude).setIdentity();
  T.block<3, 3>(3, vehicle::kPosition) = -Eigen::Matrix3d::Identity();
  T.block<3, 3>(3, kLandmark).setIdentity();
  const AttitudeOffsetMatrix C = T * P * T.transpose();
  // Symmetrised: the error-state attitude's Hessian of the Jacobian carries an antisymmetric
  // part (Exp(d + δ) ≠ Exp(d) Exp(δ)) that a quadratic form does not see.
  StereoSecondOrderTerms terms;
  std::array<AttitudeOffsetMatrix, 4> GC;
  for (std::size_t i = 0; i < 4; ++i) {
    hessian[i] = 0.5 * (hessian[i] + hessian[i].transpose()).eval();
    GC[i] = hessian[i] * C;
  }
  if (chart == ErrorChart::kRightInvariant) {
    terms.mean = invariantMean(camera, pose, p_LinN, C, hessian);
  } else {
    for (int i = 0; i < 4; ++i) terms.mean(i) = 0.5 * GC[static_cast<std::size_t>(i)].trace();
  }
  Eigen::Matrix4d& delta = terms.noise;
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      // tr(A B) without forming A B.
      const double t = (GC[static_cast<std::size_t>(i)].array() *
                        GC[static_cast<std::size_t>(j)].transpose().array())
                           .sum();
      delta(i, j) = delta(j, i) = 0.5 * t;
    }
  }
  return terms;
}

}  // namespace cvslam
