#pragma once
// Stereo correspondence with the stereo-vision constraints of §4.2.8 on a rectified pair:
// a left feature (u_L, v_L) is only compared with right features in the window
//   0 < u_L − u_R ≤ HD_max = f·b / z_min        (eq. 4.10, §4.2.8.2)
//   |v_L − v_R| ≤ VD_max                         (§4.2.8.3; ≈ 0 after rectification, kept
//                                                 as a small band for calibration error)
// then the DistRatio test (§4.2.6) runs among those candidates only, and the scale rate of
// the pair must be ≈ 1 (§4.2.7: both cameras see the feature at the same distance).

#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/vision/descriptor_matcher.h"
#include "cvslam/vision/features.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct StereoMatchOptions {
  double focal_px = 0.0;                   ///< f of the rectified pair [px] (required)
  double baseline_m = 0.0;                 ///< b [m] (required)
  double min_depth_m = 0.5;                ///< z_min: nearest point seen by both cameras [m]
  double max_vertical_disparity_px = 2.0;  ///< VD_max [px] for a rectified pair
  double min_disparity_px = 0.0;  ///< disparity must exceed this (> 0: points at finite depth)
  double scale_rate_tolerance_log2 = 0.5;  ///< |log2(s_R/s_L)| bound (§4.2.7); ≤ 0 disables
  MatchOptions match{MatchNorm::kLinf, 0.8, 0.0, true, false};  ///< criterion, DistRatio

  /// HD_max = f·b / z_min [px] (§4.2.8.2).
  double maxHorizontalDisparity() const { return focal_px * baseline_m / min_depth_m; }
  Status check() const;
  Status load(const ConfigNode& node);
};

struct StereoMatch {
  int left = -1;          ///< index in the left features
  int right = -1;         ///< index in the right features
  double distance = 0.0;  ///< descriptor distance (criterion's units)
};

/// Matches left features to right features under the constraints above. The options must be
/// valid (check()).
std::vector<StereoMatch> matchStereo(const Features& left, const Features& right,
                                     const StereoMatchOptions& options);

}  // namespace cvslam::vision
