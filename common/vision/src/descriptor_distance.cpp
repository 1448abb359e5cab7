#include "cvslam/vision/descriptor_distance.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/hal/hal.hpp>

namespace cvslam::vision {

int distanceHamming(const uint8_t* a, const uint8_t* b, int n) {
  // OpenCV's SIMD popcount (the plain loop compiles to a table/bit trick without -mpopcnt).
  return cv::hal::normHamming(a, b, n);
}

double descriptorDistance(MatchNorm norm, const uint8_t* a, const uint8_t* b, int n, double norm_a,
                          double norm_b) {
  switch (norm) {
    case MatchNorm::kLinf:
      return distanceLinf(a, b, n);
    case MatchNorm::kL2:
      return std::sqrt(static_cast<double>(distanceL2Squared(a, b, n)));
    case MatchNorm::kAngle: {
      if (norm_a <= 0) norm_a = std::sqrt(static_cast<double>(dotProduct(a, a, n)));
      if (norm_b <= 0) norm_b = std::sqrt(static_cast<double>(dotProduct(b, b, n)));
      if (norm_a <= 0 || norm_b <= 0) return M_PI / 2;
      const double c = dotProduct(a, b, n) / (norm_a * norm_b);
      return std::acos(std::clamp(c, -1.0, 1.0));
    }
    case MatchNorm::kHamming:
      return distanceHamming(a, b, n);
  }
  return 0.0;
}

}  // namespace cvslam::vision
