#pragma once
// Descriptor distances of the thesis's matching criteria (§4.2.6), on byte descriptors:
//   orientation (angle):  acos(D_i·D_j / (‖D_i‖ ‖D_j‖))
//   Euclidean (L2):       ‖D_i − D_j‖₂
//   infinity norm (L∞):   max_k |D_i,k − D_j,k|
// and Hamming for binary (ORB) descriptors. Loops are plain integer loops over contiguous
// bytes (no branches, fixed length), which GCC/Clang vectorise at -O2/-O3.

#include <cstdint>

#include "cvslam/vision/features.h"

namespace cvslam::vision {

enum class MatchNorm {
  kLinf,     ///< ∞-norm (thesis's proposal: few but distinctive matches)
  kL2,       ///< Euclidean
  kAngle,    ///< orientation criterion (Lowe's match.m)
  kHamming,  ///< binary descriptors (ORB); used automatically for DescriptorType::kOrb
};

// Inline so that the matchers' inner loops inline and vectorise them.

/// max |a_k − b_k| over n bytes.
inline int distanceLinf(const uint8_t* a, const uint8_t* b, int n) {
  uint8_t m = 0;
  for (int k = 0; k < n; ++k) {
    const uint8_t d =
        a[k] > b[k] ? static_cast<uint8_t>(a[k] - b[k]) : static_cast<uint8_t>(b[k] - a[k]);
    m = d > m ? d : m;
  }
  return m;
}

/// Σ (a_k − b_k)² over n bytes (squared Euclidean distance).
inline int distanceL2Squared(const uint8_t* a, const uint8_t* b, int n) {
  int s = 0;
  for (int k = 0; k < n; ++k) {
    const int d = static_cast<int>(a[k]) - static_cast<int>(b[k]);
    s += d * d;
  }
  return s;
}

/// Σ a_k b_k over n bytes.
inline int dotProduct(const uint8_t* a, const uint8_t* b, int n) {
  int s = 0;
  for (int k = 0; k < n; ++k) s += static_cast<int>(a[k]) * static_cast<int>(b[k]);
  return s;
}

/// Number of differing bits over n bytes (OpenCV's SIMD popcount).
int distanceHamming(const uint8_t* a, const uint8_t* b, int n);

/// Distance of `norm` between two descriptors of `n` bytes, as a double in the criterion's
/// units (grey levels, grey levels, radians, bits). For kAngle the norms ‖a‖, ‖b‖ can be
/// passed (≤ 0: computed here).
double descriptorDistance(MatchNorm norm, const uint8_t* a, const uint8_t* b, int n,
                          double norm_a = -1.0, double norm_b = -1.0);

}  // namespace cvslam::vision
