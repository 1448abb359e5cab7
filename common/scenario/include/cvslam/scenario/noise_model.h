#pragma once
// Noise kinds of the thesis's simulations (§5.9: "centred Gaussian", "centred non Gaussian",
// Table 5.4 "non-centred Gaussian" noise), shared by the pixel and the IMU noise.
//
//   gaussian              n = σ·N(0, 1)                                   (white, centred)
//   non_gaussian_centred  zero mean, standard deviation σ, not Gaussian. Shape:
//                          - uniform: U(−√3 σ, √3 σ)
//                          - mixture: heavy-tailed contaminated Gaussian, with probability
//                            0.9 N(0, σ1²) and 0.1 N(0, (4 σ1)²), σ1 = σ/√(0.9 + 1.6) so the
//                            total standard deviation is σ
//   non_centred           n = b + σ·N(0, 1): a Gaussian with a constant offset b per
//                          component (bias_px for pixels). The thesis does not give b; it is
//                          a configuration value.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cvslam/core/random.h"

namespace cvslam::sim {

enum class NoiseKind : uint8_t { kGaussian, kNonGaussianCentred, kNonCentred };
enum class NonGaussianShape : uint8_t { kUniform, kMixture };

/// Config names: {"gaussian", "non_gaussian_centred", "non_centred"}.
const std::vector<std::pair<std::string, NoiseKind>>& noiseKindNames();
/// Config names: {"uniform", "mixture"}.
const std::vector<std::pair<std::string, NonGaussianShape>>& nonGaussianShapeNames();

/// One zero-mean (for kNonCentred: zero-mean part only, the caller adds the offset) variate of
/// standard deviation `sigma` of the given kind.
double sampleCentredNoise(Rng& rng, NoiseKind kind, NonGaussianShape shape, double sigma);

}  // namespace cvslam::sim
