#include "cvslam/scenario/pixel_noise_options.h"

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

Status PixelNoiseOptions::load(const ConfigNode& node) {
  node.getEnum("kind", kind, noiseKindNames());
  node.getEnum("shape", shape, nonGaussianShapeNames());
  node.get("sigma_px", sigma_px);
  node.get("bias_px", bias_px);
  node.get("outlier_rate", outlier_rate);
  node.get("max_features", max_features);
  node.getEnum("cap", cap, {{"nearest", FeatureCap::kNearest}, {"random", FeatureCap::kRandom}});
  node.get("max_range", max_range);
  node.check(sigma_px >= 0.0, "sigma_px", "must be >= 0");
  node.check(outlier_rate >= 0.0 && outlier_rate <= 1.0, "outlier_rate", "must be in [0, 1]");
  node.check(max_features >= 0, "max_features", "must be >= 0 (0: no cap)");
  node.check(max_range > 0.0, "max_range", "must be > 0");
  return node.status();
}

}  // namespace cvslam::sim
