#pragma once
// Undistortion and rectification of a calibrated stereo pair (cv::stereoRectify +
// cv::initUndistortRectifyMap). After rectification both images share the pinhole (f, cx, cy),
// rows are epipolar lines (VD = 0, §4.2.8.3) and the right camera sits `baseline` metres along
// +x of the left one — the model of eq. 5.20 (StereoCameraOptions).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "cvslam/core/status.h"
#include "cvslam/vision/stereo_calibration.h"

namespace cvslam::vision {

struct RectifiedStereo {
  double f = 0;         ///< focal length of both rectified cameras [px]
  double cx = 0;        ///< principal point, left (= right; CALIB_ZERO_DISPARITY) [px]
  double cy = 0;        ///< [px]
  double baseline = 0;  ///< [m]
  int width = 0;        ///< rectified image size [px]
  int height = 0;
  /// Rotation from the original left camera frame to the rectified left camera frame.
  Eigen::Matrix3d R_CtoRect = Eigen::Matrix3d::Identity();
};

class StereoRectifier {
 public:
  /// Computes the rectifying transforms and the remap tables. `alpha` as in cv::stereoRectify
  /// (0: only valid pixels, 1: all source pixels kept).
  static Expected<StereoRectifier> create(const StereoCalibration& calibration, double alpha = 0.0);

  /// Undistorts and rectifies a pair (grey or colour); both images must have the calibrated
  /// sizes.
  Status rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_rect,
                 cv::Mat* right_rect) const;

  /// Maps a raw (distorted) pixel of the left / right image to rectified coordinates.
  cv::Point2d rectifyLeftPoint(const cv::Point2d& raw) const;
  cv::Point2d rectifyRightPoint(const cv::Point2d& raw) const;

  const RectifiedStereo& rectified() const { return rect_; }

 private:
  StereoRectifier() = default;
  StereoCalibration calib_;
  RectifiedStereo rect_;
  cv::Mat K_[2], D_[2], R_[2], P_[2];
  cv::Mat map1_[2], map2_[2];
};

}  // namespace cvslam::vision
