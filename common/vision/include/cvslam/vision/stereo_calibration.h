#pragma once
// Calibration of a stereo pair as the front end needs it for undistortion and rectification
// (docs/conventions.md: "undistort + rectify real data first"). A plain struct: fill it from EuRoC's
// sensor.yaml, a simulator, or a config file.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace cvslam::vision {

/// One pinhole camera with radial-tangential (plumb-bob) distortion, as in EuRoC.
struct CameraCalibration {
  int width = 0;                   ///< image width [px]
  int height = 0;                  ///< image height [px]
  double fx = 0, fy = 0;           ///< focal lengths [px]
  double cx = 0, cy = 0;           ///< principal point [px]
  std::vector<double> distortion;  ///< [k1 k2 p1 p2 (k3)] radial-tangential; empty = none
  /// Pose of the camera in the body (IMU) frame: p_B = T_CtoB · p_C (EuRoC's T_BS).
  Eigen::Isometry3d T_CtoB = Eigen::Isometry3d::Identity();
};

struct StereoCalibration {
  CameraCalibration left;   ///< cam0
  CameraCalibration right;  ///< cam1
};

}  // namespace cvslam::vision
