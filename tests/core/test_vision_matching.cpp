// Matching criteria (thesis §4.2.6) and scale-rate stability (§4.2.7) on a real EuRoC frame
// warped by a known homography (frame-to-frame ground truth).

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/feature_detector.h"
#include "vision_test_data.h"

namespace cvslam::vision {
namespace {

TEST(VisionDistance, Criteria) {
  uint8_t a[128] = {};
  uint8_t b[128] = {};
  a[3] = 10;
  b[3] = 4;
  a[100] = 3;
  b[7] = 200;
  EXPECT_EQ(distanceLinf(a, b, 128), 200);
  EXPECT_EQ(distanceL2Squared(a, b, 128), 36 + 9 + 40000);
  EXPECT_DOUBLE_EQ(descriptorDistance(MatchNorm::kL2, a, b, 128), std::sqrt(40045.0));
  EXPECT_EQ(dotProduct(a, b, 128), 40);
  const double cosine = 40.0 / (std::sqrt(109.0) * std::sqrt(16.0 + 40000.0));
  EXPECT_NEAR(descriptorDistance(MatchNorm::kAngle, a, b, 128), std::acos(cosine), 1e-12);
  EXPECT_NEAR(descriptorDistance(MatchNorm::kAngle, a, a, 128), 0.0, 1e-6);
  uint8_t x[32] = {};
  uint8_t y[32] = {};
  x[0] = 0xFF;
  y[31] = 0x0F;
  x[9] = 0x01;
  EXPECT_EQ(distanceHamming(x, y, 32), 8 + 4 + 1);
}

// Ratio test on a hand-made set: a query with two near-identical train descriptors is rejected.
TEST(VisionMatcher, DistRatioRejectsAmbiguousMatches) {
  Features q, t;
  q.type = t.type = DescriptorType::kSift;
  q.descriptors = cv::Mat::zeros(2, 128, CV_8U);
  t.descriptors = cv::Mat::zeros(3, 128, CV_8U);
  q.keypoints.resize(2);
  t.keypoints.resize(3);
  q.descriptors.at<uint8_t>(0, 0) = 100;  // unique: matches train 0
  t.descriptors.at<uint8_t>(0, 0) = 98;
  q.descriptors.at<uint8_t>(1, 5) = 100;  // ambiguous: train 1 and 2 equally close
  t.descriptors.at<uint8_t>(1, 5) = 97;
  t.descriptors.at<uint8_t>(2, 5) = 103;
  for (MatchNorm n : {MatchNorm::kLinf, MatchNorm::kL2, MatchNorm::kAngle}) {
    MatchOptions o;
    o.norm = n;
    const auto m = matchDescriptors(q, t, o);
    ASSERT_EQ(m.size(), 1u) << static_cast<int>(n);
    EXPECT_EQ(m[0].query, 0);
    EXPECT_EQ(m[0].train, 0);
  }
}

struct WarpedPair {
  cv::Mat a, b;
  cv::Matx33d H;  // b = H(a)
};

WarpedPair warpedRealFrame(double scale) {
  WarpedPair p;
  const auto stamps = test::eurocStereoStamps();
  cv::Mat r;
  if (stamps.size() < 10 || !test::loadEurocPair(stamps[10], &p.a, &r)) return p;
  const double c = std::cos(0.09), s = std::sin(0.09);  // ≈ 5° roll
  const cv::Matx33d to_centre(1, 0, -376, 0, 1, -240, 0, 0, 1);
  const cv::Matx33d rot(scale * c, -scale * s, 0, scale * s, scale * c, 0, 2e-5, -1e-5, 1);
  const cv::Matx33d back(1, 0, 376 + 9, 0, 1, 240 - 6, 0, 0, 1);
  p.H = back * rot * to_centre;
  cv::warpPerspective(p.a, p.b, cv::Mat(p.H), p.a.size(), cv::INTER_LINEAR);
  return p;
}

struct Score {
  int matches = 0;
  int correct = 0;
  double precision() const { return matches ? static_cast<double>(correct) / matches : 0.0; }
};

Score score(const std::vector<Match>& m, const Features& fa, const Features& fb,
            const cv::Matx33d& H) {
  Score s;
  for (const Match& x : m) {
    const cv::Point2f pa = fa.keypoints[static_cast<std::size_t>(x.query)].pt;
    const cv::Point2f pb = fb.keypoints[static_cast<std::size_t>(x.train)].pt;
    const cv::Vec3d h = H * cv::Vec3d(pa.x, pa.y, 1.0);
    const double err = std::hypot(h[0] / h[2] - pb.x, h[1] / h[2] - pb.y);
    // Localisation tolerance grows with the pyramid level (ORB: coordinates of level l are
    // quantised to 1.2^l px; SIFT's octave field is packed and its positions sub-pixel).
    const int octave = fa.keypoints[static_cast<std::size_t>(x.query)].octave;
    const double tol =
        fa.type == DescriptorType::kOrb ? 2.5 * std::pow(1.2, std::clamp(octave, 0, 10)) : 2.5;
    ++s.matches;
    if (err < tol) ++s.correct;
  }
  return s;
}

class VisionFrameToFrame : public ::testing::TestWithParam<DetectorType> {};

TEST_P(VisionFrameToFrame, PrecisionOnKnownHomography) {
  const WarpedPair p = warpedRealFrame(1.1);
  ASSERT_FALSE(p.a.empty()) << "EuRoC micro data missing under " << test::sharedDataDir();
  DetectorOptions d;
  d.type = GetParam();
  auto det = makeFeatureDetector(d);
  ASSERT_TRUE(det.ok());
  Features fa, fb;
  ASSERT_TRUE((*det)->detect(p.a, &fa).ok());
  ASSERT_TRUE((*det)->detect(p.b, &fb).ok());
  // Predicted-motion gate, as the front end uses it (predicted projection ± 25 px): the
  // motion prediction is off by (6, −4) px.
  std::vector<cv::Point2f> predicted;
  for (const cv::KeyPoint& k : fa.keypoints) {
    const cv::Vec3d h = p.H * cv::Vec3d(k.pt.x, k.pt.y, 1.0);
    predicted.emplace_back(static_cast<float>(h[0] / h[2] + 6),
                           static_cast<float>(h[1] / h[2] - 4));
  }
  const auto gate = candidatesNear(predicted, fb, 25.0);
  if (GetParam() == DetectorType::kOrb) {
    MatchOptions o;
    o.dist_ratio = 0.7;
    const Score global = score(matchDescriptors(fa, fb, o), fa, fb, p.H);
    const Score gated = score(matchDescriptors(fa, fb, o, &gate), fa, fb, p.H);
    std::cout << "[figures] ORB frame-to-frame: whole image " << global.matches
              << " matches, precision " << global.precision() << "; gated " << gated.matches
              << " matches, precision " << gated.precision() << "\n";
    // Known limitation, measured: ORB's binary tests confuse the repeated corners of this
    // scene (the calibration checkerboard holds most of the wrong matches); the keypoint grid
    // (keypoint_grid.h) lifts whole-image precision from 56 % to ≈ 90 %, but ORB does not reach
    // SIFT's ≥ 97 % frame to frame here, so it gets regression bounds only. SIFT is the
    // thesis's detector; ORB is the fast option.
    EXPECT_GE(gated.matches, 80);
    EXPECT_GE(gated.precision(), 0.9);
    EXPECT_GE(global.precision(), 0.85);
    return;
  }
  {
    MatchOptions o;
    const Score gated = score(matchDescriptors(fa, fb, o, &gate), fa, fb, p.H);
    std::cout << "[figures] SIFT L-inf gated: " << gated.matches << " matches, precision "
              << gated.precision() << "\n";
    EXPECT_GE(gated.precision(), 0.97);
  }
  Score by_norm[3];
  const MatchNorm norms[3] = {MatchNorm::kLinf, MatchNorm::kL2, MatchNorm::kAngle};
  for (int k = 0; k < 3; ++k) {
    MatchOptions o;
    o.norm = norms[k];
    o.dist_ratio = 0.8;
    by_norm[k] = score(matchDescriptors(fa, fb, o), fa, fb, p.H);
    std::cout << "[figures] SIFT frame-to-frame norm " << k
              << " (0 Linf, 1 L2, 2 angle): " << by_norm[k].matches << " matches, precision "
              << by_norm[k].precision() << "\n";
    EXPECT_GE(by_norm[k].matches, 50);
    EXPECT_GE(by_norm[k].precision(), 0.97);
  }
  // §4.2.6: the ∞-norm keeps fewer, but at least as precise, matches as the 2-norm.
  EXPECT_LT(by_norm[0].matches, by_norm[1].matches);
  EXPECT_GE(by_norm[0].precision(), by_norm[1].precision());
}

INSTANTIATE_TEST_SUITE_P(Detectors, VisionFrameToFrame,
                         ::testing::Values(DetectorType::kAdaptiveSift, DetectorType::kOrb));

TEST(VisionMatcher, ScaleRateFilterKeepsTheZoomAndDropsOutliers) {
  const WarpedPair p = warpedRealFrame(1.5);
  ASSERT_FALSE(p.a.empty());
  DetectorOptions d;
  auto det = makeFeatureDetector(d);
  ASSERT_TRUE(det.ok());
  Features fa, fb;
  ASSERT_TRUE((*det)->detect(p.a, &fa).ok());
  ASSERT_TRUE((*det)->detect(p.b, &fb).ok());
  MatchOptions o;
  o.norm = MatchNorm::kL2;
  std::vector<Match> m = matchDescriptors(fa, fb, o);
  ASSERT_GE(m.size(), 20u);
  // Corrupt a few matches with a wrong partner of a very different scale.
  int planted = 0;
  for (std::size_t j = 0; j < fb.size() && planted < 5; ++j) {
    if (fb.keypoints[j].size > 8.0f * fa.keypoints[static_cast<std::size_t>(m[0].query)].size) {
      m.push_back({m[static_cast<std::size_t>(planted)].query, static_cast<int>(j), 0.0});
      ++planted;
    }
  }
  const auto kept = filterByScaleRate(m, fa, fb, 0.0, 0.5);  // median rate ≈ 1.5
  const auto known = filterByScaleRate(m, fa, fb, 1.5, 0.5);
  for (const auto* set : {&kept, &known}) {
    EXPECT_LE(set->size(), m.size() - static_cast<std::size_t>(planted));
    EXPECT_GE(set->size(), (m.size() - static_cast<std::size_t>(planted)) * 8 / 10);
    for (const Match& x : *set) {
      const double rate = fb.keypoints[static_cast<std::size_t>(x.train)].size /
                          fa.keypoints[static_cast<std::size_t>(x.query)].size;
      EXPECT_NEAR(std::log2(rate), std::log2(1.5), 0.5 + 1e-9);
    }
  }
}

}  // namespace
}  // namespace cvslam::vision
