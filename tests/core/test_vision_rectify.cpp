// Undistortion and rectification of EuRoC's real calibration (radial-tangential, T_BS).

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include "cvslam/vision/stereo_rectifier.h"
#include "vision_test_data.h"

namespace cvslam::vision {
namespace {

TEST(VisionRectify, EurocCalibrationGivesRowAlignedPair) {
  StereoCalibration calib;
  ASSERT_TRUE(test::eurocCalibration(&calib)) << "EuRoC sensor.yaml missing";
  auto rect = StereoRectifier::create(calib);
  ASSERT_TRUE(rect.ok()) << rect.status().message();
  const RectifiedStereo& r = rect->rectified();
  EXPECT_NEAR(r.baseline, 0.110, 0.002);  // V1 rig: ≈ 11 cm
  EXPECT_GT(r.f, 300.0);
  EXPECT_LT(r.f, 500.0);

  // A calibration pattern: a 3-D grid in front of the left camera, projected through each
  // raw (distorted) camera, then mapped to rectified coordinates: rows must coincide and the
  // disparity must be f·b/z (eq. 4.10).
  const Eigen::Isometry3d T_LtoR = calib.right.T_CtoB.inverse() * calib.left.T_CtoB;
  cv::Mat K0 = (cv::Mat_<double>(3, 3) << calib.left.fx, 0, calib.left.cx, 0, calib.left.fy,
                calib.left.cy, 0, 0, 1);
  cv::Mat K1 = (cv::Mat_<double>(3, 3) << calib.right.fx, 0, calib.right.cx, 0, calib.right.fy,
                calib.right.cy, 0, 0, 1);
  int n = 0;
  for (double x = -1.2; x <= 1.2; x += 0.3) {
    for (double y = -0.8; y <= 0.8; y += 0.2) {
      const Eigen::Vector3d p_L(x, y, 2.5 + 0.3 * x);
      const Eigen::Vector3d p_R = T_LtoR * p_L;
      std::vector<cv::Point3d> pl{{p_L.x(), p_L.y(), p_L.z()}};
      std::vector<cv::Point3d> pr{{p_R.x(), p_R.y(), p_R.z()}};
      std::vector<cv::Point2d> ul, ur;
      const cv::Mat zero = cv::Mat::zeros(3, 1, CV_64F);
      cv::projectPoints(pl, zero, zero, K0, calib.left.distortion, ul);
      cv::projectPoints(pr, zero, zero, K1, calib.right.distortion, ur);
      if (ul[0].x < 0 || ul[0].x >= 752 || ul[0].y < 0 || ul[0].y >= 480) continue;
      if (ur[0].x < 0 || ur[0].x >= 752 || ur[0].y < 0 || ur[0].y >= 480) continue;
      const cv::Point2d rl = rect->rectifyLeftPoint(ul[0]);
      const cv::Point2d rr = rect->rectifyRightPoint(ur[0]);
      EXPECT_NEAR(rl.y, rr.y, 0.02) << x << " " << y;
      const double z_rect = (r.R_CtoRect * p_L).z();
      EXPECT_NEAR(rl.x - rr.x, r.f * r.baseline / z_rect, 0.02);
      ++n;
    }
  }
  EXPECT_GT(n, 50);

  cv::Mat l, rgt, lr, rr;
  const auto stamps = test::eurocStereoStamps();
  ASSERT_FALSE(stamps.empty());
  ASSERT_TRUE(test::loadEurocPair(stamps[0], &l, &rgt));
  ASSERT_TRUE(rect->rectify(l, rgt, &lr, &rr).ok());
  EXPECT_EQ(lr.size(), l.size());
  EXPECT_EQ(lr.type(), CV_8UC1);
  EXPECT_FALSE(rect->rectify(cv::Mat(240, 320, CV_8U), rgt, &lr, &rr).ok());
}

TEST(VisionRectify, RejectsBadCalibrations) {
  StereoCalibration calib;
  ASSERT_TRUE(test::eurocCalibration(&calib));
  StereoCalibration bad = calib;
  bad.left.distortion = {0.1, 0.2, 0.3};
  auto r1 = StereoRectifier::create(bad);
  ASSERT_FALSE(r1.ok());
  EXPECT_NE(r1.status().message().find("distortion"), std::string::npos);
  bad = calib;
  bad.right.width = 640;
  EXPECT_FALSE(StereoRectifier::create(bad).ok());
  bad = calib;
  bad.right.T_CtoB = bad.left.T_CtoB;
  EXPECT_FALSE(StereoRectifier::create(bad).ok());
  bad = calib;
  std::swap(bad.left, bad.right);  // right camera on the left
  EXPECT_FALSE(StereoRectifier::create(bad).ok());
}

}  // namespace
}  // namespace cvslam::vision
