#pragma once
// Renders the image a real, distorting camera would record: a pinhole view of the World on a
// canvas wide enough to hold the whole distorted field of view, then warped by the camera's
// radial-tangential model (EuRoC `distortion_model: radial-tangential`, [k1 k2 p1 p2]).
//
// For each output pixel (u_d, v_d) the map holds where its ray lands in the pinhole canvas:
// undistort (cv::undistortPoints, iterative inverse of the model) to normalised (x, y), then
// project with the canvas matrix. Built once; each image is one cv::remap (bilinear).
// Used by `cvslam_simulate --as-recorded` to write folders with the real calibration of a
// sensor rig (unrectified pair, distortion, extrinsics as its sensor.yaml says).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <memory>

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/core/status.h"
#include "cvslam/render/stereo_renderer.h"

namespace cvslam::render {

class DistortedCameraRenderer {
 public:
  /// Fails for a distortion model other than radial-tangential or a calibration whose
  /// distorted field of view does not fit a canvas of at most `max_canvas_scale` × the image.
  static Expected<DistortedCameraRenderer> create(std::shared_ptr<const World> world,
                                                  const EurocCameraCalibration& calibration,
                                                  const RenderOptions& options = {},
                                                  double max_canvas_scale = 3.0);

  /// The distorted mono8 image of a camera at p_CinN with orientation R_NtoC; `noise_stream`
  /// seeds the image noise (RenderOptions::effects).
  cv::Mat render(const Eigen::Matrix3d& R_NtoC, const Eigen::Vector3d& p_CinN,
                 uint64_t noise_stream) const;

  const EurocCameraCalibration& calibration() const { return calibration_; }
  /// The pinhole canvas rendered before the warp.
  const StereoCamera& canvas() const { return renderer_->camera(); }

 private:
  DistortedCameraRenderer() = default;
  EurocCameraCalibration calibration_;
  std::shared_ptr<const StereoRenderer> renderer_;
  cv::Mat map_x_, map_y_;  // CV_32F, output size: canvas coordinates of each output pixel
};

}  // namespace cvslam::render
