#include "cvslam/merge/frame_relation.h"

#include <cmath>

#include "cvslam/geometry/euler.h"

namespace cvslam::merge {

namespace {

Eigen::Matrix3d yawRotation(double yaw) {
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  Eigen::Matrix3d R;
  R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  return R;
}

// dR_z/dψ.
Eigen::Matrix3d yawRotationDerivative(double yaw) {
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  Eigen::Matrix3d D;
  D << -s, -c, 0.0, c, -s, 0.0, 0.0, 0.0, 0.0;
  return D;
}

}  // namespace

Eigen::Matrix3d FrameRelation::rotation() const {
  return yawRotation(yaw());
}

Eigen::Vector3d FrameRelation::apply(const Eigen::Vector3d& p_B, Matrix34d* J_x,
                                     Eigen::Matrix3d* J_p) const {
  const Eigen::Matrix3d R = rotation();
  if (J_x != nullptr) {
    J_x->leftCols<3>().setIdentity();
    J_x->col(3) = yawRotationDerivative(yaw()) * p_B;
  }
  if (J_p != nullptr) *J_p = R;
  return R * p_B + translation();
}

void FrameRelation::applyWithCovariance(const Eigen::Vector3d& p_B, const Eigen::Matrix3d& C_B,
                                        Eigen::Vector3d* p_A, Eigen::Matrix3d* C_A) const {
  Matrix34d J_x;
  Eigen::Matrix3d J_p;
  *p_A = apply(p_B, &J_x, &J_p);
  *C_A = J_p * C_B * J_p.transpose() + J_x * P * J_x.transpose();
}

FrameRelation FrameRelation::inverse() const {
  // x' = [−R(−ψ) t, −ψ]; ∂t'/∂t = −R(−ψ), ∂t'/∂ψ = (dR/dψ at −ψ) t, ∂ψ'/∂ψ = −1.
  FrameRelation inv;
  const Eigen::Matrix3d Rt = yawRotation(-yaw());
  inv.x.head<3>() = -Rt * translation();
  inv.x(3) = wrapAngle(-yaw());
  Matrix4d J = Matrix4d::Zero();
  J.topLeftCorner<3, 3>() = -Rt;
  J.block<3, 1>(0, 3) = yawRotationDerivative(-yaw()) * translation();
  J(3, 3) = -1.0;
  inv.P = J * P * J.transpose();
  return inv;
}

FrameRelation FrameRelation::compose(const FrameRelation& b_from_c) const {
  // x_AC = [R_AB t_BC + t_AB, ψ_AB + ψ_BC].
  FrameRelation out;
  Matrix34d J_this;
  Eigen::Matrix3d J_t;
  out.x.head<3>() = apply(b_from_c.translation(), &J_this, &J_t);
  out.x(3) = wrapAngle(yaw() + b_from_c.yaw());
  Matrix4d J_a = Matrix4d::Zero();  // with respect to this relation
  J_a.topRows<3>() = J_this;
  J_a(3, 3) = 1.0;
  Matrix4d J_b = Matrix4d::Zero();  // with respect to b_from_c
  J_b.topLeftCorner<3, 3>() = J_t;
  J_b(3, 3) = 1.0;
  out.P = J_a * P * J_a.transpose() + J_b * b_from_c.P * J_b.transpose();
  return out;
}

FrameRelation::Vector4d relationDifference(const FrameRelation::Vector4d& x1,
                                           const FrameRelation::Vector4d& x2) {
  FrameRelation::Vector4d d = x1 - x2;
  d(3) = wrapAngle(d(3));
  return d;
}

}  // namespace cvslam::merge
