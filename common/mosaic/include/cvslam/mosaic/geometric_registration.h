#pragma once
// Feature-based geometric registration of two images (thesis §4.3.3, §4.3.3.1): adaptive
// SIFT features (§4.2.5) in both images, descriptor matching with the distance-ratio test
// (§4.2.6), then a robust homography (homography.h). When a prior homography is known (the
// mosaic's pose prior), matches are searched only near the predicted position, which removes
// most wrong matches before RANSAC sees them.
//
// YAML (section `registration`):
//   sift: {...}            # vision::AdaptiveSiftOptions (adaptive_sift.h)
//   match: {...}           # vision::MatchOptions (descriptor_matcher.h)
//   homography: {...}      # homography.h
//   search_radius_px: 40   # gate around the prior prediction [px]

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>

#include "cvslam/core/status.h"
#include "cvslam/mosaic/homography.h"
#include "cvslam/vision/adaptive_sift.h"
#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/features.h"

namespace cvslam::mosaic {

struct RegistrationOptions {
  vision::AdaptiveSiftOptions sift;
  vision::MatchOptions match;
  HomographyOptions homography;
  double search_radius_px = 40.0;  ///< matches must lie this near the prior prediction [px]

  Status load(const ConfigNode& node);
};

struct Registration {
  HomographyEstimate estimate;  ///< reference ≅ H · image
  int matches = 0;              ///< descriptor matches given to RANSAC
  /// The matched positions (image, reference), in the order of estimate.inliers.
  std::vector<Eigen::Vector2d> src, dst;
};

/// Registers features `image` to `reference` (reference ≅ H image). With `prior`, only
/// matches within search_radius_px of prior·x are considered.
Expected<Registration> registerFeatures(const vision::Features& image,
                                        const vision::Features& reference,
                                        const RegistrationOptions& options,
                                        const std::optional<Eigen::Matrix3d>& prior = {});

/// Detects adaptive SIFT in both images, then registerFeatures().
Expected<Registration> registerImages(const cv::Mat& image, const cv::Mat& reference,
                                      const RegistrationOptions& options,
                                      const std::optional<Eigen::Matrix3d>& prior = {});

}  // namespace cvslam::mosaic
