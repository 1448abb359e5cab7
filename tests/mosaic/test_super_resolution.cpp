// Super-resolution (thesis §4.3.4, Papoulis–Gerchberg): from several low-resolution images
// shifted by known sub-pixel amounts, the high-resolution image is recovered better than by
// bicubic up-sampling of one of them.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "cvslam/core/random.h"
#include "cvslam/mosaic/super_resolution.h"
#include "mosaic/mosaic_test_images.h"

namespace cvslam::mosaic {
namespace {

struct Scene {
  cv::Mat truth;                    // HR image, CV_32F
  std::vector<LowResFrame> frames;  // LR images with their LR → HR maps
};

// LR pixel (u, v) samples the HR image at (scale·u + dx, scale·v + dy) (point sampling, as
// the renderer samples the ground texture at pixel centres).
Scene makeScene(int scale, int count, uint64_t seed) {
  Scene s;
  test::texturedImage({192, 160}, seed, 300, 0.7).convertTo(s.truth, CV_32F);
  uint64_t state = seed;
  for (int k = 0; k < count; ++k) {
    const double dx = k == 0 ? 0.0 : static_cast<double>(splitmix64(state) % 1000) / 1000 * scale;
    const double dy = k == 0 ? 0.0 : static_cast<double>(splitmix64(state) % 1000) / 1000 * scale;
    const cv::Matx23d lr_to_hr(scale, 0, dx, 0, scale, dy);
    cv::Mat lr;
    cv::warpAffine(s.truth, lr, lr_to_hr, {s.truth.cols / scale, s.truth.rows / scale},
                   cv::INTER_CUBIC | cv::WARP_INVERSE_MAP, cv::BORDER_REFLECT);
    LowResFrame f;
    lr.convertTo(f.image, CV_8U);
    f.H_to_hr << scale, 0, dx, 0, scale, dy, 0, 0, 1;
    s.frames.push_back(f);
  }
  return s;
}

cv::Mat bicubic(const LowResFrame& f, cv::Size hr) {
  const cv::Matx23d hr_to_lr(1.0 / f.H_to_hr(0, 0), 0, -f.H_to_hr(0, 2) / f.H_to_hr(0, 0), 0,
                             1.0 / f.H_to_hr(1, 1), -f.H_to_hr(1, 2) / f.H_to_hr(1, 1));
  cv::Mat up;
  cv::warpAffine(f.image, up, hr_to_lr, hr, cv::INTER_CUBIC | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  up.convertTo(up, CV_32F);
  return up;
}

TEST(SuperResolution, PapoulisGerchbergBeatsBicubicUpsampling) {
  const int scale = 2;
  const Scene s = makeScene(scale, 8, 21);
  const cv::Mat up = bicubic(s.frames[0], s.truth.size());
  SuperResolutionOptions o;
  o.scale = scale;
  const auto sr = papoulisGerchberg(s.frames, s.truth.size(), o, up);
  ASSERT_TRUE(sr.ok()) << sr.status().message();
  // Compare away from the border (the bicubic reference replicates it).
  const cv::Rect inner(8, 8, s.truth.cols - 16, s.truth.rows - 16);
  const double p_sr = psnr((*sr)(inner), s.truth(inner));
  const double p_bicubic = psnr(up(inner), s.truth(inner));
  RecordProperty("psnr_sr_db", std::to_string(p_sr));
  RecordProperty("psnr_bicubic_db", std::to_string(p_bicubic));
  EXPECT_GT(p_sr, p_bicubic + 2.0) << "SR " << p_sr << " dB, bicubic " << p_bicubic << " dB";
}

TEST(SuperResolution, OneFrameGivesNoGain) {
  // With a single LR frame there is nothing to fuse: PG must not invent detail (its PSNR stays
  // close to bicubic's), which shows the gain above comes from the extra frames.
  const int scale = 2;
  const Scene s = makeScene(scale, 1, 22);
  const cv::Mat up = bicubic(s.frames[0], s.truth.size());
  SuperResolutionOptions o;
  o.scale = scale;
  const auto sr = papoulisGerchberg(s.frames, s.truth.size(), o, up);
  ASSERT_TRUE(sr.ok());
  const cv::Rect inner(8, 8, s.truth.cols - 16, s.truth.rows - 16);
  EXPECT_LT(psnr((*sr)(inner), s.truth(inner)), psnr(up(inner), s.truth(inner)) + 1.0);
}

TEST(SuperResolution, PsnrOfIdenticalImagesIsHighAndOfNoiseLow) {
  const cv::Mat a = test::texturedImage({64, 64}, 3);
  EXPECT_GT(psnr(a, a), 100.0);
  cv::Mat b = a.clone();
  b += cv::Scalar(10);
  EXPECT_NEAR(psnr(a, b), 10 * std::log10(255.0 * 255.0 / 100.0), 0.5);
}

}  // namespace
}  // namespace cvslam::mosaic
