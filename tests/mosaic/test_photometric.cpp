// Photometric registration (thesis §4.3.3.3, eq. 4.26): a known gain and bias between two
// aligned images are recovered by orthogonal regression, despite noise and outliers.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "cvslam/mosaic/photometric_registration.h"
#include "mosaic/mosaic_test_images.h"

namespace cvslam::mosaic {
namespace {

TEST(PhotometricRegistration, RecoversKnownGainAndBias) {
  const cv::Mat image = test::texturedImage({200, 150}, 5);
  const double gain = 1.25, bias = -18.0;
  cv::Mat ref;
  image.convertTo(ref, CV_32F, gain, bias);
  // Noise in both images (orthogonal regression is unbiased for it; OLS would not be).
  cv::RNG rng(9);
  cv::Mat n1(image.size(), CV_32F), n2(image.size(), CV_32F), noisy;
  rng.fill(n1, cv::RNG::NORMAL, 0, 2.0);
  rng.fill(n2, cv::RNG::NORMAL, 0, 2.0);
  image.convertTo(noisy, CV_32F);
  noisy += n1;
  ref += n2;
  // A block where the images disagree (a moving object, a seam): outliers.
  ref(cv::Rect(10, 10, 40, 30)).setTo(255.0);
  const auto g = estimateGainBias(noisy, ref, cv::Mat(), PhotometricOptions{});
  ASSERT_TRUE(g.ok()) << g.status().message();
  EXPECT_NEAR(g->gain, gain, 0.01);
  EXPECT_NEAR(g->bias, bias, 1.5);
  EXPECT_LT(g->pixels, image.rows * image.cols);  // the outlier block was dropped
}

TEST(PhotometricRegistration, UsesOnlyMaskedPixels) {
  const cv::Mat image = test::texturedImage({120, 100}, 6);
  cv::Mat ref;
  image.convertTo(ref, CV_32F, 0.8, 30.0);
  cv::Mat mask(image.size(), CV_8U, cv::Scalar(0));
  mask(cv::Rect(0, 0, 60, 100)).setTo(255);
  ref(cv::Rect(60, 0, 60, 100)).setTo(0.0);  // garbage outside the mask
  const auto g = estimateGainBias(image, ref, mask, PhotometricOptions{});
  ASSERT_TRUE(g.ok()) << g.status().message();
  EXPECT_NEAR(g->gain, 0.8, 0.01);
  EXPECT_NEAR(g->bias, 30.0, 1.0);
}

TEST(PhotometricRegistration, TooLittleOverlapFails) {
  const cv::Mat image = test::texturedImage({20, 20}, 7);
  const auto g = estimateGainBias(image, image, cv::Mat(), PhotometricOptions{});
  EXPECT_FALSE(g.ok());  // 400 pixels < min_pixels
}

}  // namespace
}  // namespace cvslam::mosaic
