// Stereo matching with the constraints of §4.2.8: synthetic ground truth (a real image shifted
// by a known disparity field) and the real, rectified EuRoC pair (row error, plausible depth).

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "cvslam/vision/feature_detector.h"
#include "cvslam/vision/stereo_matcher.h"
#include "cvslam/vision/stereo_rectifier.h"
#include "vision_test_data.h"

namespace cvslam::vision {
namespace {

// Disparity field of the synthetic pair: a slanted plane, d grows down the image.
double trueDisparity(double v, int rows) {
  return 6.0 + 30.0 * v / rows;
}

struct SyntheticResult {
  std::size_t left_features = 0, right_features = 0, matches = 0;
  double precision = 0.0;
};

// The real left image shifted by trueDisparity(): detect, match, count the matches whose
// disparity and row are right within the localisation tolerance.
SyntheticResult syntheticStereo(const DetectorOptions& d) {
  SyntheticResult res;
  const auto stamps = test::eurocStereoStamps();
  cv::Mat left, unused;
  if (!(stamps.size() > 20 && test::loadEurocPair(stamps[20], &left, &unused))) {
    ADD_FAILURE() << "EuRoC micro data missing under " << test::sharedDataDir();
    return res;
  }
  // right(u, v) = left(u + d(v), v): a left pixel (u, v) appears at u − d(v) on the right.
  cv::Mat map_x(left.size(), CV_32F), map_y(left.size(), CV_32F);
  for (int v = 0; v < left.rows; ++v)
    for (int u = 0; u < left.cols; ++u) {
      map_x.at<float>(v, u) = static_cast<float>(u + trueDisparity(v, left.rows));
      map_y.at<float>(v, u) = static_cast<float>(v);
    }
  cv::Mat right;
  cv::remap(left, right, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);

  auto det = makeFeatureDetector(d);
  EXPECT_TRUE(det.ok());
  if (!det.ok()) return res;
  Features fl, fr;
  EXPECT_TRUE((*det)->detect(left, &fl).ok());
  EXPECT_TRUE((*det)->detect(right, &fr).ok());
  StereoMatchOptions o;
  o.focal_px = 450.0;
  o.baseline_m = 0.11;
  o.min_depth_m = 1.0;  // HD_max = 49.5 px > max true disparity 36 px
  const auto matches = matchStereo(fl, fr, o);
  int correct = 0;
  for (const StereoMatch& m : matches) {
    const cv::Point2f pl = fl.keypoints[static_cast<std::size_t>(m.left)].pt;
    const cv::Point2f pr = fr.keypoints[static_cast<std::size_t>(m.right)].pt;
    const double disparity = pl.x - pr.x;
    EXPECT_GT(disparity, 0.0);
    EXPECT_LE(disparity, o.maxHorizontalDisparity());
    EXPECT_LE(std::abs(pl.y - pr.y), o.max_vertical_disparity_px);
    // Localisation tolerance grows with the pyramid level (keypoint coordinates of level l
    // are quantised to the level's pixel, 1.2^l px for ORB).
    const int octave = fl.keypoints[static_cast<std::size_t>(m.left)].octave & 0xFF;
    const double tol = d.type == DetectorType::kOrb ? 1.5 * std::pow(1.2, octave) : 1.5;
    const double err = std::abs(disparity - trueDisparity(pl.y, left.rows));
    if (err < tol && std::abs(pl.y - pr.y) < tol) ++correct;
  }
  res.left_features = fl.size();
  res.right_features = fr.size();
  res.matches = matches.size();
  res.precision = matches.empty() ? 0.0 : static_cast<double>(correct) / matches.size();
  std::cout << "[figures] synthetic stereo (" << static_cast<int>(d.type)
            << (d.adaptive_sift.upsample_first_octave ? "" : ", first octave not upsampled")
            << "): " << fl.size() << "/" << fr.size() << " features, " << matches.size()
            << " matches, precision " << res.precision << "\n";
  return res;
}

class VisionStereoSynthetic : public ::testing::TestWithParam<DetectorType> {};

TEST_P(VisionStereoSynthetic, PrecisionAgainstKnownDisparity) {
  DetectorOptions d;
  d.type = GetParam();
  const SyntheticResult r = syntheticStereo(d);
  EXPECT_GE(r.matches, 100u);
  // Both detectors must reach 98 %. (Without the keypoint grid, ORB spends its budget on the
  // calibration checkerboard of this scene and falls to ≈ 92 %.)
  EXPECT_GE(r.precision, 0.98);
}

INSTANTIATE_TEST_SUITE_P(Detectors, VisionStereoSynthetic,
                         ::testing::Values(DetectorType::kAdaptiveSift, DetectorType::kOrb));

// The faster adaptive SIFT without the doubled first octave (adaptive_sift.h, item 4): its
// keypoints are mapped back to the input's pixel grid exactly (a coordinate error would show
// as a disparity or row error here), at the cost of fewer features.
TEST(VisionStereoSyntheticNoUpsample, PrecisionAgainstKnownDisparity) {
  DetectorOptions d;
  const SyntheticResult full = syntheticStereo(d);
  d.adaptive_sift.upsample_first_octave = false;
  const SyntheticResult fast = syntheticStereo(d);
  EXPECT_GE(fast.matches, 100u);
  EXPECT_GE(fast.precision, 0.98);
  EXPECT_LE(fast.left_features, full.left_features);
}

// Parameter: adaptive SIFT's upsample_first_octave (true: default).
class VisionStereoReal : public ::testing::TestWithParam<bool> {};

TEST_P(VisionStereoReal, RectifiedEurocPairHasRowAlignedPlausibleMatches) {
  StereoCalibration calib;
  ASSERT_TRUE(test::eurocCalibration(&calib));
  auto rect = StereoRectifier::create(calib);
  ASSERT_TRUE(rect.ok()) << rect.status().message();
  const RectifiedStereo& r = rect->rectified();
  DetectorOptions d;
  d.adaptive_sift.upsample_first_octave = GetParam();
  auto det = makeFeatureDetector(d);
  ASSERT_TRUE(det.ok());
  StereoMatchOptions o;
  o.focal_px = r.f;
  o.baseline_m = r.baseline;
  o.min_depth_m = 0.4;
  o.max_vertical_disparity_px = 4.0;  // wide band, so that row errors could show
  std::vector<std::pair<cv::Mat, cv::Mat>> pairs;
  ASSERT_TRUE(test::rectifiedEurocPairs(*rect, &pairs));
  std::vector<std::pair<cv::Point2f, cv::Point2f>> matches;
  for (const auto& [lr, rr] : pairs) {
    Features fl, fr;
    ASSERT_TRUE((*det)->detect(lr, &fl).ok());
    ASSERT_TRUE((*det)->detect(rr, &fr).ok());
    for (const StereoMatch& m : matchStereo(fl, fr, o))
      matches.push_back({fl.keypoints[static_cast<std::size_t>(m.left)].pt,
                         fr.keypoints[static_cast<std::size_t>(m.right)].pt});
  }
  // Vicon room: everything seen lies between 0.4 m and ≈ 10 m of the camera.
  const test::RealStereoSummary s = test::summariseRealStereo(matches, r.f, r.baseline);
  ASSERT_GT(s.total, 150);
  std::cout << "[figures] real rectified EuRoC stereo"
            << (GetParam() ? "" : " (first octave not upsampled)") << ": " << s.total
            << " matches in 3 pairs, "
            << "median row error " << s.median_row_error << " px, plausible " << s.plausible
            << "\n";
  EXPECT_LT(s.median_row_error, 0.5);  // rectification: epipolar lines are rows
  // Without the doubled octave: ≈ 18 % fewer matches and 96.7 % plausible against 98.2 %
  // (measured; docs/front_end.md), hence the option is off by default.
  EXPECT_GE(s.plausible, GetParam() ? 0.98 : 0.95);
}

INSTANTIATE_TEST_SUITE_P(UpsampleFirstOctave, VisionStereoReal, ::testing::Bool());

// Hand-made features: one left feature and one right candidate with the same descriptor; the
// candidate is moved through the constraints of §4.2.8 and §4.2.7.
TEST(VisionStereo, WindowAndScaleRateConstraints) {
  auto make = [](float u, float v, float size) {
    Features f;
    f.type = DescriptorType::kSift;
    f.keypoints.emplace_back(cv::Point2f(u, v), size);
    f.descriptors = cv::Mat(1, 128, CV_8U);
    for (int k = 0; k < 128; ++k) f.descriptors.at<uint8_t>(0, k) = static_cast<uint8_t>(k);
    return f;
  };
  StereoMatchOptions o;
  o.focal_px = 400;
  o.baseline_m = 0.1;
  o.min_depth_m = 1.0;  // HD_max = 40 px
  o.match.max_distance = 10;
  o.match.accept_single_candidate = true;
  const Features left = make(200, 100, 4);
  auto matched = [&](float u, float v, float size) {
    return matchStereo(left, make(u, v, size), o).size() == 1;
  };
  EXPECT_TRUE(matched(180, 100, 4));           // d = 20
  EXPECT_TRUE(matched(160.5f, 101.5f, 4.5f));  // d = 39.5, |Δv| = 1.5, rate 1.125
  EXPECT_FALSE(matched(159, 100, 4));          // d = 41 > HD_max
  EXPECT_FALSE(matched(200, 100, 4));          // d = 0
  EXPECT_FALSE(matched(210, 100, 4));          // d < 0
  EXPECT_FALSE(matched(180, 102.5f, 4));       // |Δv| > VD_max
  EXPECT_FALSE(matched(180, 100, 6));          // scale rate 1.5 > 2^0.5
  o.scale_rate_tolerance_log2 = 0;             // check disabled
  EXPECT_TRUE(matched(180, 100, 6));
  o.match.accept_single_candidate = false;  // no second candidate, no ratio test: refused
  EXPECT_FALSE(matched(180, 100, 4));
}

TEST(VisionStereo, OptionsCheck) {
  StereoMatchOptions o;
  EXPECT_FALSE(o.check().ok());  // focal and baseline required
  o.focal_px = 450;
  o.baseline_m = 0.11;
  EXPECT_TRUE(o.check().ok());
  o.min_depth_m = 0.5;
  EXPECT_DOUBLE_EQ(o.maxHorizontalDisparity(), 450 * 0.11 / 0.5);  // HD_max = f·b/z_min
}

}  // namespace
}  // namespace cvslam::vision
