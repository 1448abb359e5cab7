#include "cvslam/camera/euroc_calibration.h"

#include <Eigen/LU>
#include <fstream>
#include <sstream>
#include <vector>

#include "cvslam/io/config_node.h"

namespace cvslam {

Eigen::Matrix3d EurocCameraCalibration::K() const {
  Eigen::Matrix3d K;
  K << intrinsics(0), 0.0, intrinsics(2), 0.0, intrinsics(1), intrinsics(3), 0.0, 0.0, 1.0;
  return K;
}

Eigen::Matrix4d EurocStereoCalibration::T_LtoR() const {
  // T_CLtoCR = T_BtoCR · T_CLtoB = (T_CRtoB)⁻¹ · T_CLtoB.
  return right.T_CtoB.inverse() * left.T_CtoB;
}

double EurocStereoCalibration::baseline() const {
  return T_LtoR().topRightCorner<3, 1>().norm();
}

Expected<EurocCameraCalibration> loadEurocCameraCalibration(const std::string& sensor_yaml) {
  std::ifstream in(sensor_yaml);
  if (!in) return Status::Error(sensor_yaml + ": cannot open camera calibration file");
  // yaml-cpp does not understand OpenCV's "%YAML:1.0" directive: drop directive lines.
  std::stringstream text;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML", 0) == 0) continue;
    text << line << '\n';
  }
  auto cfg = ConfigNode::fromString(text.str(), sensor_yaml);
  if (!cfg.ok()) return cfg.status();
  const ConfigNode& node = *cfg;

  EurocCameraCalibration c;
  c.source = sensor_yaml;
  if (!node.has("T_BS")) {
    node.check(false, "T_BS", "required key is missing");
  } else {
    const ConfigNode t = node.child("T_BS");
    int rows = 0, cols = 0;
    t.require("rows", rows);
    t.require("cols", cols);
    t.check(rows == 4 && cols == 4, "rows", "T_BS must be 4×4");
    Eigen::Matrix4d T = Eigen::Matrix4d::Zero();
    t.require("data", T);  // row-major, as the file lists it
    if (t.status().ok()) {
      const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
      t.check(T.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)), "data",
              "last row must be [0, 0, 0, 1]");
      t.check((R * R.transpose()).isIdentity(1e-5) && R.determinant() > 0, "data",
              "rotation part is not a rotation matrix");
      c.T_CtoB = T;
    }
  }
  node.get("comment", c.comment);
  std::string sensor_type = "camera", camera_model;
  node.get("sensor_type", sensor_type);
  node.check(sensor_type == "camera", "sensor_type",
             "must be 'camera' (got '" + sensor_type + "')");
  node.require("camera_model", camera_model);
  if (node.has("camera_model"))
    node.check(camera_model == "pinhole", "camera_model",
               "only 'pinhole' is supported (got '" + camera_model + "')");
  node.require("intrinsics", c.intrinsics);
  node.check(c.intrinsics(0) > 0 && c.intrinsics(1) > 0, "intrinsics",
             "focal lengths fu, fv must be > 0");
  node.require("distortion_model", c.distortion_model);
  if (node.has("distortion_model"))
    node.check(c.distortion_model == "radial-tangential", "distortion_model",
               "only 'radial-tangential' is supported (got '" + c.distortion_model + "')");
  node.require("distortion_coefficients", c.distortion);
  std::vector<int> resolution;
  node.require("resolution", resolution);
  if (node.has("resolution") &&
      node.check(resolution.size() == 2, "resolution", "expected [width, height]")) {
    c.width = resolution[0];
    c.height = resolution[1];
    node.check(c.width > 0 && c.height > 0, "resolution", "width and height must be > 0");
  }
  node.require("rate_hz", c.rate_hz);
  node.check(c.rate_hz > 0, "rate_hz", "must be > 0");

  if (Status s = node.status(); !s.ok()) return s;
  return c;
}

Expected<EurocStereoCalibration> loadEurocStereoCalibration(const std::string& mav0_dir) {
  auto left = loadEurocCameraCalibration(mav0_dir + "/cam0/sensor.yaml");
  if (!left.ok()) return left.status();
  auto right = loadEurocCameraCalibration(mav0_dir + "/cam1/sensor.yaml");
  if (!right.ok()) return right.status();
  EurocStereoCalibration s{*left, *right};
  if (s.baseline() <= 0.0)
    return Status::Error(mav0_dir + ": cam0 and cam1 have the same optical centre");
  return s;
}

}  // namespace cvslam
