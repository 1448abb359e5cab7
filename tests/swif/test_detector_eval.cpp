// The evaluation metrics SWIF is judged by (detector_eval.h; thesis §4.4.5, §4.4.7.2), on
// hand-made keypoints whose answers are known.

#include <gtest/gtest.h>

#include "cvslam/vision/detector_eval.h"

namespace cvslam::vision {
namespace {

const cv::Size kSize(100, 80);

std::vector<cv::KeyPoint> grid(float dx, float dy) {
  std::vector<cv::KeyPoint> k;
  for (int y = 10; y < 80; y += 20)
    for (int x = 10; x < 100; x += 20)
      k.emplace_back(cv::Point2f(static_cast<float>(x) + dx, static_cast<float>(y) + dy), 4.0f);
  return k;
}

TEST(DetectorEval, RepeatabilityCountsOneToOnePairsWithinEps) {
  const auto a = grid(0, 0);  // 5 × 4 = 20 points
  const cv::Matx33d I = cv::Matx33d::eye();
  EXPECT_DOUBLE_EQ(repeatability(a, kSize, a, kSize, I, 1.0).repeatability, 1.0);
  EXPECT_DOUBLE_EQ(repeatability(a, kSize, grid(0.5f, 0.5f), kSize, I, 1.0).repeatability, 1.0);
  EXPECT_DOUBLE_EQ(repeatability(a, kSize, grid(3, 0), kSize, I, 1.0).repeatability, 0.0);
  // A shift by 10 px in the homography: the shifted set repeats exactly; half of the points of a
  // column leave the image.
  const cv::Matx33d T(1, 0, 20, 0, 1, 0, 0, 0, 1);
  const auto r = repeatability(a, kSize, grid(20, 0), kSize, T, 1.0);
  EXPECT_EQ(r.visible_a, 16);  // x = 90 → 110 leaves the 100-px image
  EXPECT_EQ(r.correspondences, 16);
  EXPECT_DOUBLE_EQ(r.repeatability, 1.0);
  // One-to-one: two points of b near one of a count once.
  std::vector<cv::KeyPoint> one{cv::KeyPoint(cv::Point2f(50, 40), 4)};
  std::vector<cv::KeyPoint> two{cv::KeyPoint(cv::Point2f(50.2f, 40), 4),
                                cv::KeyPoint(cv::Point2f(49.8f, 40), 4)};
  EXPECT_EQ(repeatability(one, kSize, two, kSize, I, 1.0).correspondences, 1);
}

TEST(DetectorEval, MatchQualityUnderHomographyAndStereo) {
  Features a, b;
  a.keypoints = grid(0, 0);
  b.keypoints = grid(-5, 0.5f);  // b = a shifted 5 px left (a disparity of 5), 0.5 px down
  std::vector<Match> m;
  for (int i = 0; i < 20; ++i) m.push_back({i, i, 0.0});
  m.push_back({0, 1, 0.0});  // one wrong match
  const cv::Matx33d T(1, 0, -5, 0, 1, 0.5, 0, 0, 1);
  const MatchQuality h = matchQualityHomography(a, b, m, T, 1.0);
  EXPECT_EQ(h.matches, 21);
  EXPECT_EQ(h.correct, 20);
  EXPECT_DOUBLE_EQ(h.precision, 20.0 / 21.0);
  EXPECT_DOUBLE_EQ(h.matching_score, 1.0);
  const MatchQuality s = matchQualityStereo(a, b, m, 1.0, 0.0, 100.0);
  EXPECT_EQ(s.correct, 20);  // the wrong match has disparity −15
  EXPECT_EQ(matchQualityStereo(a, b, m, 0.25, 0.0, 100.0).correct, 0);  // rows differ by 0.5
  EXPECT_EQ(matchQualityFundamental(a, b, {m.begin(), m.begin() + 5}, 1.0).correct, 0);  // < 8
}

}  // namespace
}  // namespace cvslam::vision
