#pragma once
// The relation between two agents' navigation frames. Each agent estimates in its own
// gravity-aligned NED frame (its IMU fixes roll and pitch), so two frames differ by a yaw
// about the common down axis and a translation: 4 degrees of freedom.
//
//   p_A = R_z(ψ) p_B + t,   x = [t_N, t_E, t_D, ψ],   R_z(ψ) = [c −s 0; s c 0; 0 0 1]
//
// maps a point of frame B into frame A. The covariance P (4×4) is that of x; a point carried
// across (apply) gets the relation's uncertainty added through the Jacobians below, so that
// a landmark sent to a peer keeps a consistent covariance in the receiver's frame.

#include <Eigen/Core>

namespace cvslam::merge {

struct FrameRelation {
  using Vector4d = Eigen::Matrix<double, 4, 1>;
  using Matrix4d = Eigen::Matrix<double, 4, 4>;
  using Matrix34d = Eigen::Matrix<double, 3, 4>;

  Vector4d x = Vector4d::Zero();  ///< [t_N, t_E, t_D (m), ψ (rad, wrapped to (−π, π])]
  Matrix4d P = Matrix4d::Zero();  ///< covariance of x

  Eigen::Vector3d translation() const { return x.head<3>(); }
  double yaw() const { return x(3); }
  Eigen::Matrix3d rotation() const;

  /// p_A = R_z(ψ) p_B + t. Optional Jacobians with respect to x (3×4) and to p_B (3×3).
  Eigen::Vector3d apply(const Eigen::Vector3d& p_B, Matrix34d* J_x = nullptr,
                        Eigen::Matrix3d* J_p = nullptr) const;
  /// A point of B with covariance C_B, carried into A: C_A = J_p C_B J_pᵀ + J_x P J_xᵀ (the
  /// point's and the relation's errors independent).
  void applyWithCovariance(const Eigen::Vector3d& p_B, const Eigen::Matrix3d& C_B,
                           Eigen::Vector3d* p_A, Eigen::Matrix3d* C_A) const;

  /// The relation of A in B (p_B = R_z(−ψ)(p_A − t)), covariance propagated to first order.
  FrameRelation inverse() const;
  /// This (B → A) after `b_from_c` (C → B): C → A, the two relations' errors independent.
  FrameRelation compose(const FrameRelation& b_from_c) const;
};

/// x1 − x2 with the yaw difference wrapped to (−π, π].
FrameRelation::Vector4d relationDifference(const FrameRelation::Vector4d& x1,
                                           const FrameRelation::Vector4d& x2);

}  // namespace cvslam::merge
