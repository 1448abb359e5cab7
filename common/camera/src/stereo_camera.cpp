#include "cvslam/camera/stereo_camera.h"

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <sstream>

#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/io/config_node.h"

namespace cvslam {
namespace {

/// Partial derivatives of R_NtoB = R_x(φ) R_y(θ) R_z(ψ) (euler.h) w.r.t. φ, θ, ψ.
/// Written from the three elementary frame rotations so each factor stays readable.
std::array<Eigen::Matrix3d, 3> dRotationNavToBody_dEuler(const Eigen::Vector3d& euler) {
  const double cr = std::cos(euler(0)), sr = std::sin(euler(0));
  const double cp = std::cos(euler(1)), sp = std::sin(euler(1));
  const double cy = std::cos(euler(2)), sy = std::sin(euler(2));
  Eigen::Matrix3d Rx, Ry, Rz, dRx, dRy, dRz;
  Rx << 1, 0, 0, 0, cr, sr, 0, -sr, cr;
  Ry << cp, 0, -sp, 0, 1, 0, sp, 0, cp;
  Rz << cy, sy, 0, -sy, cy, 0, 0, 0, 1;
  dRx << 0, 0, 0, 0, -sr, cr, 0, -cr, -sr;
  dRy << -sp, 0, -cp, 0, 0, 0, cp, 0, -sp;
  dRz << -sy, cy, 0, -cy, -sy, 0, 0, 0, 0;
  return {dRx * Ry * Rz, Rx * dRy * Rz, Rx * Ry * dRz};
}

}  // namespace

Status StereoCameraOptions::load(const ConfigNode& node) {
  node.get("fx", fx);
  node.get("fy", fy);
  node.get("cx", cx);
  node.get("cy", cy);
  node.get("width", width);
  node.get("height", height);
  node.get("baseline", baseline);
  node.get("R_BtoC", R_BtoC);
  node.get("p_CinB", p_CinB);
  node.get("min_depth", min_depth);
  node.get("min_disparity", min_disparity);
  node.check(fx > 0 && fy > 0, "fx", "focal lengths must be > 0");
  node.check(width > 0 && height > 0, "width", "image size must be > 0");
  node.check(baseline > 0, "baseline", "must be > 0");
  node.check(min_depth > 0, "min_depth", "must be > 0");
  node.check(min_disparity > 0, "min_disparity", "must be > 0");
  node.check((R_BtoC * R_BtoC.transpose()).isIdentity(1e-6) && R_BtoC.determinant() > 0, "R_BtoC",
             "must be a rotation matrix");
  return node.status();
}

Eigen::Vector3d StereoCamera::landmarkInCamera(const EstimatedPose& pose,
                                               const Eigen::Vector3d& p_LinN, Matrix3x9d* dpC_dxv,
                                               Eigen::Matrix3d* dpC_dpL) const {
  const bool euler = pose.attitude == vehicle::Attitude::kEuler;
  // Euler: R from the angles, as the thesis's model (bit-identical to it).
  const Eigen::Matrix3d R_NtoB =
      euler ? rotationNavToBody(pose.euler) : Eigen::Matrix3d(pose.R_BtoN.transpose());
  const Eigen::Vector3d d_N = p_LinN - pose.p_BinN;  // landmark relative to the body, in N
  const Eigen::Matrix3d R_NtoC = o_.R_BtoC * R_NtoB;
  if (dpC_dxv) {
    dpC_dxv->setZero();
    dpC_dxv->block<3, 3>(0, vehicle::kPosition) = -R_NtoC;
    if (euler) {
      const auto dR = dRotationNavToBody_dEuler(pose.euler);
      for (int i = 0; i < 3; ++i) dpC_dxv->col(vehicle::kAttitude + i) = o_.R_BtoC * dR[i] * d_N;
    } else {
      // R_NtoB(δθ) = Exp(−δθ) R̂ᵀ: ∂(R_NtoB d_N)/∂δθ = [R̂ᵀ d_N]×.
      dpC_dxv->block<3, 3>(0, vehicle::kAttitude) = o_.R_BtoC * so3::skew<double>(R_NtoB * d_N);
    }
  }
  if (dpC_dpL) *dpC_dpL = R_NtoC;
  return o_.R_BtoC * (R_NtoB * d_N - o_.p_CinB);
}

Eigen::Vector3d StereoCamera::landmarkInCamera(const Eigen::Vector3d& p_BinN,
                                               const Eigen::Vector3d& euler,
                                               const Eigen::Vector3d& p_LinN, Matrix3x9d* dpC_dxv,
                                               Eigen::Matrix3d* dpC_dpL) const {
  Vector9d x = Vector9d::Zero();
  x << p_BinN, Eigen::Vector3d::Zero(), euler;
  return landmarkInCamera(EstimatedPose::fromEuler(x), p_LinN, dpC_dxv, dpC_dpL);
}

Eigen::Vector4d StereoCamera::project(const Eigen::Vector3d& p_LinC, Matrix4x3d* dz_dpC) const {
  const double inv_z = 1.0 / p_LinC.z();
  const double u_l = o_.fx * p_LinC.x() * inv_z + o_.cx;
  const double v = o_.fy * p_LinC.y() * inv_z + o_.cy;
  const double u_r = o_.fx * (p_LinC.x() - o_.baseline) * inv_z + o_.cx;
  if (dz_dpC) {
    const double inv_z2 = inv_z * inv_z;
    // Rows: d/d[x y z] of each pixel coordinate of eq. 5.20.
    *dz_dpC << o_.fx * inv_z, 0.0, -o_.fx * p_LinC.x() * inv_z2,           //
        0.0, o_.fy * inv_z, -o_.fy * p_LinC.y() * inv_z2,                  //
        o_.fx * inv_z, 0.0, -o_.fx * (p_LinC.x() - o_.baseline) * inv_z2,  //
        0.0, o_.fy * inv_z, -o_.fy * p_LinC.y() * inv_z2;
  }
  return {u_l, v, u_r, v};
}

Eigen::Vector4d StereoCamera::project(const EstimatedPose& pose, const Eigen::Vector3d& p_LinN,
                                      Matrix4x9d* dz_dxv, Matrix4x3d* dz_dpL) const {
  Matrix3x9d dpC_dxv;
  Eigen::Matrix3d dpC_dpL;
  const bool need_chain = dz_dxv || dz_dpL;
  const Eigen::Vector3d p_LinC = landmarkInCamera(pose, p_LinN, need_chain ? &dpC_dxv : nullptr,
                                                  need_chain ? &dpC_dpL : nullptr);
  Matrix4x3d dz_dpC;
  const Eigen::Vector4d z = project(p_LinC, need_chain ? &dz_dpC : nullptr);
  if (dz_dxv) *dz_dxv = dz_dpC * dpC_dxv;
  if (dz_dpL) *dz_dpL = dz_dpC * dpC_dpL;
  return z;
}

Eigen::Vector4d StereoCamera::project(const Vector9d& x_v, const Eigen::Vector3d& p_LinN,
                                      Matrix4x9d* dz_dxv, Matrix4x3d* dz_dpL) const {
  return project(EstimatedPose::fromEuler(x_v), p_LinN, dz_dxv, dz_dpL);
}

bool StereoCamera::isVisible(const Eigen::Vector3d& p_LinC) const {
  if (!(p_LinC.z() >= o_.min_depth)) return false;
  const Eigen::Vector4d z = project(p_LinC);
  const auto inside = [&](double u, double v) {
    return u >= 0.0 && u < o_.width && v >= 0.0 && v < o_.height;
  };
  return inside(z(0), z(1)) && inside(z(2), z(3));
}

Status StereoCamera::triangulateInCamera(const Eigen::Vector4d& z, Eigen::Vector3d* p_LinC,
                                         Matrix3x4d* dpC_dz) const {
  if (!z.allFinite()) return Status::Error("triangulate: non-finite pixel coordinates");
  const double d = z(0) - z(2);  // disparity u_L − u_R
  if (!(d >= o_.min_disparity)) {
    std::ostringstream os;
    os << "triangulate: disparity " << d << " px is below min_disparity " << o_.min_disparity
       << " px (point at infinity or behind the cameras)";
    return Status::Error(os.str());
  }
  // Rectified rows agree up to noise: the mean row halves its variance.
  const double v = 0.5 * (z(1) + z(3));
  const double du = z(0) - o_.cx;
  const double dv = v - o_.cy;
  const double b_d = o_.baseline / d;
  const double fxy = o_.fx / o_.fy;
  if (p_LinC) *p_LinC = {du * b_d, fxy * dv * b_d, o_.fx * b_d};
  if (dpC_dz) {
    // ∂d/∂z = [1 0 −1 0], ∂(b/d)/∂d = −b/d², ∂v̄/∂z = [0 ½ 0 ½].
    const double b_d2 = b_d / d;
    *dpC_dz << b_d - du * b_d2, 0.0, du * b_d2, 0.0,                          //
        -fxy * dv * b_d2, 0.5 * fxy * b_d, fxy * dv * b_d2, 0.5 * fxy * b_d,  //
        -o_.fx * b_d2, 0.0, o_.fx * b_d2, 0.0;
  }
  return Status::Ok();
}

Status StereoCamera::triangulate(const Eigen::Vector4d& z, const EstimatedPose& pose,
                                 Eigen::Vector3d* p_LinN, Matrix3x9d* dpL_dxv,
                                 Matrix3x4d* dpL_dz) const {
  Eigen::Vector3d p_LinC;
  Matrix3x4d dpC_dz;
  if (Status s = triangulateInCamera(z, &p_LinC, &dpC_dz); !s.ok()) return s;
  const bool euler = pose.attitude == vehicle::Attitude::kEuler;
  const Eigen::Matrix3d R_BtoN = euler ? rotationBodyToNav(pose.euler) : pose.R_BtoN;
  // Landmark relative to the body origin, in B (inverse of landmarkInCamera).
  const Eigen::Vector3d p_LinB = o_.R_BtoC.transpose() * p_LinC + o_.p_CinB;
  if (p_LinN) *p_LinN = pose.p_BinN + R_BtoN * p_LinB;
  if (dpL_dxv) {
    dpL_dxv->setZero();
    dpL_dxv->block<3, 3>(0, vehicle::kPosition).setIdentity();
    if (euler) {
      const auto dR = dRotationNavToBody_dEuler(pose.euler);  // R_BtoN = R_NtoBᵀ
      for (int i = 0; i < 3; ++i) dpL_dxv->col(vehicle::kAttitude + i) = dR[i].transpose() * p_LinB;
    } else {
      // R̂ Exp(δθ) p_LinB: ∂/∂δθ = −R̂ [p_LinB]×.
      dpL_dxv->block<3, 3>(0, vehicle::kAttitude) = -R_BtoN * so3::skew<double>(p_LinB);
    }
  }
  if (dpL_dz) *dpL_dz = R_BtoN * o_.R_BtoC.transpose() * dpC_dz;
  return Status::Ok();
}

Status StereoCamera::triangulate(const Eigen::Vector4d& z, const Vector9d& x_v,
                                 Eigen::Vector3d* p_LinN, Matrix3x9d* dpL_dxv,
                                 Matrix3x4d* dpL_dz) const {
  return triangulate(z, EstimatedPose::fromEuler(x_v), p_LinN, dpL_dxv, dpL_dz);
}

}  // namespace cvslam
