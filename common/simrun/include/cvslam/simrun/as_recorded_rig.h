#pragma once
// What a real sensor rig would have recorded on a simulated flight (`cvslam_simulate
// --as-recorded`): the data of an EuRoC-format folder as the VI-sensor writes it, not in the
// simulator's convenient frames.
//
//   - World W is z-up: W = N with y and z flipped (R_NtoW = diag(1, −1, −1)), like the Leica /
//     Vicon frames of EuRoC. Ground truth is the pose of the IMU frame S in W.
//   - The IMU measures in its own axes S, mounted as the real rig mounts it. The mounting
//     follows from the real calibration and the scenario's camera: the camera keeps the
//     viewing direction the scenario gives it (R_BtoC), and S sits where the real rig puts it
//     relative to that camera: R_BtoS = R_CtoS · R_BtoC (R_CtoS from cam0's T_BS). For the
//     EuRoC calibration on an FRD body this puts x_S up, as on the VI-sensor. The IMU is at the
//     body origin; ω_S = R_BtoS ω_B, f_S = R_BtoS f_B, biases likewise.
//   - Both cameras are rendered with their own intrinsics, radial-tangential distortion and
//     T_BS (unrectified pair, DistortedCameraRenderer), so the folder's sensor.yaml is the real
//     calibration's.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <memory>

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/camera/stereo_camera.h"
#include "cvslam/core/status.h"
#include "cvslam/dataset/euroc_dataset.h"
#include "cvslam/dataset/euroc_sensor_yaml.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/render/distorted_camera_renderer.h"
#include "cvslam/sensors/sensor_stream.h"

namespace cvslam {

class AsRecordedRig {
 public:
  /// `rig` is the real calibration (cam0/cam1 sensor.yaml); `scenario_camera` the scenario
  /// agent's camera, whose R_BtoC fixes the mounting.
  static Expected<AsRecordedRig> create(std::shared_ptr<const render::World> world,
                                        const EurocStereoCalibration& rig,
                                        const StereoCameraOptions& scenario_camera,
                                        const render::RenderOptions& rendering = {});

  /// z-up world from the simulator's NED frame.
  static Eigen::Matrix3d R_NtoW() { return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal(); }

  const Eigen::Matrix3d& R_BtoS() const { return R_BtoS_; }
  /// The IMU sample in S.
  ImuSample imu(const ImuSample& body) const;
  /// The ground-truth row of S in W (biases in S).
  EurocGroundTruth groundTruth(int64_t t_us, const VehiclePose& truth) const;
  /// Both distorted images of a frame at the true vehicle pose; `frame_index` seeds the noise.
  void render(const VehiclePose& truth, uint64_t frame_index, cv::Mat* left, cv::Mat* right) const;
  /// The sensor.yaml contents of cam0 / cam1 (the real calibration, at `rate_hz`).
  EurocCameraInfo cameraInfo(bool right, double rate_hz) const;

 private:
  AsRecordedRig() = default;
  EurocStereoCalibration rig_;
  Eigen::Matrix3d R_BtoS_ = Eigen::Matrix3d::Identity();
  std::shared_ptr<const render::DistortedCameraRenderer> left_, right_;
};

}  // namespace cvslam
