#pragma once
// A scenario's pixel noise on feature-level stereo observations (section `pixel_noise:` of an
// agent; sim/observation_simulator.h draws it; thesis §5.4, §5.9): noise kind and σ, the
// non-centred offset, the outlier rate and the feature cap.

#include <Eigen/Core>
#include <cstdint>

#include "cvslam/core/status.h"
#include "cvslam/scenario/noise_model.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::sim {

enum class FeatureCap : uint8_t { kNearest, kRandom };

struct PixelNoiseOptions {
  NoiseKind kind = NoiseKind::kGaussian;  ///< gaussian | non_gaussian_centred | non_centred
  NonGaussianShape shape = NonGaussianShape::kUniform;            ///< uniform | mixture
  double sigma_px = 0.5;                                          ///< σ per pixel coordinate [px]
  Eigen::Vector4d bias_px = Eigen::Vector4d(0.5, 0.5, 0.0, 0.5);  ///< non_centred offset [px]
  double outlier_rate = 0.0;              ///< probability that an observation is a wrong match
  int max_features = 0;                   ///< at most this many observations per frame (0: no cap)
  FeatureCap cap = FeatureCap::kNearest;  ///< nearest | random
  double max_range = 150.0;  ///< landmarks farther than this from the camera are unseen [m]

  Status load(const ConfigNode& node);
};

}  // namespace cvslam::sim
