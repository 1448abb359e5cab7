#pragma once
// Rectified pinhole stereo pair rigidly mounted on the vehicle (thesis §5.4, eq. 5.20).
//
// Left camera CL: pinhole (fx, fy, cx, cy); the right camera CR has the same intrinsics and
// sits `baseline` metres along +x of CL (rectified pair). The pair's pose on the body is
// T_BtoC: R_BtoC and p_CinB (left camera centre in the body frame).
//
// Observation of landmark p_LinN from vehicle state x_v = [p_BinN, v_B, euler]:
//   p_LinC = R_BtoC (R_NtoB(euler) (p_LinN − p_BinN) − p_CinB)
//   z = [fx x/z + cx, fy y/z + cy, fx (x − b)/z + cx, fy y/z + cy]

#include <Eigen/Core>
#include <optional>

#include "cvslam/core/status.h"

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

  Status load(const ConfigNode& node);
};

class StereoCamera {
 public:
  explicit StereoCamera(const StereoCameraOptions& options = {}) : o_(options) {}
  const StereoCameraOptions& options() const { return o_; }

  /// Landmark in the left camera frame.
  Eigen::Vector3d landmarkInCamera(const Eigen::Vector3d& p_BinN, const Eigen::Vector3d& euler,
                                   const Eigen::Vector3d& p_LinN) const;

  /// Predicted measurement z = [u_L v_L u_R v_R] (eq. 5.20). Does not check visibility.
  Eigen::Vector4d project(const Eigen::Vector3d& p_LinC) const;

  /// True when the point is in front of both cameras (depth ≥ min_depth) and projects
  /// inside both images.
  bool isVisible(const Eigen::Vector3d& p_LinC) const;

 private:
  StereoCameraOptions o_;
};

}  // namespace cvslam
