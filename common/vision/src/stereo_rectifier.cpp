#include "cvslam/vision/stereo_rectifier.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace cvslam::vision {

namespace {

Status checkCamera(const CameraCalibration& c, const std::string& name) {
  if (c.width <= 0 || c.height <= 0)
    return Status::Error("stereo calibration: " + name + " image size must be > 0");
  if (!(c.fx > 0) || !(c.fy > 0))
    return Status::Error("stereo calibration: " + name + " focal lengths must be > 0");
  const std::size_t n = c.distortion.size();
  if (!(n == 0 || n == 4 || n == 5 || n == 8))
    return Status::Error("stereo calibration: " + name +
                         " distortion needs 0, 4, 5 or 8 coefficients (radial-tangential), got " +
                         std::to_string(n));
  return Status::Ok();
}

cv::Mat cameraMatrix(const CameraCalibration& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

cv::Mat distortion(const CameraCalibration& c) {
  cv::Mat d(1, static_cast<int>(c.distortion.size()), CV_64F);
  for (std::size_t k = 0; k < c.distortion.size(); ++k)
    d.at<double>(0, static_cast<int>(k)) = c.distortion[k];
  return d;
}

}  // namespace

Expected<StereoRectifier> StereoRectifier::create(const StereoCalibration& calibration,
                                                  double alpha) {
  if (Status s = checkCamera(calibration.left, "left"); !s.ok()) return s;
  if (Status s = checkCamera(calibration.right, "right"); !s.ok()) return s;
  if (calibration.left.width != calibration.right.width ||
      calibration.left.height != calibration.right.height)
    return Status::Error("stereo calibration: left and right image sizes differ");

  StereoRectifier r;
  r.calib_ = calibration;
  // Left camera frame → right camera frame: p_R = T_BtoR · T_LtoB · p_L.
  const Eigen::Isometry3d T_LtoR = calibration.right.T_CtoB.inverse() * calibration.left.T_CtoB;
  if (T_LtoR.translation().norm() < 1e-6)
    return Status::Error("stereo calibration: the two camera centres coincide");
  cv::Mat R(3, 3, CV_64F);
  cv::Mat T(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    T.at<double>(i) = T_LtoR.translation()(i);
    for (int j = 0; j < 3; ++j) R.at<double>(i, j) = T_LtoR.linear()(i, j);
  }
  const cv::Size size(calibration.left.width, calibration.left.height);
  r.K_[0] = cameraMatrix(calibration.left);
  r.K_[1] = cameraMatrix(calibration.right);
  r.D_[0] = distortion(calibration.left);
  r.D_[1] = distortion(calibration.right);
  cv::Mat Q;
  cv::stereoRectify(r.K_[0], r.D_[0], r.K_[1], r.D_[1], size, R, T, r.R_[0], r.R_[1], r.P_[0],
                    r.P_[1], Q, cv::CALIB_ZERO_DISPARITY, alpha, size);
  for (int c = 0; c < 2; ++c)
    cv::initUndistortRectifyMap(r.K_[c], r.D_[c], r.R_[c], r.P_[c], size, CV_16SC2, r.map1_[c],
                                r.map2_[c]);
  // P_right = [f 0 cx  −f·b; 0 f cy 0; 0 0 1 0] for a horizontal pair.
  const double f = r.P_[0].at<double>(0, 0);
  const double tx = r.P_[1].at<double>(0, 3);
  if (std::abs(r.P_[1].at<double>(1, 3)) > 1e-6 * std::abs(tx) + 1e-9 || !(tx < 0))
    return Status::Error(
        "stereo calibration: the pair is not a left/right pair with the right camera along +x "
        "of the left one");
  r.rect_.f = f;
  r.rect_.cx = r.P_[0].at<double>(0, 2);
  r.rect_.cy = r.P_[0].at<double>(1, 2);
  r.rect_.baseline = -tx / f;
  r.rect_.width = size.width;
  r.rect_.height = size.height;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.rect_.R_CtoRect(i, j) = r.R_[0].at<double>(i, j);
  return r;
}

Status StereoRectifier::rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_rect,
                                cv::Mat* right_rect) const {
  const cv::Size size(rect_.width, rect_.height);
  if (left.size() != size || right.size() != size)
    return Status::Error("rectify: images must be " + std::to_string(size.width) + "x" +
                         std::to_string(size.height) + " as calibrated");
  cv::remap(left, *left_rect, map1_[0], map2_[0], cv::INTER_LINEAR);
  cv::remap(right, *right_rect, map1_[1], map2_[1], cv::INTER_LINEAR);
  return Status::Ok();
}

namespace {
cv::Point2d rectifyPoint(const cv::Point2d& raw, const cv::Mat& K, const cv::Mat& D,
                         const cv::Mat& R, const cv::Mat& P) {
  std::vector<cv::Point2d> in{raw};
  std::vector<cv::Point2d> out;
  cv::undistortPoints(in, out, K, D, R, P);
  return out[0];
}
}  // namespace

cv::Point2d StereoRectifier::rectifyLeftPoint(const cv::Point2d& raw) const {
  return rectifyPoint(raw, K_[0], D_[0], R_[0], P_[0]);
}

cv::Point2d StereoRectifier::rectifyRightPoint(const cv::Point2d& raw) const {
  return rectifyPoint(raw, K_[1], D_[1], R_[1], P_[1]);
}

}  // namespace cvslam::vision
