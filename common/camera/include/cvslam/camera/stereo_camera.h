#pragma once
// Rectified pinhole stereo pair rigidly mounted on the vehicle (thesis §5.4, eq. 5.20).
//
// Left camera CL: pinhole (fx, fy, cx, cy); the right camera CR has the same intrinsics and
// sits `baseline` metres along +x of CL (rectified pair). The pair's pose on the body is
// T_BtoC: R_BtoC and p_CinB (left camera centre in the body frame).
//
// Observation of landmark p_LinN from the vehicle pose (ins/estimated_pose.h: p_BinN, R_BtoN):
//   p_LinC = R_BtoC (R_NtoB (p_LinN − p_BinN) − p_CinB)                          (eq. 5.9–5.14)
//   z = [fx x/z + cx, fy y/z + cy, fx (x − b)/z + cx, fy y/z + cy]                   (eq. 5.20)
// The thesis writes eq. 5.20 with the 3×4 matrices I_c (Mh_c^n)^-1 of both cameras; for a
// rectified pair these share the rotation, so the chain above is the same model, factored so
// that the Jacobians compose: dz_dxv = dz_dpC · dpC_dxv.
//
// Inverse observation model (landmark initialisation, docs/conventions.md): stereo triangulation
// from the disparity d = u_L − u_R and the mean row (v_L + v_R)/2:
//   p_LinC = b/d · [u_L − cx, (fx/fy)(v̄ − cy), fx]
//   p_LinN = p_BinN + R_NtoBᵀ (R_BtoCᵀ p_LinC + p_CinB)
// with Jacobians dpL_dxv (3×9) and dpL_dz (3×4) for the augmentation
//   P_LL = J_x P_vv J_xᵀ + J_z R J_zᵀ,  P_Lx = J_x P_v·.
// Jacobians w.r.t. the vehicle have the columns [p_BinN, v_B (zero), attitude], the attitude
// in the pose's coordinates: Euler angles (the thesis's model, evaluated from the angles) or
// the rotation error δθ of R = R_BtoN · Exp(δθ) at δθ = 0 (docs/filter.md). The overloads
// taking a 9-vector [p_BinN, v_B, φ θ ψ] are the Euler pose.

#include <Eigen/Core>
#include <optional>

#include "cvslam/core/status.h"
#include "cvslam/ins/estimated_pose.h"

namespace cvslam {

class ConfigNode;

struct StereoCameraOptions {
  double fx = 560.0;       ///< focal length [px] (thesis Table 5.6: α ≈ 560)
  double fy = 560.0;       ///< focal length [px]
  double cx = 160.0;       ///< principal point [px]
  double cy = 120.0;       ///< principal point [px]
  int width = 320;         ///< image width [px]
  int height = 240;        ///< image height [px]
  double baseline = 0.20;  ///< distance between the optical centres [m]
  /// R_BtoC, row-major in config. Default: looking down, image top towards the nose
  /// (x_C = right wing, y_C = tail, z_C = down).
  Eigen::Matrix3d R_BtoC = (Eigen::Matrix3d() << 0, 1, 0, -1, 0, 0, 0, 0, 1).finished();
  Eigen::Vector3d p_CinB = Eigen::Vector3d::Zero();  ///< left camera centre in the body [m]
  double min_depth = 0.5;  ///< points nearer than this along z_C are not observable [m]
  /// Triangulation refuses disparities below this [px] (zero or negative: point at or
  /// behind infinity; tiny: depth and its Jacobian explode).
  double min_disparity = 1e-3;

  Status load(const ConfigNode& node);
};

class StereoCamera {
 public:
  using Vector9d = Eigen::Matrix<double, 9, 1>;
  using Matrix4x3d = Eigen::Matrix<double, 4, 3>;
  using Matrix4x9d = Eigen::Matrix<double, 4, 9>;
  using Matrix3x9d = Eigen::Matrix<double, 3, 9>;
  using Matrix3x4d = Eigen::Matrix<double, 3, 4>;

  explicit StereoCamera(const StereoCameraOptions& options = {}) : o_(options) {}
  const StereoCameraOptions& options() const { return o_; }

  /// Landmark in the left camera frame. Optional Jacobians w.r.t. the vehicle pose
  /// [p_BinN, v_B, attitude] (velocity columns zero) and w.r.t. p_LinN.
  Eigen::Vector3d landmarkInCamera(const EstimatedPose& pose, const Eigen::Vector3d& p_LinN,
                                   Matrix3x9d* dpC_dxv = nullptr,
                                   Eigen::Matrix3d* dpC_dpL = nullptr) const;
  /// The same for the Euler pose [p_BinN, ·, euler].
  Eigen::Vector3d landmarkInCamera(const Eigen::Vector3d& p_BinN, const Eigen::Vector3d& euler,
                                   const Eigen::Vector3d& p_LinN, Matrix3x9d* dpC_dxv = nullptr,
                                   Eigen::Matrix3d* dpC_dpL = nullptr) const;

  /// Predicted measurement z = [u_L v_L u_R v_R] of a point in the left camera frame
  /// (eq. 5.20), with optional dz_dpC (4×3). Does not check visibility.
  Eigen::Vector4d project(const Eigen::Vector3d& p_LinC, Matrix4x3d* dz_dpC = nullptr) const;

  /// Full observation model h(pose, p_LinN) (eq. 5.20) with optional dz_dxv (4×9, columns
  /// [p_BinN, v_B, attitude], velocity columns zero) and dz_dpL (4×3).
  Eigen::Vector4d project(const EstimatedPose& pose, const Eigen::Vector3d& p_LinN,
                          Matrix4x9d* dz_dxv = nullptr, Matrix4x3d* dz_dpL = nullptr) const;
  /// The same for the Euler pose x_v = [p_BinN, v_B, φ θ ψ].
  Eigen::Vector4d project(const Vector9d& x_v, const Eigen::Vector3d& p_LinN,
                          Matrix4x9d* dz_dxv = nullptr, Matrix4x3d* dz_dpL = nullptr) const;

  /// True when the point is in front of both cameras (depth ≥ min_depth) and projects
  /// inside both images.
  bool isVisible(const Eigen::Vector3d& p_LinC) const;

  /// Triangulates z = [u_L v_L u_R v_R] into the left camera frame, with optional
  /// dpC_dz (3×4). Fails when the disparity u_L − u_R is below min_disparity or z is not
  /// finite.
  Status triangulateInCamera(const Eigen::Vector4d& z, Eigen::Vector3d* p_LinC,
                             Matrix3x4d* dpC_dz = nullptr) const;

  /// Inverse observation model: landmark p_LinN from z and the vehicle pose, with optional
  /// dpL_dxv (3×9, velocity columns zero) and dpL_dz (3×4). Same failure cases as
  /// triangulateInCamera; outputs are untouched on failure.
  Status triangulate(const Eigen::Vector4d& z, const EstimatedPose& pose, Eigen::Vector3d* p_LinN,
                     Matrix3x9d* dpL_dxv = nullptr, Matrix3x4d* dpL_dz = nullptr) const;
  /// The same for the Euler pose x_v = [p_BinN, v_B, φ θ ψ].
  Status triangulate(const Eigen::Vector4d& z, const Vector9d& x_v, Eigen::Vector3d* p_LinN,
                     Matrix3x9d* dpL_dxv = nullptr, Matrix3x4d* dpL_dz = nullptr) const;

 private:
  StereoCameraOptions o_;
};

}  // namespace cvslam
