#pragma once
// Photometric registration (thesis §4.3.3.3): once two images are geometrically registered
// and warped into alignment, the remaining difference of corresponding intensities is
// modelled per channel as i2 = α·i1 + β (eq. 4.26; our images are grey, one channel, so two
// parameters). α and β are "a simple line-fit to the intensities of corresponding pixels
// (i1, i2), easily achieved by orthogonal regression" (§4.3.3.3): the line through the mean
// along the principal axis of the 2×2 covariance of (i1, i2), which, unlike ordinary least
// squares, treats noise in both images alike (OLS would bias α towards 0).
// Pixels whose residual exceeds `outlier_sigma`·σ of the first fit (moving objects, seams,
// parallax) are dropped and the line refitted once.
//
// YAML (section `photometric`):
//   enabled: true   min_pixels: 500   outlier_sigma: 3.0   max_gain_change: 0.5
//   smoothing_px: 1.5

#include <opencv2/core.hpp>

#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::mosaic {

struct PhotometricOptions {
  bool enabled = true;           ///< correct gain/bias before blending into the mosaic
  int min_pixels = 500;          ///< fewer overlapping pixels: no estimate
  double outlier_sigma = 3.0;    ///< refit without residuals above this many σ
  double max_gain_change = 0.5;  ///< |α − 1| above this is rejected as implausible
  /// Gaussian σ applied by the mosaic to both images before the fit [px] (0 = none).
  double smoothing_px = 1.5;

  Status load(const ConfigNode& node);
};

struct GainBias {
  double gain = 1.0;  ///< α of eq. 4.26
  double bias = 0.0;  ///< β of eq. 4.26 [grey levels]
  int pixels = 0;     ///< pixels used in the final fit
};

/// Fits reference ≈ gain·image + bias over pixels where `mask` (CV_8U, may be empty = all) is
/// non-zero. Both images CV_8U or CV_32F, same size, already aligned.
Expected<GainBias> estimateGainBias(const cv::Mat& image, const cv::Mat& reference,
                                    const cv::Mat& mask, const PhotometricOptions& options);

}  // namespace cvslam::mosaic
