// SWIF on a real EuRoC stereo pair (euroc_micro, V1_01_easy frame 0): after rectification the
// SWIF matches between left and right must satisfy the epipolar constraint (same row, positive
// disparity), and consecutive left frames must be related by a fundamental matrix.

#include <gtest/gtest.h>

#include <iostream>

#include "core/vision_test_data.h"
#include "cvslam/vision/detector_eval.h"
#include "cvslam/vision/stereo_front_end.h"
#include "cvslam/vision/swif.h"

namespace cvslam::vision {
namespace {

constexpr double kRowTolerancePx = 2.0;    // rectified rows agree to this (EuRoC calibration)
constexpr double kMaxDisparityPx = 150.0;  // f·b/z for z ≥ 0.35 m (458 px · 0.11 m)

MatchOptions matchOptions() {
  MatchOptions m;
  m.norm = MatchNorm::kL2;
  m.dist_ratio = 0.8;
  return m;
}

TEST(SwifEuroc, StereoMatchesSatisfyTheEpipolarConstraint) {
  StereoCalibration calib;
  ASSERT_TRUE(test::eurocCalibration(&calib))
      << "euroc_micro calibration not found under " << test::eurocMicroDir();
  auto rect = StereoRectifier::create(calib);
  ASSERT_TRUE(rect.ok()) << rect.status().message();
  const auto stamps = test::eurocStereoStamps();
  ASSERT_FALSE(stamps.empty());
  cv::Mat l, r, lr, rr;
  ASSERT_TRUE(test::loadEurocPair(stamps[0], &l, &r));
  ASSERT_TRUE(rect->rectify(l, r, &lr, &rr).ok());
  Swif swif{SwifOptions()};
  Features fl, fr;
  ASSERT_TRUE(swif.detectAndDescribe(lr, &fl).ok());
  ASSERT_TRUE(swif.detectAndDescribe(rr, &fr).ok());
  const auto matches = matchDescriptors(fl, fr, matchOptions());
  const MatchQuality q = matchQualityStereo(fl, fr, matches, kRowTolerancePx, 0.0, kMaxDisparityPx);
  std::cout << "stereo: " << fl.size() << " / " << fr.size() << " features, " << q.matches
            << " matches, " << q.correct << " on the epipolar line (precision " << q.precision
            << ")\n";
  EXPECT_GE(q.correct, 80);
  EXPECT_GE(q.precision, 0.75);
}

TEST(SwifEuroc, StereoFrontEndRunsWithSwif) {
  // detector.type: swif through the front end (§4.2.8 stereo constraints, no vocabulary: there
  // is none for SWIF descriptors, and a SIFT one is refused).
  StereoCalibration calib;
  ASSERT_TRUE(test::eurocCalibration(&calib));
  auto rect = StereoRectifier::create(calib);
  ASSERT_TRUE(rect.ok());
  const auto stamps = test::eurocStereoStamps();
  ASSERT_FALSE(stamps.empty());
  cv::Mat l, r, lr, rr;
  ASSERT_TRUE(test::loadEurocPair(stamps[0], &l, &r));
  ASSERT_TRUE(rect->rectify(l, r, &lr, &rr).ok());
  StereoFrontEndOptions o;
  o.detector.type = DetectorType::kSwif;
  o.stereo.focal_px = rect->rectified().f;
  o.stereo.baseline_m = rect->rectified().baseline;
  auto fe = StereoFrontEnd::create(o, nullptr);
  ASSERT_TRUE(fe.ok()) << fe.status().message();
  std::vector<StereoObservation> obs;
  ASSERT_TRUE(fe->process(lr, rr, &obs).ok());
  std::cout << "front end: " << obs.size() << " stereo observations\n";
  EXPECT_GE(obs.size(), 50u);
  for (const StereoObservation& ob : obs) {
    EXPECT_LE(std::abs(ob.z(1) - ob.z(3)), o.stereo.max_vertical_disparity_px + 1e-9);
    EXPECT_GT(ob.z(0) - ob.z(2), 0.0);
    EXPECT_EQ(ob.descriptor.size(),
              static_cast<std::size_t>(descriptorBytes(DescriptorType::kSwif)));
  }
}

TEST(SwifEuroc, ConsecutiveFramesFitAFundamentalMatrix) {
  const auto stamps = test::eurocStereoStamps();
  ASSERT_GT(stamps.size(), 2u);
  cv::Mat l0, r0, l1, r1;
  ASSERT_TRUE(test::loadEurocPair(stamps[0], &l0, &r0));
  ASSERT_TRUE(test::loadEurocPair(stamps[2], &l1, &r1));
  Swif swif{SwifOptions()};
  Features a, b;
  ASSERT_TRUE(swif.detectAndDescribe(l0, &a).ok());
  ASSERT_TRUE(swif.detectAndDescribe(l1, &b).ok());
  const auto matches = matchDescriptors(a, b, matchOptions());
  const MatchQuality q = matchQualityFundamental(a, b, matches, 1.0);
  std::cout << "frames 0 → 2: " << q.matches << " matches, " << q.correct
            << " RANSAC-F inliers (precision " << q.precision << ")\n";
  EXPECT_GE(q.correct, 150);
  EXPECT_GE(q.precision, 0.85);
}

}  // namespace
}  // namespace cvslam::vision
