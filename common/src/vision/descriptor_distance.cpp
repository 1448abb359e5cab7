#include "cvslam/vision/descriptor_distance.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace cvslam::vision {

int distanceLinf(const uint8_t* a, const uint8_t* b, int n) {
  uint8_t m = 0;
  for (int k = 0; k < n; ++k) {
    const uint8_t d =
        a[k] > b[k] ? static_cast<uint8_t>(a[k] - b[k]) : static_cast<uint8_t>(b[k] - a[k]);
    m = d > m ? d : m;
  }
  return m;
}

int distanceL2Squared(const uint8_t* a, const uint8_t* b, int n) {
  int s = 0;
  for (int k = 0; k < n; ++k) {
    const int d = static_cast<int>(a[k]) - static_cast<int>(b[k]);
    s += d * d;
  }
  return s;
}

int dotProduct(const uint8_t* a, const uint8_t* b, int n) {
  int s = 0;
  for (int k = 0; k < n; ++k) s += static_cast<int>(a[k]) * static_cast<int>(b[k]);
  return s;
}

int distanceHamming(const uint8_t* a, const uint8_t* b, int n) {
  int s = 0;
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    uint64_t x = 0;
    uint64_t y = 0;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    s += __builtin_popcountll(x ^ y);
  }
  for (; k < n; ++k) s += __builtin_popcount(static_cast<unsigned>(a[k] ^ b[k]));
  return s;
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
