#pragma once
// One rendered camera image with its exact per-pixel ground truth.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

#include "cvslam/render/rasterizer.h"

namespace cvslam::render {

/// The surface point a pixel sees.
struct SurfacePoint {
  Eigen::Vector3d p_N;  ///< point in the navigation frame [m]
  double depth = 0.0;   ///< z in the camera frame (along the optical axis) [m]
};

struct RenderedImage {
  cv::Mat image;                        ///< CV_8UC1 (mono8)
  cv::Mat1i triangle_ids;               ///< per pixel: triangle drawn there, −1 = background
  std::vector<Eigen::Vector3d> planes;  ///< per triangle: 1/z_C = P·[u v 1]
  PinholeIntrinsics intrinsics;
  Eigen::Matrix3d R_NtoC = Eigen::Matrix3d::Identity();  ///< camera orientation
  Eigen::Vector3d p_CinN = Eigen::Vector3d::Zero();      ///< camera centre [m]

  /// The true 3-D point seen at image point (u, v) (pixel centres are integers), exact on
  /// the triangle covering the nearest pixel; empty where the pixel shows background.
  std::optional<SurfacePoint> surfaceAt(double u, double v) const;
  /// Depth z_C per pixel (CV_32F), NaN on background.
  cv::Mat1f depthMap() const;
};

}  // namespace cvslam::render
