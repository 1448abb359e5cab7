#pragma once
// Synthetic textured images for the mosaic tests (seeded, deterministic).

#include <opencv2/imgproc.hpp>

#include <cstdint>

namespace cvslam::test {

/// Grey image with random disks, rectangles and noise, slightly blurred (SIFT-friendly).
inline cv::Mat texturedImage(cv::Size size, uint64_t seed, int shapes = 400, double blur = 1.0) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8U, cv::Scalar(128));
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const int r = rng.uniform(2, 14);
    const cv::Scalar grey(rng.uniform(20, 235));
    if (i % 2)
      cv::circle(img, c, r, grey, cv::FILLED, cv::LINE_AA);
    else
      cv::rectangle(img, cv::Rect(c.x, c.y, r + 2, rng.uniform(3, 16)), grey, cv::FILLED);
  }
  cv::Mat noise(size, CV_8U);
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  img += noise;
  cv::GaussianBlur(img, img, cv::Size(0, 0), blur);
  return img;
}

}  // namespace cvslam::test
