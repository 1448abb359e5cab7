#include "cvslam/slam/agent_calibration.h"

#include <filesystem>

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/dataset/euroc_sensor_yaml.h"

namespace cvslam {
namespace {

vision::CameraCalibration visionCalibration(const EurocCameraCalibration& c) {
  vision::CameraCalibration v;
  v.width = c.width;
  v.height = c.height;
  v.fx = c.intrinsics(0);
  v.fy = c.intrinsics(1);
  v.cx = c.intrinsics(2);
  v.cy = c.intrinsics(3);
  v.distortion.assign(c.distortion.data(), c.distortion.data() + 4);
  v.T_CtoB.matrix() = c.T_CtoB;
  return v;
}

/// Already a rectified pair (simulated folders): no distortion, same intrinsics and
/// orientation, right camera along +x of the left one.
bool isRectified(const EurocStereoCalibration& s) {
  constexpr double kTol = 1e-9;
  const Eigen::Matrix4d T_LtoR = s.T_LtoR();
  const Eigen::Vector3d t = T_LtoR.topRightCorner<3, 1>();
  return s.left.distortion.isZero(kTol) && s.right.distortion.isZero(kTol) &&
         (s.left.intrinsics - s.right.intrinsics).isZero(kTol) &&
         (T_LtoR.topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity()).isZero(kTol) &&
         std::abs(t.y()) < kTol && std::abs(t.z()) < kTol && t.x() < 0.0 &&
         s.left.width == s.right.width && s.left.height == s.right.height;
}

}  // namespace

Expected<AgentCalibration> calibrationFromEuroc(const std::string& dir,
                                                const VisualInertialSlamOptions& options) {
  std::string mav0 = dir;
  if (std::filesystem::exists(dir + "/mav0/cam0/sensor.yaml")) mav0 = dir + "/mav0";
  auto stereo = loadEurocStereoCalibration(mav0);
  if (!stereo.ok()) return stereo.status();
  auto imu = readEurocImuYaml(mav0 + "/imu0/sensor.yaml");
  if (!imu.ok()) return imu.status();
  // The estimator's body frame is the IMU frame, whatever its mounting (docs/conventions.md):
  // the cameras' T_BS (camera → recording body) become camera → IMU, T_ItoBᵀ-composed with
  // the IMU's own T_BS (IMU → recording body; rigid, checked by readEurocImuYaml).
  const Eigen::Matrix3d R_ItoB = imu->T_BS.topLeftCorner<3, 3>();
  Eigen::Matrix4d T_BtoI = Eigen::Matrix4d::Identity();
  T_BtoI.topLeftCorner<3, 3>() = R_ItoB.transpose();
  T_BtoI.topRightCorner<3, 1>() = -R_ItoB.transpose() * imu->T_BS.topRightCorner<3, 1>();
  stereo->left.T_CtoB = T_BtoI * stereo->left.T_CtoB;
  stereo->right.T_CtoB = T_BtoI * stereo->right.T_CtoB;
  AgentCalibration c;
  c.source = mav0;
  c.options = options;
  c.options.ins.gyro_noise_density = imu->gyroscope_noise_density;
  c.options.ins.accel_noise_density = imu->accelerometer_noise_density;
  c.options.ins.gyro_random_walk = imu->gyroscope_random_walk;
  c.options.ins.accel_random_walk = imu->accelerometer_random_walk;
  // A recording's turn-on accelerometer bias is unknown (slam_options.h).
  c.options.slam.initial_accel_bias_sigma = options.slam.recorded_accel_bias_sigma;

  StereoCameraOptions cam;
  const EurocCameraCalibration& left = stereo->left;
  if (isRectified(*stereo)) {
    cam.fx = left.intrinsics(0);
    cam.fy = left.intrinsics(1);
    cam.cx = left.intrinsics(2);
    cam.cy = left.intrinsics(3);
    cam.width = left.width;
    cam.height = left.height;
    cam.baseline = stereo->baseline();
    cam.R_BtoC = left.R_CtoB().transpose();
  } else {
    vision::StereoCalibration raw{visionCalibration(left), visionCalibration(stereo->right)};
    auto rectifier = vision::StereoRectifier::create(raw);
    if (!rectifier.ok()) return Status::Error(mav0 + ": " + rectifier.status().message());
    const vision::RectifiedStereo& r = rectifier->rectified();
    cam.fx = cam.fy = r.f;
    cam.cx = r.cx;
    cam.cy = r.cy;
    cam.width = r.width;
    cam.height = r.height;
    cam.baseline = r.baseline;
    // p_B = R_CtoB p_C and p_rect = R_CtoRect p_C, so R_BtoRect = R_CtoRect R_CtoBᵀ.
    cam.R_BtoC = r.R_CtoRect * left.R_CtoB().transpose();
    c.rectifier = std::move(*rectifier);
  }
  cam.p_CinB = left.p_CinB();
  c.camera = StereoCamera(cam);
  return c;
}

}  // namespace cvslam
