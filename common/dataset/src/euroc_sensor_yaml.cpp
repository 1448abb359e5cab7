#include "cvslam/dataset/euroc_sensor_yaml.h"

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/io/number_format.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace cvslam {
namespace {

Expected<YAML::Node> loadOpenCvStyleYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open");
  std::stringstream text;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    // "%YAML:1.0" is OpenCV's directive spelling; YAML proper wants "%YAML 1.0". Drop it.
    if (first && line.rfind("%YAML", 0) == 0) {
      first = false;
      continue;
    }
    first = false;
    text << line << '\n';
  }
  try {
    YAML::Node root = YAML::Load(text.str());
    if (!root.IsMap()) return Status::Error(path + ": expected a map of keys");
    return root;
  } catch (const YAML::Exception& e) {
    return Status::Error(path + ": invalid YAML: " + e.what());
  }
}

// Reads T_BS {rows: 4, cols: 4, data: [...]}.
Status readTbs(const YAML::Node& root, const std::string& path, Eigen::Matrix4d& T) {
  const YAML::Node n = root["T_BS"];
  if (!n || !n["data"] || !n["data"].IsSequence() || n["data"].size() != 16)
    return Status::Error(path + ": T_BS: expected {rows: 4, cols: 4, data: [16 numbers]}");
  for (std::size_t k = 0; k < 16; ++k) T(k / 4, k % 4) = n["data"][k].as<double>();
  // A sensor's pose in the body must be rigid (the same rule as the camera calibration's,
  // camera/euroc_calibration.cpp): a scaled, sheared or reflected "rotation" would silently
  // distort every measurement.
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if (!T.allFinite() || !T.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)))
    return Status::Error(path + ": T_BS: last row must be [0, 0, 0, 1]");
  if (!(R * R.transpose()).isIdentity(1e-5) || !(R.determinant() > 0))
    return Status::Error(path + ": T_BS: rotation part is not a rotation matrix (not rigid)");
  return Status::Ok();
}

std::string tbsBlock(const Eigen::Matrix4d& T) {
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int k = 0; k < 16; ++k) {
    s += formatShortest(T(k / 4, k % 4));
    if (k < 15) s += (k % 4 == 3) ? ",\n         " : ", ";
  }
  return s + "]\n";
}

}  // namespace

Expected<EurocCameraInfo> readEurocCameraYaml(const std::string& path) {
  // One parser and one set of checks for camera sensor.yaml files: the calibration loader's.
  auto calib = loadEurocCameraCalibration(path);
  if (!calib.ok()) return calib.status();
  EurocCameraInfo info;
  if (!calib->comment.empty()) info.comment = calib->comment;
  info.T_BS = calib->T_CtoB;
  info.rate_hz = calib->rate_hz;
  info.width = calib->width;
  info.height = calib->height;
  info.intrinsics = calib->intrinsics;
  info.distortion_model = calib->distortion_model;
  info.distortion.assign(calib->distortion.data(), calib->distortion.data() + 4);
  return info;
}

Expected<EurocImuInfo> readEurocImuYaml(const std::string& path) {
  auto root = loadOpenCvStyleYaml(path);
  if (!root.ok()) return root.status();
  EurocImuInfo info;
  try {
    const YAML::Node& r = *root;
    if (r["comment"]) info.comment = r["comment"].as<std::string>();
    Status s = readTbs(r, path, info.T_BS);
    if (!s.ok()) return s;
    if (r["rate_hz"]) info.rate_hz = r["rate_hz"].as<double>();
    for (auto [key, value] : {std::pair{"gyroscope_noise_density", &info.gyroscope_noise_density},
                              {"gyroscope_random_walk", &info.gyroscope_random_walk},
                              {"accelerometer_noise_density", &info.accelerometer_noise_density},
                              {"accelerometer_random_walk", &info.accelerometer_random_walk}}) {
      if (!r[key]) return Status::Error(path + ": " + key + ": missing");
      *value = r[key].as<double>();
    }
  } catch (const YAML::Exception& e) {
    return Status::Error(path + ": bad value: " + e.what());
  }
  return info;
}

std::string formatEurocCameraYaml(const EurocCameraInfo& c) {
  std::string s =
      "%YAML:1.0\n# General sensor definitions.\nsensor_type: camera\ncomment: " + c.comment +
      "\n\n# Sensor extrinsics wrt. the body-frame.\n" + tbsBlock(c.T_BS);
  s += "\n# Camera specific definitions.\nrate_hz: " + formatShortest(c.rate_hz) + "\n";
  s += "resolution: [" + std::to_string(c.width) + ", " + std::to_string(c.height) + "]\n";
  s += "camera_model: " + c.camera_model + "\n";
  s += "intrinsics: [" + formatShortest(c.intrinsics(0)) + ", " + formatShortest(c.intrinsics(1)) +
       ", " + formatShortest(c.intrinsics(2)) + ", " + formatShortest(c.intrinsics(3)) +
       "] #fu, fv, cu, cv\n";
  s += "distortion_model: " + c.distortion_model + "\ndistortion_coefficients: [";
  for (std::size_t i = 0; i < c.distortion.size(); ++i)
    s += (i ? ", " : "") + formatShortest(c.distortion[i]);
  return s + "]\n";
}

std::string formatEurocImuYaml(const EurocImuInfo& m) {
  std::string s =
      "%YAML:1.0\n#Default imu sensor yaml file\nsensor_type: imu\ncomment: " + m.comment +
      "\n\n# Sensor extrinsics wrt. the body-frame.\n" + tbsBlock(m.T_BS);
  s += "rate_hz: " + formatShortest(m.rate_hz) +
       "\n\n# inertial sensor noise model parameters (static)\n";
  s += "gyroscope_noise_density: " + formatShortest(m.gyroscope_noise_density) +
       "     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )\n";
  s += "gyroscope_random_walk: " + formatShortest(m.gyroscope_random_walk) +
       "       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )\n";
  s += "accelerometer_noise_density: " + formatShortest(m.accelerometer_noise_density) +
       "  # [ m / s^2 / sqrt(Hz) ]   ( accel \"white noise\" )\n";
  s += "accelerometer_random_walk: " + formatShortest(m.accelerometer_random_walk) +
       "    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion )\n";
  return s;
}

}  // namespace cvslam
