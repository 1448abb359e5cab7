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

/// max |a_k − b_k| over n bytes.
int distanceLinf(const uint8_t* a, const uint8_t* b, int n);
/// Σ (a_k − b_k)² over n bytes (squared Euclidean distance).
int distanceL2Squared(const uint8_t* a, const uint8_t* b, int n);
/// Σ a_k b_k over n bytes.
int dotProduct(const uint8_t* a, const uint8_t* b, int n);
/// Number of differing bits over n bytes.
int distanceHamming(const uint8_t* a, const uint8_t* b, int n);

/// Distance of `norm` between two descriptors of `n` bytes, as a double in the criterion's
/// units (grey levels, grey levels, radians, bits). For kAngle the norms ‖a‖, ‖b‖ can be
/// passed (≤ 0: computed here).
double descriptorDistance(MatchNorm norm, const uint8_t* a, const uint8_t* b, int n,
                          double norm_a = -1.0, double norm_b = -1.0);

}  // namespace cvslam::vision
