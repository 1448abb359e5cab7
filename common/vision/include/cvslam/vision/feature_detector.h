#pragma once
// One interface for the front end's detectors (thesis §4.2.3–4.2.5, docs/front_end.md):
// adaptive SIFT (the thesis's choice, on OpenCV's SIFT), fast SIFT (the same adaptation on our
// own scale space, fast_sift.h), plain SIFT (Lowe, the baseline), ORB, and SWIF (the thesis's
// wavelet detector and descriptor, §4.4, swif.h).
// A detector turns one grey image into keypoints plus descriptors.

#include <memory>

#include "cvslam/core/status.h"
#include "cvslam/vision/adaptive_sift.h"
#include "cvslam/vision/fast_sift.h"
#include "cvslam/vision/features.h"
#include "cvslam/vision/swif.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

enum class DetectorType { kAdaptiveSift, kSift, kOrb, kFastSift, kSwif };

/// The descriptors a detector type produces.
DescriptorType descriptorTypeOf(DetectorType type);

struct DetectorOptions {
  DetectorType type =
      DetectorType::kAdaptiveSift;    ///< adaptive_sift | fast_sift | sift | orb | swif
  AdaptiveSiftOptions adaptive_sift;  ///< §4.2.5 (adaptive_sift, and fast_sift's adaptation)
  FastSiftOptions fast_sift;          ///< grid and octaves of fast_sift
  SwifOptions swif;                   ///< §4.4 wavelet detector and descriptor (swif.h)
  // Plain SIFT (Lowe 2004; OpenCV's defaults).
  int sift_max_features = 0;              ///< 0 = keep all (classical SIFT)
  int sift_octave_layers = 3;             ///< s, k = 2^(1/s)
  double sift_contrast_threshold = 0.04;  ///< DoG contrast threshold (image in [0, 1])
  double sift_edge_threshold = 10.0;      ///< principal-curvature ratio r
  double sift_sigma = 1.6;                ///< σ0 of the first level
  // ORB (fast option).
  int orb_max_features = 800;     ///< features kept (best FAST/Harris response)
  double orb_scale_factor = 1.2;  ///< pyramid ratio
  int orb_levels = 6;             ///< pyramid levels
  int orb_fast_threshold = 12;    ///< FAST threshold [grey levels]
  int orb_grid_cols = 8;          ///< spread keypoints over a cols × rows grid; 0 = off
  int orb_grid_rows = 6;          ///< (keypoint_grid.h)

  Status load(const ConfigNode& node);
};

class FeatureDetector {
 public:
  virtual ~FeatureDetector() = default;
  /// Detects and describes features in a grey (CV_8UC1) image.
  virtual Status detect(const cv::Mat& gray, Features* out) = 0;
  virtual DescriptorType descriptorType() const = 0;
};

/// The detector the options select. Each call makes an independent instance (no shared state).
Expected<std::unique_ptr<FeatureDetector>> makeFeatureDetector(const DetectorOptions& options);

}  // namespace cvslam::vision
