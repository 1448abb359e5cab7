#pragma once
// Raw (unrectified) stereo calibration as EuRoC ASL folders store it:
// mav0/cam0/sensor.yaml (left) and mav0/cam1/sensor.yaml (right), docs/architecture.md.
//
// Each file holds T_BS (sensor→body, i.e. T_CtoB in our naming; 4×4 row-major `data`),
// `intrinsics: [fu, fv, cu, cv]`, `distortion_model: radial-tangential` with
// `distortion_coefficients: [k1, k2, p1, p2]`, `resolution: [width, height]` and `rate_hz`.
// The files begin with the OpenCV `%YAML:1.0` directive, which yaml-cpp rejects; the loader
// drops that line. Rectification is the front end's job: this is only the parsed data.

#include <Eigen/Core>
#include <string>

#include "cvslam/core/status.h"

namespace cvslam {

struct EurocCameraCalibration {
  std::string source;                                    ///< file it was read from
  std::string comment;                                   ///< the file's free-text comment
  Eigen::Vector4d intrinsics = Eigen::Vector4d::Zero();  ///< [fu fv cu cv] [px]
  std::string distortion_model = "radial-tangential";
  Eigen::Vector4d distortion = Eigen::Vector4d::Zero();  ///< [k1 k2 p1 p2]
  Eigen::Matrix4d T_CtoB = Eigen::Matrix4d::Identity();  ///< EuRoC T_BS
  int width = 0;                                         ///< [px]
  int height = 0;                                        ///< [px]
  double rate_hz = 0.0;                                  ///< frame rate [Hz]

  /// 3×3 camera matrix [fu 0 cu; 0 fv cv; 0 0 1].
  Eigen::Matrix3d K() const;
  Eigen::Matrix3d R_CtoB() const { return T_CtoB.topLeftCorner<3, 3>(); }
  Eigen::Vector3d p_CinB() const { return T_CtoB.topRightCorner<3, 1>(); }
};

struct EurocStereoCalibration {
  EurocCameraCalibration left;   ///< cam0
  EurocCameraCalibration right;  ///< cam1

  /// Pose of the left camera in the right camera frame: p_inCR = T_CLtoCR p_inCL.
  Eigen::Matrix4d T_LtoR() const;
  /// Distance between the two optical centres [m].
  double baseline() const;
};

/// Parses one EuRoC camera `sensor.yaml`. Errors name the file and the key.
Expected<EurocCameraCalibration> loadEurocCameraCalibration(const std::string& sensor_yaml);

/// Parses `<mav0_dir>/cam0/sensor.yaml` and `<mav0_dir>/cam1/sensor.yaml`.
Expected<EurocStereoCalibration> loadEurocStereoCalibration(const std::string& mav0_dir);

}  // namespace cvslam
