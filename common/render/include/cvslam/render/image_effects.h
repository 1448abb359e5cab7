#pragma once
// Camera effects applied to rendered images: exposure gain, optical blur, sensor noise.
//
// Exposure is applied while shading (before 8-bit quantisation, as in a camera); blur and
// noise afterwards by applyImageEffects(), in that order (optics, then the sensor). Noise is
// seeded from (noise_seed, frame index, camera), so a frame is reproducible and the two
// cameras and successive frames get independent noise.

#include <opencv2/core.hpp>

#include <cstdint>

#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::render {

struct ImageEffectsOptions {
  double exposure = 1.0;     ///< gain on scene radiance (1 = nominal; 0.5 = one stop darker)
  double blur_sigma = 0.0;   ///< Gaussian blur σ [px]; 0 = none
  double noise_sigma = 0.0;  ///< additive Gaussian noise σ [grey levels]; 0 = none
  uint64_t noise_seed = 1;   ///< seed of the noise sequence

  /// Keys: exposure, blur_sigma, noise_sigma, noise_seed.
  Status load(const ConfigNode& node);
};

/// Blur then noise, in place, on a CV_8UC1 image. `stream` distinguishes cameras/frames.
void applyImageEffects(const ImageEffectsOptions& options, uint64_t stream, cv::Mat& image);

}  // namespace cvslam::render
