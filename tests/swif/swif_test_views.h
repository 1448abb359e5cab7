#pragma once
// The rendered ground image the SWIF tests transform (render/view_changes.h), made once.

#include <gtest/gtest.h>

#include "cvslam/render/view_changes.h"

namespace cvslam::test {

constexpr int kGroundSide = 1024;
constexpr uint64_t kGroundSeed = 1;
inline const cv::Size kViewSize(640, 480);

inline const cv::Mat& groundImage() {
  static const cv::Mat ground = [] {
    auto g = render::renderGroundImage(kGroundSide, kGroundSeed);
    return g.ok() ? *g : cv::Mat();
  }();
  return ground;
}

}  // namespace cvslam::test
