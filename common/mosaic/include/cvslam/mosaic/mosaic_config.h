#pragma once
// Every option of a mosaic run (config/mosaic.yaml, cvslam_mosaic --config): one section per
// concept. Missing keys keep the defaults; unknown keys are errors (typos).
//
//   mosaic: {...}            # mosaic_builder.h (with `adjustment:`, mosaic_adjustment.h)
//   registration: {...}      # geometric_registration.h (sift, match, homography)
//   photometric: {...}       # photometric_registration.h
//   super_resolution: {...}  # super_resolution.h
//   evaluation: {...}        # mosaic_evaluation.h

#include <string>

#include "cvslam/core/status.h"
#include "cvslam/mosaic/geometric_registration.h"
#include "cvslam/mosaic/mosaic_builder.h"
#include "cvslam/mosaic/mosaic_evaluation.h"
#include "cvslam/mosaic/photometric_registration.h"
#include "cvslam/mosaic/super_resolution.h"

namespace cvslam::mosaic {

struct MosaicConfig {
  MosaicOptions mosaic;
  RegistrationOptions registration;
  PhotometricOptions photometric;
  SuperResolutionOptions super_resolution;
  EvaluationOptions evaluation;

  Status load(const ConfigNode& node);
  /// Reads a YAML file; the error names the file, key and reason.
  static Expected<MosaicConfig> loadFile(const std::string& path);
};

}  // namespace cvslam::mosaic
