#include "cvslam/scenario/noise_model.h"

#include <cmath>

namespace cvslam::sim {

const std::vector<std::pair<std::string, NoiseKind>>& noiseKindNames() {
  static const std::vector<std::pair<std::string, NoiseKind>> kNames = {
      {"gaussian", NoiseKind::kGaussian},
      {"non_gaussian_centred", NoiseKind::kNonGaussianCentred},
      {"non_centred", NoiseKind::kNonCentred}};
  return kNames;
}

const std::vector<std::pair<std::string, NonGaussianShape>>& nonGaussianShapeNames() {
  static const std::vector<std::pair<std::string, NonGaussianShape>> kNames = {
      {"uniform", NonGaussianShape::kUniform}, {"mixture", NonGaussianShape::kMixture}};
  return kNames;
}

double sampleCentredNoise(Rng& rng, NoiseKind kind, NonGaussianShape shape, double sigma) {
  if (kind != NoiseKind::kNonGaussianCentred) return sigma * rng.gaussian();
  if (shape == NonGaussianShape::kUniform) {
    const double half_width = std::sqrt(3.0) * sigma;
    return rng.uniform(-half_width, half_width);
  }
  // Contaminated Gaussian: variance 0.9 σ1² + 0.1 (4 σ1)² = 2.5 σ1² = σ².
  const double sigma1 = sigma / std::sqrt(2.5);
  const bool outlier = rng.uniform() < 0.1;
  return (outlier ? 4.0 * sigma1 : sigma1) * rng.gaussian();
}

}  // namespace cvslam::sim
