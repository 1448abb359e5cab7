#pragma once
// EuRoC `sensor.yaml` files (cam0/cam1/imu0), read and written as the ASL tools write them:
// a `%YAML:1.0` header (OpenCV style, which plain YAML parsers reject, so it is stripped
// before parsing), `T_BS: {cols: 4, rows: 4, data: [16 numbers, row-major]}` mapping sensor
// to body (our T_CtoB for a camera), `rate_hz`, and for cameras `resolution: [w, h]`,
// `camera_model: pinhole`, `intrinsics: [fu, fv, cu, cv]`,
// `distortion_model: radial-tangential`, `distortion_coefficients: [k1, k2, p1, p2]`;
// for the IMU the noise densities and random walks.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {

struct EurocCameraInfo {
  std::string comment = "cvslam rendered camera";
  Eigen::Matrix4d T_BS = Eigen::Matrix4d::Identity();  ///< sensor → body
  double rate_hz = 20.0;
  int width = 0, height = 0;
  std::string camera_model = "pinhole";
  Eigen::Vector4d intrinsics = Eigen::Vector4d::Zero();  ///< fu, fv, cu, cv [px]
  std::string distortion_model = "radial-tangential";
  std::vector<double> distortion = {0.0, 0.0, 0.0, 0.0};  ///< k1, k2, p1, p2
};

struct EurocImuInfo {
  std::string comment = "cvslam simulated IMU";
  Eigen::Matrix4d T_BS = Eigen::Matrix4d::Identity();
  double rate_hz = 200.0;
  double gyroscope_noise_density = 1.6968e-04;      ///< rad/s/√Hz
  double gyroscope_random_walk = 1.9393e-05;        ///< rad/s²/√Hz
  double accelerometer_noise_density = 2.0000e-03;  ///< m/s²/√Hz
  double accelerometer_random_walk = 3.0000e-03;    ///< m/s³/√Hz
};

/// Reads a camera sensor.yaml; errors name the file and the key.
Expected<EurocCameraInfo> readEurocCameraYaml(const std::string& path);
Expected<EurocImuInfo> readEurocImuYaml(const std::string& path);

/// File contents in EuRoC's layout (full double precision, so values read back exactly).
std::string formatEurocCameraYaml(const EurocCameraInfo& info);
std::string formatEurocImuYaml(const EurocImuInfo& info);

}  // namespace cvslam
