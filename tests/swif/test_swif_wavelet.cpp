// The Daubechies filter bank under SWIF (daubechies.h; thesis §4.4.3.1): orthonormal filters
// and one DWT level that has no detail on a flat image.

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "cvslam/vision/daubechies.h"

namespace cvslam::vision {
namespace {

TEST(SwifWavelet, DaubechiesFiltersAreOrthonormal) {
  for (int order = 1; order <= kMaxDaubechiesOrder; ++order) {
    const std::vector<double>& h = daubechiesLowPass(order);
    ASSERT_EQ(static_cast<int>(h.size()), 2 * order) << "db" << order;
    EXPECT_NEAR(std::accumulate(h.begin(), h.end(), 0.0), std::sqrt(2.0), 1e-12) << "db" << order;
    // Σ h[n] h[n + 2k] = δ_k: orthogonal to its even shifts (Daubechies 1992).
    for (int k = 0; k < order; ++k) {
      double dot = 0.0;
      for (std::size_t n = 0; n + 2 * static_cast<std::size_t>(k) < h.size(); ++n)
        dot += h[n] * h[n + 2 * static_cast<std::size_t>(k)];
      EXPECT_NEAR(dot, k == 0 ? 1.0 : 0.0, 1e-12) << "db" << order << " shift " << 2 * k;
    }
  }
  EXPECT_TRUE(daubechiesLowPass(0).empty());
  EXPECT_TRUE(daubechiesLowPass(kMaxDaubechiesOrder + 1).empty());
}

TEST(SwifWavelet, FlatImageHasNoDetailAndScaledApproximation) {
  const cv::Mat flat(64, 80, CV_32F, cv::Scalar(100.0));
  for (int order : {1, 2, 6}) {
    WaveletLevel w;
    waveletLevel(flat, order, true, &w);
    EXPECT_LT(cv::norm(w.horizontal, cv::NORM_INF), 1e-3) << "db" << order;
    EXPECT_LT(cv::norm(w.vertical, cv::NORM_INF), 1e-3);
    EXPECT_LT(cv::norm(w.diagonal, cv::NORM_INF), 1e-3);
    ASSERT_EQ(w.next.size(), cv::Size(40, 32));
    // DC gain of the orthonormal low-pass is √2 per axis: 2 per level.
    EXPECT_NEAR(cv::mean(w.next)[0], 200.0, 1e-3);
  }
}

}  // namespace
}  // namespace cvslam::vision
