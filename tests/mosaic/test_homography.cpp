// Geometric registration (thesis §4.3.3.1): DLT, RANSAC + refinement, and registration of a
// synthetic image warped by a known homography.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "cvslam/core/random.h"
#include "cvslam/io/config_node.h"
#include "cvslam/mosaic/geometric_registration.h"
#include "cvslam/mosaic/homography.h"
#include "mosaic/mosaic_test_images.h"

namespace cvslam::mosaic {
namespace {

Eigen::Matrix3d knownHomography() {
  Eigen::Matrix3d H;
  // Rotation by ~8°, scale 1.05, shift, and a mild perspective (a tilted ground plane).
  H << 1.04, -0.146, 12.5, 0.146, 1.04, -7.25, 2e-4, -1.5e-4, 1.0;
  return H;
}

// Largest distance between where the two homographies send a grid of points of the image.
double maxGridError(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B, cv::Size size) {
  double e = 0.0;
  for (int v = 0; v <= size.height; v += size.height / 8)
    for (int u = 0; u <= size.width; u += size.width / 8)
      e = std::max(
          e, (applyHomography(A, Eigen::Vector2d(u, v)) - applyHomography(B, Eigen::Vector2d(u, v)))
                 .norm());
  return e;
}

double uniform(uint64_t& state, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;
}

TEST(Homography, DltRecoversExactHomographyFromFourPoints) {
  const Eigen::Matrix3d H = knownHomography();
  std::vector<Eigen::Vector2d> src = {{0, 0}, {300, 10}, {290, 230}, {5, 220}}, dst;
  for (const auto& p : src) dst.push_back(applyHomography(H, p));
  const auto est = homographyDlt(src, dst);
  ASSERT_TRUE(est.ok()) << est.status().message();
  EXPECT_LT(maxGridError(*est, H, {320, 240}), 1e-6);
}

TEST(Homography, RansacRejectsOutliersAndRefinesToSubPixel) {
  const Eigen::Matrix3d H = knownHomography();
  uint64_t state = 42;
  std::vector<Eigen::Vector2d> src, dst;
  const int n = 200, outliers = 70;  // 35 % wrong matches
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d p(uniform(state, 0, 320), uniform(state, 0, 240));
    src.push_back(p);
    if (i < outliers) {
      dst.emplace_back(uniform(state, -50, 370), uniform(state, -50, 290));
    } else {
      const Eigen::Vector2d noise(uniform(state, -0.5, 0.5), uniform(state, -0.5, 0.5));
      dst.push_back(applyHomography(H, p) + noise);
    }
  }
  HomographyOptions o;
  o.seed = 7;
  const auto est = estimateHomography(src, dst, o);
  ASSERT_TRUE(est.ok()) << est.status().message();
  int wrong_kept = 0;
  for (int i = 0; i < outliers; ++i) wrong_kept += est->inliers[static_cast<std::size_t>(i)];
  // A random outlier may fall within the 2 px gate by chance; hardly more than one.
  EXPECT_LE(wrong_kept, 1);
  EXPECT_GE(est->inlier_count, n - outliers - 2);
  EXPECT_LT(maxGridError(est->H, H, {320, 240}), 0.3);
  // The plain DLT on all matches is ruined by the outliers: RANSAC is what makes it work.
  const auto naive = homographyDlt(src, dst);
  ASSERT_TRUE(naive.ok());
  EXPECT_GT(maxGridError(*naive, H, {320, 240}), 5.0);
}

TEST(Homography, TooFewMatchesFailWithAMessage) {
  std::vector<Eigen::Vector2d> src = {{0, 0}, {1, 0}, {0, 1}}, dst = src;
  const auto est = estimateHomography(src, dst, HomographyOptions{});
  ASSERT_FALSE(est.ok());
  EXPECT_NE(est.status().message().find("need"), std::string::npos);
}

TEST(GeometricRegistration, RecoversKnownWarpOfSyntheticImageToSubPixel) {
  const cv::Size size(320, 240);
  const cv::Mat image = test::texturedImage(size, 11);
  const Eigen::Matrix3d H = knownHomography();
  cv::Matx33d M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = H(r, c);
  cv::Mat warped;  // warped(H x) = image(x)
  cv::warpPerspective(image, warped, M, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  RegistrationOptions o;
  const auto reg = registerImages(image, warped, o);
  ASSERT_TRUE(reg.ok()) << reg.status().message();
  EXPECT_GE(reg->estimate.inlier_count, 30);
  // Points of the image that stay inside the warped image.
  double e = 0.0;
  for (int v = 40; v <= 200; v += 20)
    for (int u = 40; u <= 280; u += 20)
      e = std::max(e, (applyHomography(reg->estimate.H, Eigen::Vector2d(u, v)) -
                       applyHomography(H, Eigen::Vector2d(u, v)))
                          .norm());
  EXPECT_LT(e, 0.5);
}

TEST(HomographyOptions, RejectsInvalidValues) {
  auto node = ConfigNode::fromString("ransac_threshold_px: -1\n", "test");
  ASSERT_TRUE(node.ok());
  HomographyOptions o;
  const Status s = o.load(*node);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("ransac_threshold_px"), std::string::npos);
}

}  // namespace
}  // namespace cvslam::mosaic
