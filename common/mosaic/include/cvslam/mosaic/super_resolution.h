#pragma once
// Super-resolution by the iterative Papoulis–Gerchberg algorithm (thesis §4.3.4, Fig. 4.38):
//  1. Form a high-resolution (HR) grid; set the known pixel values from the registered
//     low-resolution (LR) images, each LR pixel placed by "rounding the magnified pixel
//     positions to nearest integer locations" (§4.3.4.2). Several LR pixels on one HR pixel
//     are averaged.
//  2. Set the high-frequency components to zero in the frequency domain (the HR image is
//     assumed band-limited to `bandwidth` of the HR Nyquist frequency).
//  3. Force the known pixel values in the spatial domain.
//  4. Iterate 2–3.
// The LR images are registered by the mosaic's homographies (geometric_registration.h): the
// thesis computes them from (A)SIFT matches as well (§4.3.4, "using SIFT features").
// Unknown HR pixels start from `initial` (e.g. the bicubic up-sampled plain mosaic), or the
// mean of the known pixels. The DFT is periodic, so the HR grid is padded by reflection
// with `padding` pixels to keep the borders from ringing.
//
// YAML (section `super_resolution`):
//   scale: 2   iterations: 10   bandwidth: 0.5   padding: 16

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

#include "cvslam/core/status.h"

namespace cvslam {
class ConfigNode;
}  // namespace cvslam

namespace cvslam::mosaic {

struct SuperResolutionOptions {
  int scale = 2;           ///< HR pixels per LR (mosaic) pixel along each axis
  int iterations = 10;     ///< Papoulis–Gerchberg iterations
  double bandwidth = 0.5;  ///< kept fraction of the HR Nyquist band per axis, (0, 1]
  int padding = 16;        ///< reflection padding of the HR grid for the DFT [HR px]

  Status load(const ConfigNode& node);
};

/// One registered LR image: HR-grid position (pixel centres integer) ≅ H_to_hr · [u v 1].
struct LowResFrame {
  cv::Mat image;                                          ///< CV_8U or CV_32F, one channel
  Eigen::Matrix3d H_to_hr = Eigen::Matrix3d::Identity();  ///< LR pixel → HR grid pixel
};

/// Known HR pixels from the LR frames (step 1): values (CV_32F) and a mask (CV_8U).
void projectOntoGrid(const std::vector<LowResFrame>& frames, cv::Size hr_size, cv::Mat* values,
                     cv::Mat* known);

/// Papoulis–Gerchberg on an HR grid of `hr_size`; returns the HR image (CV_32F).
Expected<cv::Mat> papoulisGerchberg(const std::vector<LowResFrame>& frames, cv::Size hr_size,
                                    const SuperResolutionOptions& options,
                                    const cv::Mat& initial = {});

/// PSNR of `image` against `truth` over `mask` (CV_8U, empty = all) for 8-bit grey levels.
double psnr(const cv::Mat& image, const cv::Mat& truth, const cv::Mat& mask = {});

}  // namespace cvslam::mosaic
