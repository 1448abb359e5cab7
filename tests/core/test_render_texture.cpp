#include "cvslam/render/texture_bank.h"

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>

#include "cvslam/core/random.h"

namespace cvslam {
namespace {

// Bilinear interpolation straight from the row-major mip image (texel centres at i + 0.5).
float referenceSample(const cv::Mat& m, float s, float t, int level) {
  const double x = s / (1 << level) - 0.5, y = t / (1 << level) - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double ax = x - x0, ay = y - y0;
  auto at = [&](int xi, int yi) {
    const int n = m.cols;
    return static_cast<double>(m.at<uint8_t>((yi % n + n) % n, (xi % n + n) % n));
  };
  const double top = at(x0, y0) + ax * (at(x0 + 1, y0) - at(x0, y0));
  const double bottom = at(x0, y0 + 1) + ax * (at(x0 + 1, y0 + 1) - at(x0, y0 + 1));
  return static_cast<float>(top + ay * (bottom - top));
}

TEST(TextureBank, BlockedSamplingMatchesTheMipImages) {
  render::TextureOptions o;
  o.tile_size = 256;
  o.tile_count = 2;
  auto bank = render::TextureBank::create(o);
  ASSERT_TRUE(bank.ok());
  EXPECT_EQ(bank->levels(), 6);  // 256 … 8
  Rng rng(3);
  for (int k = 0; k < 2000; ++k) {
    const int tile = static_cast<int>(rng.below(2)), level = static_cast<int>(rng.below(bank->levels()));
    const auto s = static_cast<float>(rng.uniform(0, 256)),
               t = static_cast<float>(rng.uniform(0, 256));
    ASSERT_NEAR(bank->sample(tile, level, s, t),
                referenceSample(bank->tile(tile, level), s, t, level), 0.02)
        << "tile " << tile << " level " << level << " at " << s << ", " << t;
  }
}

TEST(TextureBank, VariantsDifferInCornerCount) {
  render::TextureOptions o;
  o.tile_size = 512;
  o.tile_count = 1;
  auto high = render::TextureBank::create(o);
  o.variant = render::TextureVariant::kLow;
  auto low = render::TextureBank::create(o);
  ASSERT_TRUE(high.ok() && low.ok());
  std::vector<cv::KeyPoint> kh, kl;
  cv::FAST(high->tile(0, 0), kh, 20);
  cv::FAST(low->tile(0, 0), kl, 20);
  EXPECT_GT(kh.size(), 10 * std::max<std::size_t>(kl.size(), 1));
}

}  // namespace
}  // namespace cvslam
